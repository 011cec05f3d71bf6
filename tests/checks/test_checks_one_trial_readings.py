"""Task 3 of notebooks 02, 03 and 04 (paired Monte Carlo comparisons of MSEs): a student who
takes every run's MSE against the one trial's readings y of the task before (broadcast over
all runs) instead of the truth is told so, for the per-run MSEs and for the interval."""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails

from lqe_helpers import checks, experiments, metrics
from lqe_helpers.scenario import DEFAULT

BURN, RUNS = DEFAULT.burn_in_steps, DEFAULT.mc_runs
FUSED = ("vision", "proprioception")
ONE_TRIAL = "against the readings of one trial (y), the same for every run"


def paired(mses: np.ndarray) -> metrics.Interval:
    return metrics.mean_ci95(mses[:, 0] - mses[:, 1])


@pytest.mark.slow
def test_02_names_start_and_after_differences_against_the_trials_readings() -> None:
    y = experiments.track(DEFAULT).measurements            # the notebook's y, (n, 1)
    batch = experiments.track(DEFAULT, p0_variance=[1.0, 1e5], runs=RUNS)
    start = paired(metrics.mse(batch.positions[..., :BURN], y[:BURN, 0]))
    after = paired(metrics.mse(batch.positions, y[:, 0], BURN))
    right_start = paired(metrics.mse(batch.positions[..., :BURN], DEFAULT.truth[:BURN, 0]))
    assert_fails(f"start_difference is not right: the MSEs are measured {ONE_TRIAL}",
                 checks.check_start_and_after, start, after)
    assert_fails(f"after_difference is not right: the MSEs are measured {ONE_TRIAL}",
                 checks.check_start_and_after, right_start, after)


def task3(notebook: str) -> tuple[experiments.Tracking, experiments.Tracking, np.ndarray]:
    """Task 3's two Monte Carlo runs (vision alone, fused) and Task 2's trial y (n, 2)."""
    sigmas = [1.5, 4.5] if notebook == "04" else [DEFAULT.sigma_v, DEFAULT.sigma_p]
    vision_mc = experiments.track(DEFAULT, ("vision",), sigmas=sigmas[:1], runs=RUNS)
    fused_mc = experiments.track(DEFAULT, FUSED, sigmas=sigmas, runs=RUNS)
    return vision_mc, fused_mc, experiments.readings(DEFAULT, FUSED, sigmas=sigmas)


CHECKS = {"03": checks.check_fusion_difference, "04": checks.check_noisier_difference}


@pytest.mark.slow
@pytest.mark.parametrize("notebook", list(CHECKS))
@pytest.mark.parametrize(("column", "sense"), [(0, "vision's"), (1, "proprioception's")])
def test_03_and_04_name_per_run_mses_against_the_trials_readings(notebook, column,
                                                                 sense) -> None:
    vision_mc, fused_mc, y = task3(notebook)
    mse_vision = metrics.mse(vision_mc.positions, y[:, column], BURN)
    mse_fused = metrics.mse(fused_mc.positions, y[:, column], BURN)
    message = assert_fails(
        f"mse_vision is not right: it compares the estimate with {sense} readings of one "
        f"trial (column {column} of y), the same for every run, not with the true position",
        CHECKS[notebook], mse_vision, mse_fused, metrics.mean_ci95(mse_vision - mse_fused))
    assert f"mse_fused is not right: it compares the estimate with {sense} readings of one " \
           f"trial" in message


@pytest.mark.slow
@pytest.mark.parametrize("notebook", list(CHECKS))
def test_03_and_04_name_a_difference_against_the_trials_readings(notebook) -> None:
    vision_mc, fused_mc, y = task3(notebook)
    against = [metrics.mse(mc.positions, y[:, 0], BURN) for mc in (vision_mc, fused_mc)]
    assert_fails(f"difference is not right: the MSEs are measured {ONE_TRIAL}",
                 CHECKS[notebook], vision_mc.mse(), fused_mc.mse(),
                 metrics.mean_ci95(against[0] - against[1]))
