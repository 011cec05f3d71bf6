"""Issue 17 §4: the numbers the notebooks will state, measured on DEFAULT (300 runs, seed 5).

Each assertion pins a number the report to the lead quotes, to its printed precision, so
prose that states it stays true.
"""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import experiments, metrics, smoothing
from lqe_helpers.scenario import DEFAULT

pytestmark = pytest.mark.slow
TRUTH, BURN, RUNS = DEFAULT.truth[:, 0], DEFAULT.burn_in_steps, DEFAULT.mc_runs
ALPHAS = np.round(np.arange(0.01, 1.0001, 0.005), 3)
WINDOWS = np.arange(1, 151)


@pytest.fixture(scope="module")
def vision_batch() -> experiments.Tracking:
    return experiments.track(DEFAULT, sigmas=[[1.5], [4.5]], runs=RUNS)


@pytest.mark.parametrize(("column", "alpha", "window", "excess_percent", "lag_ms"),
                         [(0, 0.34, 5, 68.2, -19.4), (1, 0.185, 10, 14.4, -43.7)])
def test_01_tuned_smoothers_lose_to_the_lqe(vision_batch, column, alpha, window,
                                            excess_percent, lag_ms) -> None:
    y = vision_batch.measurements[:, column, :, 0]
    lqe = vision_batch.mse()[:, column]
    ewma = smoothing.tune_smoother("exponential", y, TRUTH, ALPHAS, BURN)
    boxcar = smoothing.tune_smoother("moving_average", y, TRUTH, WINDOWS, BURN)
    assert ewma.best == alpha and boxcar.best == window
    for tuned in (ewma, boxcar):
        assert metrics.mean_ci95(tuned.mse - lqe).low > 0
    relative = metrics.mean_ci95(100 * (ewma.mse - lqe) / lqe.mean())
    assert round(relative.mean, 1) == excess_percent
    clean = smoothing.exponential_smoother(TRUTH, alpha)
    fit = metrics.fit_sinusoid(DEFAULT.times[BURN:], clean[BURN:], DEFAULT.frequency)
    assert round(1000 * float(fit.lead), 1) == lag_ms


def test_01_filtered_mse_growth_and_its_parts(vision_batch) -> None:
    mse = vision_batch.mse().mean(axis=0)
    systematic, noise = [], []
    for i, sigma in enumerate((1.5, 4.5)):
        clean = experiments.track(DEFAULT, sigmas=[sigma], noise=np.zeros((DEFAULT.n_steps, 1)))
        systematic.append(float(clean.mse()))
        noise.append(metrics.mse(vision_batch.positions[:, i] - clean.positions,
                                 np.zeros_like(TRUTH), BURN).mean())
    assert round(mse[1] / mse[0], 2) == 6.84
    assert round(systematic[1] / systematic[0], 2) == 10.09
    assert round(noise[1] / noise[0], 2) == 6.40


def test_03_fusion_cuts_the_first_second_by_more_than_a_third() -> None:
    vision = experiments.track(DEFAULT, ("vision",), runs=RUNS).positions
    fused = experiments.track(DEFAULT, ("vision", "proprioception"), runs=RUNS).positions

    def window(positions, start, stop):
        return np.mean((positions[:, start:stop] - TRUTH[start:stop]) ** 2, axis=-1)

    first = (window(vision, 0, BURN), window(fused, 0, BURN))
    after = (window(vision, BURN, None), window(fused, BURN, None))
    whole = (window(vision, 0, None), window(fused, 0, None))
    cut = {name: metrics.mean_ci95(100 * (v - f) / v.mean())
           for name, (v, f) in (("first", first), ("after", after), ("whole", whole))}
    assert round(cut["first"].mean, 1) == 37.7
    assert round(cut["after"].mean, 1) == 45.0 and round(cut["whole"].mean, 1) == 42.9
    absolute_whole = metrics.mean_ci95(whole[0] - whole[1])
    absolute_after = metrics.mean_ci95(after[0] - after[1])
    assert absolute_whole.low > absolute_after.high  # larger in absolute terms
    assert round(absolute_whole.mean, 3) == 0.208 and round(absolute_after.mean, 3) == 0.173


def test_05_compensation_wins_back_57_percent_of_the_delays_cost() -> None:
    tracking = experiments.track(DEFAULT, runs=RUNS)
    delayed = experiments.delay_and_compensate(tracking, DEFAULT.delay)
    late, compensated, undelayed = (delayed.mse("delayed").mean(),
                                    delayed.mse("predicted").mean(), tracking.mse().mean())
    share = (late - compensated) / (late - undelayed)
    assert round(100 * share, 1) == 56.7
