"""Choosing σ_j without the true path (issue 17 §2): NIS and likelihood against the MSE."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lqe_helpers import experiments, jerk_tuning, metrics, model
from lqe_helpers.scenario import DEFAULT


def test_each_column_is_the_filter_run_at_that_jerk_std() -> None:
    grid = np.array([700.0, 1400.0, 2800.0])
    choice = jerk_tuning.tune_jerk_std(DEFAULT, grid, runs=20)
    for g, jerk_std in enumerate(grid):
        variant = dataclasses.replace(DEFAULT, jerk_std=jerk_std)
        tracking = experiments.track(variant, runs=20)
        innovations = metrics.innovations(tracking.measurements, tracking.result, variant.A,
                                          model.observation_matrix(("vision",)), np.zeros(3))
        np.testing.assert_allclose(choice.mse[:, g], tracking.mse(), rtol=1e-12)
        assert choice.nis_mean[g] == pytest.approx(
            metrics.nis_test(innovations, DEFAULT.burn_in_steps).mean, rel=1e-12)
        np.testing.assert_allclose(
            choice.log_likelihood[:, g],
            metrics.innovation_log_likelihood(innovations, DEFAULT.burn_in_steps), rtol=1e-12)


def test_refinement_finds_a_parabolas_vertex_and_a_linear_crossing() -> None:
    grid = np.geomspace(100, 10_000, 9)
    logs = np.log(grid)
    runs = np.zeros((2, 9))
    choice = jerk_tuning.JerkChoice(
        jerk_stds=grid,
        nis_mean=1.0 - 0.1 * (logs - np.log(1234.0)),       # crosses 1 at 1234
        log_likelihood=runs - (logs - np.log(777.0)) ** 2,   # peaks at 777
        mse=runs + (logs - np.log(2000.0)) ** 2,             # lowest at 2000
        sensors=1)
    assert choice.by_likelihood == pytest.approx(777.0, rel=1e-9)
    assert choice.by_nis == pytest.approx(1234.0, rel=1e-9)
    assert choice.by_mse == pytest.approx(2000.0, rel=1e-9)
    flat = dataclasses.replace(choice, nis_mean=np.full(9, 1.5))
    assert np.isnan(flat.by_nis)


def test_each_runs_pick_is_refined_between_grid_points() -> None:
    """Issue 23 §5: one run's pick was a grid point, so a range of picks was two grid points."""
    grid = np.geomspace(100, 10_000, 9)
    peaks = np.array([[777.0], [1500.0], [250.0]])
    choice = jerk_tuning.JerkChoice(
        jerk_stds=grid, nis_mean=np.ones(9),
        log_likelihood=-(np.log(grid) - np.log(peaks)) ** 2, mse=np.zeros((3, 9)), sensors=1)
    np.testing.assert_allclose(choice.by_likelihood_per_run, peaks[:, 0], rtol=1e-9)


@pytest.mark.slow
def test_likelihood_and_nis_choose_near_the_mse_optimum_without_the_truth() -> None:
    # Measured on DEFAULT (300 runs, grid 300–6 000 cm/s³): likelihood 1 346, NIS 1 185,
    # MSE optimum 1 344, the pack's quarter-period σ_j 1 396 cm/s³.
    choice = jerk_tuning.tune_jerk_std(DEFAULT, np.geomspace(300, 6000, 27))
    assert choice.by_likelihood == pytest.approx(choice.by_mse, rel=0.05)
    assert choice.by_nis == pytest.approx(choice.by_mse, rel=0.2)
    # The MSE at the likelihood's grid choice is within 0.5 % of the grid's best.
    mean_mse = choice.mse.mean(axis=0)
    at_likelihood = mean_mse[np.argmax(choice.log_likelihood.mean(axis=0))]
    assert at_likelihood <= 1.005 * mean_mse.min()


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: jerk_tuning.tune_jerk_std(DEFAULT, [100.0, 50.0, 200.0]),
         r"^jerk_stds must be an increasing grid of at least 3 values, got \[100, 50, 200\]"),
        (lambda: jerk_tuning.tune_jerk_std(DEFAULT, [100.0, 200.0]), r"at least 3 values"),
        (lambda: jerk_tuning.tune_jerk_std(DEFAULT, [-1.0, 2.0, 3.0]),
         r"^jerk_stds must all be > 0 cm/s³"),
        (lambda: jerk_tuning.tune_jerk_std(DEFAULT, [1.0, 2.0, 3.0], runs=1),
         r"^runs must be a whole number >= 2, got 1$"),
        (lambda: jerk_tuning.tune_jerk_std("DEFAULT", [1.0, 2.0, 3.0]),
         r"^scenario must be a Scenario"),
    ],
)
def test_bad_input_names_the_parameter(call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()


def test_the_choice_draws_the_painters_figure_of_its_means() -> None:
    """Notebook 00's Figure 6 (issue 25): JerkChoice.figure hands its own means over the
    runs to figures.jerk_choice_figure, byte for byte; another grid draws another figure."""
    from explorer_checks import same_png as same

    from lqe_helpers import figures

    choice = jerk_tuning.tune_jerk_std(DEFAULT, [300.0, 1000.0, 3000.0, 10000.0], runs=20)
    chosen = {"likelihood": choice.by_likelihood, "NIS": choice.by_nis, "MSE": choice.by_mse}
    by_arrays = figures.jerk_choice_figure(choice.jerk_stds, choice.log_likelihood.mean(axis=0),
                                           choice.nis_mean, choice.mse.mean(axis=0), chosen)
    assert same(choice.figure(chosen), by_arrays)
    other = jerk_tuning.tune_jerk_std(DEFAULT, [500.0, 1000.0, 3000.0, 10000.0], runs=20)
    assert not same(other.figure(chosen), choice.figure(chosen))
