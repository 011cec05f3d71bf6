"""The tutorial's lessons hold at the scenario's defaults, measured over Monte Carlo runs.

The scenario's constants (lqe_helpers/scenario.py) stand in for the MATLAB script the
tutorial refers to; these tests make sure each question still teaches what it should.
"""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import experiments, metrics
from lqe_helpers.scenario import DEFAULT

FUSED = ("vision", "proprioception")


@pytest.mark.parametrize("sigma_v", [1.5, 4.5])
def test_a_filtered_mse_is_well_below_the_sensor_variance(sigma_v: float) -> None:
    vision = experiments.track(DEFAULT, sigmas=[sigma_v], runs=DEFAULT.mc_runs)
    filtered = metrics.mean_ci95(vision.mse())
    raw = metrics.mean_ci95(vision.measurement_mse())
    # Raw readings have the sensor's variance; the filter removes most of it.
    assert raw.low < sigma_v**2 < raw.high
    assert filtered.high < 0.25 * sigma_v**2


def test_b_large_p0_converges_faster_than_small_p0() -> None:
    runs = experiments.track(DEFAULT, p0_variance=np.array([1e5, 1.0]), runs=DEFAULT.mc_runs)
    squared = (runs.positions - DEFAULT.truth[:, 0]) ** 2       # (runs, 2, n)
    rng = np.random.default_rng(DEFAULT.seed)
    large = metrics.convergence_time_ci95(squared[:, 0], DEFAULT.dt, rng)
    small = metrics.convergence_time_ci95(squared[:, 1], DEFAULT.dt, rng)
    assert large.high < small.low                 # intervals do not overlap
    assert small.mean > 3 * large.mean            # and the difference is large
    # P0 only shapes the transient: the steady states agree.
    late = squared[:, :, DEFAULT.n_steps // 2:].mean(axis=(0, 2))
    assert late[0] == pytest.approx(late[1], rel=0.01)


def test_c_equal_noise_proprioception_lowers_mse() -> None:
    vision = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    fused = experiments.track(DEFAULT, sensors=FUSED, sigmas=[1.5, 1.5], runs=DEFAULT.mc_runs)
    gain = metrics.mean_ci95(vision.mse() - fused.mse())
    assert gain.low > 0.3 * metrics.mean_ci95(vision.mse()).mean  # > 30 % lower


def test_d_noisier_proprioception_still_lowers_mse_by_a_clear_margin() -> None:
    vision = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    fused = experiments.track(DEFAULT, sensors=FUSED, sigmas=[1.5, 4.5], runs=DEFAULT.mc_runs)
    gain = metrics.mean_ci95(vision.mse() - fused.mse())
    vision_mse = metrics.mean_ci95(vision.mse()).mean
    # Margin: at least 5 % of the vision-only MSE, and the whole interval above zero.
    assert gain.low > 0.05 * vision_mse


def test_e_compensated_prediction_beats_the_uncompensated_delayed_estimate() -> None:
    vision = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    delayed = experiments.delay_and_compensate(vision, DEFAULT.delay)
    assert delayed.steps == 10
    gain = metrics.mean_ci95(delayed.mse("delayed") - delayed.mse("predicted"))
    assert gain.low > 0.25 * metrics.mean_ci95(delayed.mse("delayed")).mean
    # But nothing beats having no delay at all.
    assert metrics.mean_ci95(delayed.mse("predicted")).low > metrics.mean_ci95(vision.mse()).high


def test_matched_jerk_noise_is_near_the_mse_optimum() -> None:
    """Q from the physics of the path lands within 10 % of the best MSE of a wide sweep."""
    from dataclasses import replace

    matched = DEFAULT.process_jerk_std
    mses = {}
    for factor in (0.1, 0.3, 1.0, 3.0, 10.0):
        scenario = replace(DEFAULT, jerk_std=factor * matched)
        mses[factor] = experiments.track(scenario, runs=100).mse().mean()
    assert mses[1.0] <= 1.1 * min(mses.values())
    assert mses[0.1] > 1.5 * mses[1.0] and mses[10.0] > 1.2 * mses[1.0]
