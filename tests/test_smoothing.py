"""The smoothers of issue 17 §1 against plain loops written here, and their tuner."""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import experiments, metrics, smoothing
from lqe_helpers.scenario import DEFAULT


def ewma_loop(y: np.ndarray, alpha: float) -> np.ndarray:
    """s_0 = y_0, s_j = (1 − α) s_{j−1} + α y_j, one sample at a time."""
    out = [float(y[0])]
    for value in y[1:]:
        out.append((1 - alpha) * out[-1] + alpha * float(value))
    return np.array(out)


def moving_average_loop(y: np.ndarray, window: int) -> np.ndarray:
    """Mean of y[max(0, j − N + 1) … j] for each j, one sample at a time."""
    return np.array([np.mean(y[max(0, j - window + 1):j + 1]) for j in range(len(y))])


@pytest.mark.parametrize("alpha", [0.01, 0.2, 0.5, 0.93, 1.0])
def test_exponential_smoother_matches_a_loop(alpha: float) -> None:
    y = np.random.default_rng(1).normal(5.0, 3.0, size=200)
    np.testing.assert_allclose(smoothing.exponential_smoother(y, alpha), ewma_loop(y, alpha),
                               rtol=1e-13, atol=1e-12)


def test_exponential_smoother_batches_runs_and_a_grid_of_weights_in_one_call() -> None:
    y = np.random.default_rng(2).normal(size=(4, 50))
    alphas = np.array([0.05, 0.3, 1.0])
    out = smoothing.exponential_smoother(y[:, None, :], alphas)
    assert out.shape == (4, 3, 50)
    for r in range(4):
        for g, alpha in enumerate(alphas):
            np.testing.assert_allclose(out[r, g], ewma_loop(y[r], alpha), rtol=1e-13,
                                       atol=1e-12)


def test_alpha_one_and_window_one_return_the_readings() -> None:
    y = np.random.default_rng(3).normal(size=(2, 30))
    np.testing.assert_array_equal(smoothing.exponential_smoother(y, 1.0), y)
    np.testing.assert_allclose(smoothing.moving_average(y, 1), y, rtol=0, atol=1e-14)


@pytest.mark.parametrize("window", [1, 2, 7, 30, 500])
def test_moving_average_matches_a_loop(window: int) -> None:
    y = np.random.default_rng(4).normal(10.0, 2.0, size=300)
    np.testing.assert_allclose(smoothing.moving_average(y, window),
                               moving_average_loop(y, window), rtol=1e-12, atol=1e-12)


def test_moving_average_batches_runs_and_windows() -> None:
    y = np.random.default_rng(5).normal(size=(3, 40))
    windows = np.array([1, 4, 40, 100])
    out = smoothing.moving_average(y[:, None, :], windows)
    assert out.shape == (3, 4, 40)
    for r in range(3):
        for g, window in enumerate(windows):
            np.testing.assert_allclose(out[r, g], moving_average_loop(y[r], window),
                                       rtol=1e-12, atol=1e-12)


def test_smoothers_are_causal() -> None:
    # Changing a future reading changes nothing before it.
    y = np.random.default_rng(6).normal(size=100)
    changed = y.copy()
    changed[60:] += 100.0
    for smooth in (lambda v: smoothing.exponential_smoother(v, 0.2),
                   lambda v: smoothing.moving_average(v, 9)):
        np.testing.assert_array_equal(smooth(y)[:60], smooth(changed)[:60])
        assert np.all(smooth(y)[60:] != smooth(changed)[60:])


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: smoothing.exponential_smoother(np.ones(5), 0.0),
         r"^alpha must be in \(0, 1\], got \[0.0\]$"),
        (lambda: smoothing.exponential_smoother(np.ones(5), [0.5, 1.5]),
         r"^alpha must be in \(0, 1\], got \[0.5, 1.5\]$"),
        (lambda: smoothing.exponential_smoother(np.ones(5), np.nan),
         r"^alpha must contain only finite numbers"),
        (lambda: smoothing.exponential_smoother(np.ones(5), True),
         r"^alpha must be a numeric array, got True: a boolean"),
        (lambda: smoothing.exponential_smoother(np.ones((2, 5)), [0.1, 0.2, 0.3]),
         r"^leading batch axes must broadcast against each other, got y \(2,\), alpha \(3,\)$"),
        (lambda: smoothing.exponential_smoother(5.0, 0.5),
         r"^y must have at least 1 axes"),
        (lambda: smoothing.moving_average(np.ones(5), 0),
         r"^window must be a whole number of samples >= 1 \(or an array of them\), got 0$"),
        (lambda: smoothing.moving_average(np.ones(5), 2.5), r"got 2.5$"),
        (lambda: smoothing.moving_average(np.ones(5), True), r"got True: a boolean"),
        (lambda: smoothing.moving_average(np.ones(5), "3"), r"got '3': text"),
        (lambda: smoothing.moving_average(np.ones(5), []), r"got \[\]$"),
        (lambda: smoothing.moving_average([1.0, np.inf], 2),
         r"^y must contain only finite numbers"),
        (lambda: smoothing.tune_smoother("ewma", np.ones((2, 5)), np.ones(5), [0.5]),
         r"^kind must be one of \('exponential', 'moving_average'\), got 'ewma'$"),
        (lambda: smoothing.tune_smoother("exponential", np.ones(5), np.ones(5), [0.5]),
         r"^y must have shape \(runs, n\) with runs >= 2, got shape \(5,\)$"),
    ],
)
def test_bad_input_names_the_parameter(call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()


def test_tuner_picks_the_grid_minimum_of_the_mean_mse() -> None:
    rng = np.random.default_rng(7)
    truth = np.sin(np.linspace(0, 6, 200))
    y = truth + 0.5 * rng.normal(size=(20, 200))
    alphas = np.array([0.02, 0.1, 0.3, 1.0])
    tuned = smoothing.tune_smoother("exponential", y, truth, alphas, burn_in_steps=10)
    by_hand = np.array([[np.mean((ewma_loop(run, a)[10:] - truth[10:]) ** 2) for a in alphas]
                        for run in y])
    np.testing.assert_allclose(tuned.mean_mse, by_hand.mean(axis=0), rtol=1e-12)
    best = int(np.argmin(by_hand.mean(axis=0)))
    assert tuned.best == alphas[best]
    np.testing.assert_allclose(tuned.mse, by_hand[:, best], rtol=1e-12)
    np.testing.assert_allclose(tuned.smoothed[3], ewma_loop(y[3], alphas[best]), rtol=1e-12)
    windows = smoothing.tune_smoother("moving_average", y, truth, [1, 5, 20], 10)
    assert windows.best in (1, 5, 20) and windows.mse.shape == (20,)


@pytest.mark.slow
def test_tuning_on_the_judged_draws_flatters_the_smoother_by_less_than_its_interval() -> None:
    # The best α chosen on the DEFAULT draws, judged on a fresh draw (seed + 1), costs no
    # more than the Monte Carlo interval's half width over the in-sample choice.
    import dataclasses

    alphas = np.linspace(0.02, 0.6, 59)
    truth = DEFAULT.truth[:, 0]
    tuned = {}
    for seed in (DEFAULT.seed, DEFAULT.seed + 1):
        scenario = dataclasses.replace(DEFAULT, seed=seed)
        y = experiments.track(scenario, runs=DEFAULT.mc_runs).measurements[..., 0]
        tuned[seed] = smoothing.tune_smoother("exponential", y, truth, alphas,
                                              DEFAULT.burn_in_steps)
    fresh = tuned[DEFAULT.seed + 1]
    chosen_elsewhere = fresh.mean_mse[np.flatnonzero(alphas == tuned[DEFAULT.seed].best)[0]]
    interval = metrics.mean_ci95(fresh.mse)
    assert chosen_elsewhere - fresh.mean_mse.min() < interval.half_width
