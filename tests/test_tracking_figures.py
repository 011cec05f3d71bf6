"""A tracking run draws notebook 00's and 02's pictures itself (lqe_helpers/tracking_figures.py).

Each method's figure is the figure its painter draws of the same arrays fed directly (the
notebook cell before issue 25), byte for byte, and a different run draws another figure.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from explorer_checks import same_png

from lqe_helpers import experiments, figures
from lqe_helpers.prediction import open_loop
from lqe_helpers.scenario import DEFAULT

CLOSE = round(2.0 / DEFAULT.dt)
LABELS = ("P0 = diag(1)", "P0 = diag(1e5)")


def _eyes_closed(tracking: experiments.Tracking):
    blind = open_loop(DEFAULT, tracking.result.estimates[CLOSE],
                      tracking.result.estimate_covariances[CLOSE], 1.0)
    return blind, blind.position_stds


def test_open_loop_figure_is_the_painters_figure_of_the_runs_arrays() -> None:
    tracking = experiments.track(DEFAULT)
    blind, std = _eyes_closed(tracking)
    by_arrays = figures.open_loop_figure(
        DEFAULT.times, DEFAULT.truth[:, 0], tracking.measurements[:, 0], tracking.positions,
        DEFAULT.times[CLOSE], DEFAULT.times[CLOSE] + blind.times, blind.means[:, 0], std)
    assert same_png(tracking.open_loop_figure(blind, CLOSE, std), by_arrays)
    other = experiments.track(DEFAULT, sigmas=[4.5])
    assert not same_png(other.open_loop_figure(_eyes_closed(other)[0], CLOSE, std),
                        tracking.open_loop_figure(blind, CLOSE, std))


def _variants(noise: np.ndarray | None = None) -> dict[str, experiments.Tracking]:
    return {f"σ_j = {value:g}": experiments.track(dataclasses.replace(DEFAULT, jerk_std=value),
                                                  noise=noise)
            for value in (30.0, 300.0, 30000.0)}


def test_panels_figure_is_the_painters_figure_of_the_runs_arrays() -> None:
    tracking = experiments.track(DEFAULT)
    panels = _variants()
    by_arrays = figures.tracking_panels_figure(
        DEFAULT.times, DEFAULT.truth[:, 0], tracking.measurements[:, 0],
        {title: run.positions for title, run in panels.items()}, window=(2.0, 5.0))
    assert same_png(tracking.panels_figure(panels, window=(2.0, 5.0)), by_arrays)
    noise = np.random.default_rng(1).standard_normal((DEFAULT.n_steps, 1))
    other = experiments.track(DEFAULT, noise=noise)
    assert not same_png(other.panels_figure(_variants(noise), window=(2.0, 5.0)),
                        tracking.panels_figure(panels, window=(2.0, 5.0)))


def _sweep(p0: list[float] | None = None) -> experiments.Tracking:
    return experiments.track(DEFAULT, p0_variance=p0 or [1.0, 1e5], runs=4)


def test_gains_figure_is_the_painters_figure_of_the_runs_arrays() -> None:
    batch = _sweep()
    steady = experiments.filter_model(DEFAULT).steady_state()
    by_arrays = figures.gains_figure(
        DEFAULT.times, {LABELS[0]: (batch.result.gains[0, 0, :, :, 0], "estimate"),
                        LABELS[1]: (batch.result.gains[0, 1, :, :, 0], "alternative")},
        steady.gain[:, 0])
    assert same_png(batch.gains_figure(LABELS), by_arrays)
    assert not same_png(_sweep([10.0, 1e3]).gains_figure(LABELS), batch.gains_figure(LABELS))


def _belief_arrays(batch: experiments.Tracking) -> tuple[np.ndarray, tuple[float, float]]:
    mean = ((batch.positions - DEFAULT.truth[:, 0]) ** 2).mean(axis=0)
    return mean, (0.3, 0.8)


def test_belief_figure_is_the_painters_figure_of_the_runs_arrays() -> None:
    batch = _sweep()
    mean, times = _belief_arrays(batch)
    steady = experiments.filter_model(DEFAULT).steady_state()
    by_arrays = figures.belief_and_error_figure(
        DEFAULT.times,
        {LABELS[0]: (mean[0], batch.position_variances[0, 0], times[0], "estimate"),
         LABELS[1]: (mean[1], batch.position_variances[0, 1], times[1], "alternative")},
        steady.estimate_covariance[0, 0], 0.5, 4)
    assert same_png(batch.belief_figure(mean, times, 0.5, LABELS), by_arrays)
    other = _sweep([10.0, 1e3])
    assert not same_png(other.belief_figure(mean, times, 0.5, LABELS),
                        batch.belief_figure(mean, times, 0.5, LABELS))


@pytest.mark.parametrize(("draw", "message"), [
    (lambda: experiments.track(DEFAULT, runs=2).open_loop_figure(
        _eyes_closed(experiments.track(DEFAULT))[0], CLOSE, np.ones(101)), "run must pick"),
    (lambda: experiments.track(DEFAULT).open_loop_figure("blind", CLOSE, np.ones(101)),
     "prediction must be"),
    (lambda: experiments.track(DEFAULT).open_loop_figure(
        _eyes_closed(experiments.track(DEFAULT))[0], DEFAULT.n_steps, np.ones(101)), "close"),
    (lambda: experiments.track(DEFAULT).open_loop_figure(
        _eyes_closed(experiments.track(DEFAULT, sigmas=[4.5]))[0], CLOSE, np.ones(101)),
     "prediction must start from this run's estimate"),
    (lambda: experiments.track(DEFAULT).open_loop_figure(
        _eyes_closed(experiments.track(DEFAULT))[0], CLOSE, np.ones(100)),
     r"prediction_std must have shape \(101,\)"),
    (lambda: experiments.track(DEFAULT, ("vision", "proprioception")).panels_figure(
        {}, (2.0, 5.0)), "vision alone"),
    (lambda: experiments.track(DEFAULT).panels_figure({}, (2.0, 5.0)), "panels must map"),
    (lambda: experiments.track(DEFAULT).panels_figure(
        {"other σ_v": experiments.track(DEFAULT, sigmas=[4.5])}, (2.0, 5.0)),
     "panels must map"),
    (lambda: experiments.track(DEFAULT).panels_figure({"x": DEFAULT}, (2.0, 5.0)),
     "panels must map"),
    (lambda: _sweep().gains_figure(LABELS[:1]), "labels must be one legend label"),
    (lambda: _sweep().gains_figure("P0"), "labels must be one legend label"),
    (lambda: experiments.track(DEFAULT, sigmas=[[1.5], [4.5]], runs=2).gains_figure(LABELS),
     "labels must be one legend label"),
    (lambda: experiments.track(DEFAULT, p0_variance=[1.0, 1e5]).belief_figure(
        np.ones((2, DEFAULT.n_steps)), (0.3, 0.8), 0.5, LABELS), "shape \\(runs, s, n\\)"),
    (lambda: _sweep().belief_figure(np.ones((2, 5)), (0.3, 0.8), 0.5, LABELS),
     "mean_squared_error must have shape"),
    (lambda: _sweep().belief_figure(np.ones((2, DEFAULT.n_steps)), (0.3,), 0.5, LABELS),
     "convergence_times must be one time"),
    (lambda: _sweep().belief_figure(np.ones((2, DEFAULT.n_steps)), (0.3, 0.8), -1, LABELS),
     "threshold"),
])
def test_each_method_refuses_bad_input_naming_the_parameter(draw, message) -> None:
    with pytest.raises(ValueError, match=message):
        draw()
