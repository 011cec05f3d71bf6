"""A student's own arrays as the pack's results (notebooks 01, 03, 04, 05 draw them so)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from explorer_checks import png

from lqe_helpers import experiments, figures, own_runs, simulation
from lqe_helpers.scenario import DEFAULT

FUSED = ("vision", "proprioception")
N = DEFAULT.n_steps


def _own_fused() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Readings (n, 2) and two 'student' position arrays, not the engine's."""
    readings = experiments.readings(DEFAULT, FUSED)
    truth = DEFAULT.truth[:, 0]
    return readings, truth + 0.25 * np.sin(7 * DEFAULT.times), truth - 0.1


def test_tracking_holds_the_students_arrays_and_the_engines_covariances() -> None:
    readings, _, fused = _own_fused()
    run = own_runs.tracking(readings, fused, sensors=FUSED, sigmas=[1.5, 1.5])
    np.testing.assert_array_equal(run.positions, fused)
    np.testing.assert_array_equal(run.measurements, readings)
    engine = experiments.track(DEFAULT, FUSED, sigmas=[1.5, 1.5])
    np.testing.assert_allclose(run.position_variances, engine.position_variances)
    assert run.sensors == FUSED
    whole = np.column_stack([fused, np.zeros((N, 2))])
    np.testing.assert_array_equal(own_runs.tracking(readings, whole, sensors=FUSED).positions,
                                  fused)


def test_the_trial_figure_of_own_runs_is_the_figure_of_their_arrays() -> None:
    """Notebook 03's Figure 1: one object's ``figure()`` draws what six arrays drew."""
    readings, vision, fused = _own_fused()
    truth = DEFAULT.truth[:, 0]
    by_arrays = figures.tracking_comparison_figure(
        DEFAULT.times, truth, {"vision only": (vision, "alternative"),
                               "vision + proprioception": (fused, "estimate")},
        readings={"vision readings": (readings[:, 0], "vision"),
                  "proprioception readings": (readings[:, 1], "proprioception")},
        title="t")
    own = own_runs.tracking(readings, fused, sensors=FUSED)
    by_object = own.figure("vision + proprioception",
                           against={"vision only": own_runs.tracking(readings[:, :1], vision)},
                           title="t")
    try:
        assert [line.get_label() for line in by_object.axes[0].get_lines()] == [
            "vision readings", "proprioception readings", "true position", "vision only",
            "vision + proprioception"]
        assert png(by_object, dpi=30) == png(by_arrays, dpi=30)
    finally:
        plt.close(by_arrays)
        plt.close(by_object)


def test_reading_labels_rename_a_sensors_readings() -> None:
    """Notebook 01's Figures 1–2 call vision's readings "noisy vision"."""
    readings = experiments.readings(DEFAULT)[:, 0]
    fig = own_runs.tracking(readings, DEFAULT.truth[:, 0] + 0.2).figure(
        "filtered estimate (my_filter)", reading_labels={"vision": "noisy vision"})
    try:
        assert [line.get_label() for line in fig.axes[0].get_lines()] == [
            "noisy vision", "true position", "filtered estimate (my_filter)"]
    finally:
        plt.close(fig)


def _delayed_arrays(steps: int) -> tuple[experiments.Tracking, np.ndarray, np.ndarray,
                                         np.ndarray]:
    run = experiments.track(DEFAULT)
    late = simulation.delay_signal(run.measurements, steps)[:, 0]
    delayed = simulation.delay_signal(run.result.estimates, steps)[:, 0] + 0.05
    compensated = DEFAULT.truth[:, 0] - 0.3
    compensated[:steps] = np.nan
    return run, late, delayed, compensated


@pytest.mark.slow
def test_delayed_draws_the_students_arrays_in_both_figures() -> None:
    """Notebook 05's Figures 1 and 3, from the student's three arrays."""
    steps = DEFAULT.delay_steps(0.1)
    run, late, delayed, compensated = _delayed_arrays(steps)
    own = own_runs.delayed(run, 0.1, late, delayed, compensated)
    assert own.steps == steps
    truth = DEFAULT.truth[:, 0]
    pairs = [
        (own.figure(), figures.delay_figure(DEFAULT.times, truth, late, delayed, compensated,
                                            0.1)),
        (own.comparison_figure("t"), figures.tracking_comparison_figure(
            DEFAULT.times, truth,
            {r"delayed estimate $\hat p_{j-\delta}$": (delayed, "estimate"),
             r"compensated $p^*_j$": (compensated, "prediction"),
             r"perfect but late eye $p_{j-\delta}$": (
                 simulation.delay_signal(truth, steps, axis=-1), "reference")},
            title="t")),
        (own.comparison_figure("t"), figures.late_eye_figure(
            DEFAULT.times, truth, delayed, compensated,
            simulation.delay_signal(truth, steps, axis=-1), "t")),
    ]
    try:
        for by_object, by_arrays in pairs:
            assert png(by_object, dpi=30) == png(by_arrays, dpi=30)
    finally:
        plt.close("all")


@pytest.mark.parametrize(("call", "message"), [
    (lambda r, e: own_runs.tracking(r, e), r"readings must have one column per sensor "
                                           r"\('vision',\), got shape \(1000, 2\)"),
    (lambda r, e: own_runs.tracking(r[:-1], e, sensors=FUSED),
     r"readings must be readings \(cm\) of shape \(n,\) or \(n, c\) with n = 1000, got shape "
     r"\(999, 2\)"),
    (lambda r, e: own_runs.tracking(r, e[:-1], sensors=FUSED),
     r"estimates must be estimates \(cm\) of shape .* got shape \(999,\)"),
    (lambda r, e: own_runs.tracking(r, np.where(e > 0, np.nan, e), sensors=FUSED),
     r"estimates must be finite numbers \(cm\), got \d+ NaN or infinite values"),
    (lambda r, e: own_runs.tracking(r, "abc", sensors=FUSED),
     r"estimates must be an array of estimates \(cm\), .* got str"),
    (lambda r, e: own_runs.tracking(r, e, sensors=("vision", "smell")), "smell"),
    (lambda r, e: own_runs.tracking(r, e, scenario="DEFAULT", sensors=FUSED), "scenario"),
    (lambda r, e: own_runs.tracking(r, e, sensors=FUSED, sigmas=[1.5, -1.0]), "sigmas"),
])
def test_tracking_refuses_bad_input_naming_the_parameter(call, message) -> None:
    readings, _, fused = _own_fused()
    with pytest.raises(ValueError, match=message):
        call(readings, fused)


def test_delayed_refuses_bad_input_naming_the_parameter() -> None:
    steps = DEFAULT.delay_steps(0.1)
    run, late, delayed, compensated = _delayed_arrays(steps)
    with pytest.raises(ValueError, match="run must be"):
        own_runs.delayed("a run", 0.1, late, delayed, compensated)
    with pytest.raises(ValueError, match=r"run must be one trial, positions of shape \(1000,\)"):
        own_runs.delayed(experiments.track(DEFAULT, runs=2), 0.1, late, delayed, compensated)
    with pytest.raises(ValueError, match="delay"):
        own_runs.delayed(run, 0.105, late, delayed, compensated)
    with pytest.raises(ValueError, match=r"compensated must be positions of shape \(1000,\), "
                                         r"got shape \(1000, 3\)"):
        own_runs.delayed(run, 0.1, late, delayed, np.zeros((N, 3)))
    with pytest.raises(ValueError, match="late_readings must be positions"):
        own_runs.delayed(run, 0.1, late[:-1], delayed, compensated)


def _noise_free_arrays() -> tuple[dict, dict, dict]:
    """Notebook 01's Figure 4 inputs: a 'student's' noise-free filter and smoother outputs
    by σ_v (not the engine's), and the smoother's weights (numpy floats, as np.argmin picks)."""
    truth = DEFAULT.truth[:, 0]
    filtered = {1.5: truth + 0.1 * np.cos(3 * DEFAULT.times), 4.5: truth * 1.02}
    smoothed = {1.5: np.roll(truth, 5), 4.5: np.roll(truth, 9)}
    return filtered, smoothed, {1.5: np.float64(0.14), 4.5: np.float64(0.06)}


def test_noise_free_draws_the_students_outputs_as_the_lag_figure_of_their_arrays() -> None:
    """Notebook 01's Figure 4: ``own_runs.noise_free(...).figure()`` is the painter's figure
    of the arrays its cell passed before, line for line and pixel for pixel."""
    filtered, smoothed, alphas = _noise_free_arrays()
    truth = DEFAULT.truth[:, 0]
    by_arrays = figures.lag_figure(DEFAULT.times, truth, {
        f"σ_v = {s} cm": {"LQE (your my_filter)": (filtered[s], "estimate"),
                          f"exponential smoother, α = {alphas[s]:.2f}": (smoothed[s],
                                                                       "alternative")}
        for s in (1.5, 4.5)}, window=(4.1, 5.1))
    own = own_runs.noise_free(filtered, smoothed, alphas)
    by_object = own.figure(window=(4.1, 5.1))
    shown = (DEFAULT.times >= 4.1) & (DEFAULT.times <= 5.1)
    try:
        assert png(by_object, dpi=30) == png(by_arrays, dpi=30)
        for ax, sigma in zip(by_object.axes, (1.5, 4.5), strict=True):
            truth_line, lqe, smoother = ax.get_lines()
            np.testing.assert_array_equal(truth_line.get_ydata(), truth[shown])
            np.testing.assert_array_equal(lqe.get_ydata(), filtered[sigma][shown])
            np.testing.assert_array_equal(smoother.get_ydata(), smoothed[sigma][shown])
            assert [lqe.get_label(), smoother.get_label()] == [
                "LQE (your my_filter)", f"exponential smoother, α = {alphas[sigma]:.2f}"]
            assert ax.get_title() == f"σ_v = {sigma} cm"
        swapped = own_runs.noise_free(smoothed, filtered, alphas).figure(window=(4.1, 5.1))
        assert png(swapped, dpi=30) != png(by_arrays, dpi=30)
    finally:
        plt.close("all")


def test_noise_free_keeps_the_order_of_filtered_and_copies_the_arrays() -> None:
    filtered, smoothed, alphas = _noise_free_arrays()
    backwards = {4.5: smoothed[4.5], 1.5: smoothed[1.5]}
    own = own_runs.noise_free(filtered, backwards, alphas)
    assert list(own.outputs) == [1.5, 4.5]
    np.testing.assert_array_equal(own.outputs[1.5]["exponential smoother, α = 0.14"][0],
                                  smoothed[1.5])
    filtered[1.5][:] = 0.0
    assert np.any(own.outputs[1.5]["LQE (your my_filter)"][0] != 0.0)


@pytest.mark.parametrize(("change", "message"), [
    (lambda f, s, a: (f, {1.5: s[1.5]}, a),
     r"smoothed must map each σ_v of the run \(1.5, 4.5 cm\) to positions \(cm\) of shape "
     r"\(1000,\), got keys \[1.5\]"),
    (lambda f, s, a: ({1.5: f[1.5][:-1], 4.5: f[4.5]}, s, a),
     r"filtered\[1.5\] must be finite positions \(cm\) of shape \(1000,\), got shape \(999,\)"),
    (lambda f, s, a: ({-1.5: f[1.5]}, s, a), r"filtered must map σ_v > 0 \(cm\) to positions"),
    (lambda f, s, a: (f, {1.5: s[1.5], 4.5: np.full(N, np.nan)}, a),
     r"smoothed\[4.5\] must be finite .* with NaN or infinite values"),
    (lambda f, s, a: (f, s, {1.5: 0.1}),
     r"alphas must map each σ_v of filtered \(1.5, 4.5 cm\) to a weight in \(0, 1\], got "
     r"\{1.5: 0.1\}"),
    (lambda f, s, a: (f, s, [0.1, 0.2]), r"alphas must map each σ_v .* got \[0.1, 0.2\]"),
    (lambda f, s, a: (f, s, 0.1), r"alphas must map each σ_v .* got 0.1"),
    (lambda f, s, a: (f, s, {"1.5": 0.1, 4.5: 0.1}), r"alphas must map .* got \{'1.5': 0.1"),
    (lambda f, s, a: (f, s, {1.5: 0.1, 4.5: 1.5}), r"alphas\[4.5\] must be in \(0, 1\], got 1.5"),
    (lambda f, s, a: (f, s, {1.5: 0.0, 4.5: 0.1}), r"alphas\[1.5\] must be in \(0, 1\], got 0"),
    (lambda f, s, a: (f, s, {1.5: "x", 4.5: 0.1}), r"alphas\[1.5\]"),
])
def test_noise_free_refuses_bad_input_naming_the_parameter(change, message) -> None:
    with pytest.raises(ValueError, match=message):
        own_runs.noise_free(*change(*_noise_free_arrays()))


def test_noise_free_refuses_a_bad_scenario_or_window() -> None:
    with pytest.raises(ValueError, match="scenario"):
        own_runs.noise_free(*_noise_free_arrays(), scenario="DEFAULT")
    own = own_runs.noise_free(*_noise_free_arrays())
    with pytest.raises(ValueError, match=r"window must be \(start, end\)"):
        own.figure(window=(5.1, 4.1))
