"""The fifth student trial: core slips in the paired comparisons of 02–05 that got only "not
by one of the usual mistakes". Each is now named: a per cent of the mean MSE, the difference
of the root MSEs, the errors taken against the readings instead of the truth."""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails
from test_checks_delay import task3 as delay_task3
from test_checks_fusion import task3 as fusion_task3
from test_checks_noisier_proprioception import task3 as noisier_task3

from lqe_helpers import checks, experiments, metrics
from lqe_helpers.scenario import DEFAULT

BURN, DT, RUNS = DEFAULT.burn_in_steps, DEFAULT.dt, DEFAULT.mc_runs
TRUTH = DEFAULT.truth[:, 0]


def _slipped(first: np.ndarray, second: np.ndarray, slip: str) -> metrics.Interval:
    """The paired interval first − second as a student with ``slip`` computes it."""
    if slip == "per cent of the mean":
        return metrics.mean_ci95(100 * (first - second) / first.mean())
    if slip == "root MSEs":
        return metrics.mean_ci95(np.sqrt(first) - np.sqrt(second))
    raise AssertionError(slip)


SAID = {"per cent of the mean": "is not right: it is in % of",
        "root MSEs": "is not right: it is the difference of the root mean squared errors"}


@pytest.mark.slow
@pytest.mark.parametrize("slip", list(SAID))
def test_03_and_04_name_a_difference_in_per_cent_or_of_root_mses(slip) -> None:
    for task3, check in ((fusion_task3, checks.check_fusion_difference),
                         (noisier_task3, checks.check_noisier_difference)):
        mse_vision, mse_fused, _ = task3()
        assert_fails(f"difference {SAID[slip]}", check, mse_vision, mse_fused,
                     _slipped(mse_vision, mse_fused, slip))


@pytest.mark.slow
@pytest.mark.parametrize("slip", list(SAID))
def test_05_names_a_gain_in_per_cent_or_of_root_mses(slip) -> None:
    tracking_mc = experiments.track(DEFAULT, runs=RUNS)
    batch = experiments.delay_and_compensate(tracking_mc, DEFAULT.delay)
    gain = _slipped(batch.mse("delayed"), batch.mse("predicted"), slip)
    assert_fails(f"gain {SAID[slip]}", checks.check_delay_difference, gain, delay_task3()[1])


@pytest.mark.slow
def test_03_names_a_difference_of_mses_against_the_readings() -> None:
    vision_mc = experiments.track(DEFAULT, runs=RUNS)
    fused_mc = experiments.track(DEFAULT, ("vision", "proprioception"), runs=RUNS)
    mse_vision, mse_fused, _ = fusion_task3()
    against = [np.mean((mc.positions - mc.measurements[..., 0])[:, BURN:] ** 2, axis=-1)
               for mc in (vision_mc, fused_mc)]
    assert_fails("difference is not right: the MSEs are measured against the readings",
                 checks.check_fusion_difference, mse_vision, mse_fused,
                 metrics.mean_ci95(against[0] - against[1]))


@pytest.fixture(scope="module")
def batch() -> experiments.Tracking:
    """Notebook 02's Monte Carlo batch, both P0."""
    return experiments.track(DEFAULT, p0_variance=[1.0, 1e5], runs=RUNS)


@pytest.mark.slow
@pytest.mark.parametrize("readings", ["each run's", "the trial's y"])
def test_02_names_convergence_times_of_errors_against_the_readings(batch, readings) -> None:
    y = batch.measurements[..., 0] if readings == "each run's" else (
        experiments.track(DEFAULT).measurements[:, 0])
    curves = ((batch.positions - y) ** 2).mean(axis=0)
    t_small, t_large = (float(metrics.convergence_time(curve, DT)) for curve in curves)
    assert_fails("the errors are taken against", checks.check_convergence_times,
                 t_small, t_large)


@pytest.mark.slow
def test_02_names_start_and_after_differences_in_per_cent_and_against_the_readings(batch):
    mse_start = metrics.mse(batch.positions[..., :BURN], TRUTH[:BURN])
    mse_after = batch.mse()
    right_start = metrics.mean_ci95(mse_start[:, 0] - mse_start[:, 1])
    assert_fails("after_difference is not right: it is in % of",
                 checks.check_start_and_after, right_start,
                 _slipped(mse_after[:, 0], mse_after[:, 1], "per cent of the mean"))
    against = np.mean((batch.positions - batch.measurements[..., 0])[..., :BURN] ** 2, axis=-1)
    assert_fails("start_difference is not right: the MSEs are measured against the readings",
                 checks.check_start_and_after, metrics.mean_ci95(against[:, 0] - against[:, 1]),
                 metrics.mean_ci95(mse_after[:, 0] - mse_after[:, 1]))
