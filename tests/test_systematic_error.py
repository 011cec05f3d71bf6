"""A sweep's errors beside its systematic error: ``Tracking.error_figure`` (notebook 01, Fig. 5).

The result method only hands its arrays to :func:`lqe_helpers.figures.estimate_error_figure`:
the figure it draws is the painter's of the arrays notebook 01 passed before (pixel for
pixel, and line by line), so a method that drew another run, another band or another
noise-free output fails here.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from explorer_checks import png

from lqe_helpers import experiments, figures, systematic_error
from lqe_helpers.scenario import DEFAULT

SIGMAS = (1.5, 4.5)
N = DEFAULT.n_steps
TRUTH = DEFAULT.truth[:, 0]


@pytest.fixture(scope="module")
def batch() -> experiments.Tracking:
    """Runs of notebook 01's sweep (fewer runs): positions (5, 2, n)."""
    return experiments.track(DEFAULT, sigmas=[[sigma] for sigma in SIGMAS], runs=5)


def _noise_free() -> dict[float, np.ndarray]:
    """Noise-free outputs by σ_v, as a student's my_filter makes them (here the engine's)."""
    return {sigma: experiments.filter_model(DEFAULT, sigmas=[sigma]).filter(
        TRUTH[:, None]).estimates[:, 0] for sigma in SIGMAS}


def _by_arrays(batch: experiments.Tracking, clean: dict, run: int) -> plt.Figure:
    """Notebook 01's Figure 5 as its cell drew it before, from arrays."""
    return figures.estimate_error_figure(DEFAULT.times, {
        f"σ_v = {s} cm": (batch.positions[run, i] - TRUTH,
                          np.sqrt(batch.position_variances[run, i]), clean[s] - TRUTH, role)
        for i, (s, role) in enumerate(((1.5, "estimate"), (4.5, "alternative")))},
        skipped=DEFAULT.burn_in)


@pytest.mark.parametrize("run", [0, 3])
def test_error_figure_is_the_painters_figure_of_the_runs_arrays(batch, run) -> None:
    clean = _noise_free()
    by_object = batch.error_figure(noise_free=clean, run=run)
    by_arrays = _by_arrays(batch, clean, run)
    try:
        assert png(by_object, dpi=30) == png(by_arrays, dpi=30)
        for i, (ax, sigma) in enumerate(zip(by_object.axes, SIGMAS, strict=True)):
            error, systematic = ax.get_lines()
            np.testing.assert_array_equal(error.get_ydata(), batch.positions[run, i] - TRUTH)
            np.testing.assert_array_equal(systematic.get_ydata(), clean[sigma] - TRUTH)
            band = ax.collections[0].get_paths()[0].vertices[:, 1]
            assert band.max() == pytest.approx(
                2 * np.sqrt(batch.position_variances[run, i]).max())
            assert ax.get_title(loc="left") == f"σ_v = {sigma} cm"
    finally:
        plt.close(by_object)
        plt.close(by_arrays)


def test_another_run_or_noise_free_output_draws_another_figure(batch) -> None:
    """The comparison above can fail: the figure of run 1, or of shifted outputs, differs."""
    clean = _noise_free()
    reference = _by_arrays(batch, clean, 0)
    other_run = batch.error_figure(clean, run=1)
    shifted = batch.error_figure({sigma: values + 0.5 for sigma, values in clean.items()})
    try:
        assert png(other_run, dpi=30) != png(reference, dpi=30)
        assert png(shifted, dpi=30) != png(reference, dpi=30)
    finally:
        plt.close("all")


def test_the_noise_free_keys_match_the_sweep_in_any_order(batch) -> None:
    clean = _noise_free()
    reordered = {4.5: clean[4.5], np.float64(1.5): clean[1.5]}
    fig = batch.error_figure(reordered)
    try:
        first, second = fig.axes
        assert first.get_title(loc="left") == "σ_v = 1.5 cm"
        np.testing.assert_array_equal(first.get_lines()[1].get_ydata(), clean[1.5] - TRUTH)
        np.testing.assert_array_equal(second.get_lines()[1].get_ydata(), clean[4.5] - TRUTH)
    finally:
        plt.close(fig)


@pytest.mark.parametrize(("noise_free", "message"), [
    ({1.5: np.zeros(N)}, r"noise_free must map each σ_v of the run \(1.5, 4.5 cm\) to "
                         r"positions \(cm\) of shape \(1000,\), got keys \[1.5\]"),
    ({1.5: np.zeros(N), 3.0: np.zeros(N)}, r"got keys \[1.5, 3.0\]"),
    ({1.5: np.zeros(N), 4.5: np.zeros(N), 6.0: np.zeros(N)}, "noise_free must map each σ_v"),
    ({"a": np.zeros(N), 4.5: np.zeros(N)}, r"got keys \['a', 4.5\]"),
    ({"1.5": np.zeros(N), 4.5: np.zeros(N)}, r"got keys \['1.5', 4.5\]"),
    ({True: np.zeros(N), 4.5: np.zeros(N)}, r"got keys \[True, 4.5\]"),
    ([np.zeros(N), np.zeros(N)], "noise_free must map .* got list"),
    ({1.5: np.zeros(N - 1), 4.5: np.zeros(N)},
     r"noise_free\[1.5\] must be finite positions \(cm\) of shape \(1000,\), got shape "
     r"\(999,\)"),
    ({1.5: np.zeros((N, 3)), 4.5: np.zeros(N)}, r"got shape \(1000, 3\)"),
    ({1.5: np.full(N, np.nan), 4.5: np.zeros(N)}, "with NaN or infinite values"),
])
def test_error_figure_refuses_bad_noise_free_naming_it(batch, noise_free, message) -> None:
    with pytest.raises(ValueError, match=message):
        batch.error_figure(noise_free)


def test_error_figure_refuses_what_is_not_a_sweep_of_vision(batch) -> None:
    clean = _noise_free()
    fused = experiments.track(DEFAULT, ("vision", "proprioception"), runs=2)
    one = experiments.track(DEFAULT, runs=2)
    for tracking in (fused, one):
        with pytest.raises(ValueError, match=r"tracking must be runs of vision alone over a "
                                             r"sweep of 1 to 3 σ_v"):
            tracking.error_figure(clean)
    with pytest.raises(ValueError, match=r"run must pick one run of the leading axes \(5,\), "
                                         r"got 7"):
        batch.error_figure(clean, run=7)
    with pytest.raises(ValueError, match="tracking must be"):
        systematic_error.error_figure("batch", clean)


def test_positions_by_sigma_without_sigmas_takes_any_positive_sigma() -> None:
    checked = systematic_error.positions_by_sigma("x", {2: [0.0, 1.0], 0.5: (1, 2)}, 2)
    assert list(checked) == [2.0, 0.5]
    np.testing.assert_array_equal(checked[0.5], [1.0, 2.0])
    for bad in ({}, {-1.5: [0.0, 1.0]}, {np.inf: [0.0, 1.0]}):
        with pytest.raises(ValueError, match=r"x must map σ_v > 0 \(cm\) to positions"):
            systematic_error.positions_by_sigma("x", bad, 2)
