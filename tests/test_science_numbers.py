"""Issue 17 §4: the numbers the notebooks will state, measured on DEFAULT (300 runs, seed 5).

Each assertion pins a number the report to the lead quotes, to its printed precision, so
prose that states it stays true.
"""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import experiments, fixed_gain, jerk_tuning, metrics, smoothing
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


# ---------------------------------------------------------------- issue 23 §5, the review


def test_01_filtering_lowers_the_mse_in_every_run(vision_batch) -> None:
    """01's answer (a) says "every run" because its count cell prints 300 of 300."""
    below = np.sum(vision_batch.mse() < vision_batch.measurement_mse("vision"), axis=0)
    assert below.tolist() == [RUNS, RUNS]


def test_01_the_lqe_averages_harder_than_the_smoother_at_1_5_cm_slightly_less_at_4_5(
        vision_batch) -> None:
    """01's "What does the model of motion buy?": the noise parts part 2 prints."""
    alphas = np.linspace(0.02, 0.6, 30)                 # 01's grid
    noise = {}
    for i, sigma in enumerate((1.5, 4.5)):
        tuned = smoothing.tune_smoother("exponential", vision_batch.measurements[:, i, :, 0],
                                        TRUTH, alphas, BURN)
        clean = smoothing.exponential_smoother(TRUTH, tuned.best)
        lqe_clean = experiments.track(DEFAULT, sigmas=[sigma],
                                      noise=np.zeros((DEFAULT.n_steps, 1))).positions
        noise[sigma] = (np.mean((tuned.smoothed[:, BURN:] - clean[BURN:]) ** 2),
                        np.mean((vision_batch.positions[:, i, BURN:] - lqe_clean[BURN:]) ** 2))
    smoother, lqe = noise[1.5]
    assert lqe < 0.8 * smoother                          # harder at 1.5 cm
    smoother, lqe = noise[4.5]
    assert smoother < lqe < 1.1 * smoother               # slightly less at 4.5 cm
    assert (round(smoother, 2), round(lqe, 2)) == (2.00, 2.16)


def test_01_a_fixed_gain_tuned_on_the_truth_does_slightly_better_than_the_lqe(
        vision_batch) -> None:
    """01's Going further 1: the tuned fixed gain wins by a small margin whose interval lies
    below zero at both σ_v; at 4.5 cm even the fixed K∞ beats the LQE after the first second."""
    for i, sigma in enumerate((1.5, 4.5)):
        model = experiments.filter_model(DEFAULT, ("vision",), [sigma])
        tuned = fixed_gain.tune_fixed_gain(vision_batch.measurements[:, i], model.A, model.C,
                                           model.z0, TRUTH, model.steady_state().gain, BURN)
        lqe = vision_batch.mse()[:, i]
        margin = metrics.mean_ci95(tuned.mse - lqe)
        assert margin.high < 0 and -margin.mean < 0.05 * lqe.mean()
        if sigma == 4.5:
            assert metrics.mean_ci95(tuned.start_mse - lqe).high < 0


def test_00_01_what_the_readings_and_the_truth_pick_for_sigma_j() -> None:
    """00's Going further E and 01's Going further 1, on 00's grid: the matched σ_j lies a few
    per cent above the MSE's optimum; one run's likelihood picks within a tenth of it (95 %
    of runs, refined between grid points); the NIS's choice lies more than a tenth below."""
    choice = jerk_tuning.tune_jerk_std(DEFAULT, np.geomspace(700.0, 2800.0, 17))
    best = choice.by_mse
    assert round(best) == 1339 and round(DEFAULT.process_jerk_std) == 1396
    assert 0 < DEFAULT.process_jerk_std / best - 1 < 0.05
    low, high = np.percentile(choice.by_likelihood_per_run, [2.5, 97.5])
    assert -0.1 < low / best - 1 < 0 < high / best - 1 < 0.1
    assert -0.15 < choice.by_nis / best - 1 < -0.1
    assert round(100 * (choice.by_nis / best - 1)) == -12


def test_02_after_2_s_the_two_p0s_differ_by_less_than_1e_5_of_the_mse() -> None:
    batch = experiments.track(DEFAULT, p0_variance=[1.0, 1e5], runs=RUNS)
    late = metrics.mse(batch.positions, TRUTH, 2 * BURN)                 # (runs, 2)
    difference = metrics.mean_ci95(late[:, 0] - late[:, 1])
    largest = max(abs(difference.low), abs(difference.high)) / late[:, 1].mean()
    assert difference.low < 0 < difference.high and largest < 1e-5
