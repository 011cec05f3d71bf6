"""MSE, Monte Carlo intervals and convergence time."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from lqe_helpers import metrics


def test_mse_by_hand_and_burn_in() -> None:
    truth = np.zeros(4)
    estimate = np.array([[10.0, 1.0, 2.0, 3.0], [0.0, 0.0, 0.0, 2.0]])
    np.testing.assert_allclose(metrics.mse(estimate, truth), [114 / 4, 1.0])
    np.testing.assert_allclose(metrics.mse(estimate, truth, burn_in_steps=1), [14 / 3, 4 / 3])


def test_mse_refuses_nan_after_burn_in() -> None:
    estimate = np.array([np.nan, np.nan, 1.0, 1.0])
    with pytest.raises(ValueError, match="estimate must be finite after burn_in_steps = 1"):
        metrics.mse(estimate, np.zeros(4), burn_in_steps=1)
    assert metrics.mse(estimate, np.zeros(4), burn_in_steps=2) == 1.0


def test_mse_of_whole_state_estimates_names_the_position_column() -> None:
    # A student's (n, 3) estimates passed where the positions (n,) belong.
    with pytest.raises(ValueError, match=r"got shape \(6, 3\); .*pass column 0, the positions"):
        metrics.mse(np.zeros((6, 3)), np.zeros(6))
    with pytest.raises(ValueError, match=r"got shape \(5,\)$"):
        metrics.mse(np.zeros(5), np.zeros(6))


@pytest.mark.parametrize("df", [*range(1, 31), 31, 50, 299, 10_000])
def test_t_critical_matches_scipy(df: int) -> None:
    # The table holds 4 decimals (rounding error <= 5e-5); above it the docstring
    # promises the expansion to 1e-5.
    tolerance = 5e-5 if df <= 30 else 1e-5
    assert metrics.t_critical_95(df) == pytest.approx(stats.t.ppf(0.975, df), abs=tolerance)


def test_mean_ci95_matches_scipy_t_interval() -> None:
    samples = np.random.default_rng(0).normal(3.0, 2.0, size=40)
    interval = metrics.mean_ci95(samples)
    low, high = stats.t.interval(0.95, 39, loc=samples.mean(), scale=stats.sem(samples))
    assert interval.mean == pytest.approx(samples.mean())
    assert interval.low == pytest.approx(low, rel=1e-4)
    assert interval.high == pytest.approx(high, rel=1e-4)
    assert interval.runs == 40
    assert "95 % CI" in f"{interval:.2f}"


def test_mean_ci95_covers_the_true_mean_95_percent_of_the_time() -> None:
    rng = np.random.default_rng(1)
    draws = rng.exponential(1.0, size=(4000, 60))  # skewed, like per-run MSEs
    covered = [iv.low <= 1.0 <= iv.high for iv in map(metrics.mean_ci95, draws)]
    assert 0.93 <= np.mean(covered) <= 0.96


def test_convergence_time_definition() -> None:
    curve = np.concatenate([np.full(10, 50.0), [3.0, 1.5, 2.5], np.ones(87)])
    # Steady level = 1 (mean of second half); band = 2; last sample above 2 is index 12.
    assert metrics.convergence_time(curve, dt=0.1) == pytest.approx(1.3)
    assert metrics.convergence_time(np.ones(10), dt=0.1) == 0.0
    batch = np.stack([curve, np.ones(100)])
    np.testing.assert_allclose(metrics.convergence_time(batch, dt=0.1), [1.3, 0.0])


def test_convergence_time_interval_brackets_the_estimate() -> None:
    rng = np.random.default_rng(2)
    n = 400
    decay = 40 * np.exp(-np.arange(n) / 30.0) + 1.0
    errors = decay * rng.chisquare(1, size=(300, n))
    interval = metrics.convergence_time_ci95(errors, 0.01, np.random.default_rng(3))
    assert interval.low <= interval.mean <= interval.high
    # True curve: 40 e^{-t/30} + 1 crosses 2 at index 30 ln 40 ≈ 110.7 → 1.11 s.
    assert interval.low < 1.11 < interval.high


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: metrics.mean_ci95([1.0]), "samples must be a 1-D array of at least 2 runs"),
        (lambda: metrics.mean_ci95(0.14463), r"samples must be one value per run \(at least "
                                             r"2\), got one number \(0.14463\)"),
        (lambda: metrics.mean_ci95([1.0, np.nan]), "samples must contain only finite"),
        (
            lambda: metrics.mse(np.zeros(3), np.zeros(4)),
            r"estimate must have shape \(..., n\) with n = 4",
        ),
        (
            lambda: metrics.mse(np.zeros(4), np.zeros(4), burn_in_steps=4),
            r"burn_in_steps must be a whole number in \[0, 3\], got 4",
        ),
        (
            lambda: metrics.convergence_time(np.ones(10), 0.1, factor=1.0),
            "factor must be > 1, got 1.0",
        ),
        (lambda: metrics.convergence_time(-np.ones(10), 0.1), "squared_error must be >= 0"),
        (lambda: metrics.convergence_time(np.ones((300, 2)), 0.1),
         r"at least 10 samples along its last axis \(time\), got shape \(300, 2\)"),
        (lambda: metrics.convergence_time(np.ones(10), 0.0), "dt must be a finite number > 0 s"),
        (
            lambda: metrics.convergence_time_ci95(np.ones((1, 5)), 0.1, np.random.default_rng(0)),
            "runs >= 2",
        ),
        (lambda: metrics.t_critical_95(0), "df must be a whole number >= 1, got 0"),
        (
            lambda: metrics.mse(["near", "far"], np.zeros(2)),
            r"estimate must be a numeric array, got \['near', 'far'\]",
        ),
        (
            lambda: metrics.mse(np.zeros(4), np.zeros((2, 4))),
            r"truth must have shape \(n,\), got shape \(2, 4\)",
        ),
    ],
)
def test_bad_input(call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()


def test_fit_sinusoid_recovers_amplitude_and_lead():
    times = np.arange(0.0, 10.0, 0.01)
    omega = 2 * np.pi * 0.5
    leads = np.array([0.0, 0.03, -0.2])
    signal = np.array([[4.0], [10.0], [2.5]]) * np.sin(omega * (times + leads[:, None]))
    fit = metrics.fit_sinusoid(times, signal, 0.5)
    np.testing.assert_allclose(fit.amplitude, [4.0, 10.0, 2.5], rtol=1e-12)
    np.testing.assert_allclose(fit.lead, leads, atol=1e-12)


def test_fit_sinusoid_sign_matches_a_shifted_copy():
    # A signal that reaches its peak 0.05 s before sin(ωt) leads by +0.05 s.
    times = np.linspace(0.0, 4.0, 401)
    late = metrics.fit_sinusoid(times, np.sin(np.pi * (times - 0.05)), 0.5)
    assert late.lead == pytest.approx(-0.05, abs=1e-12)
    assert late.amplitude == pytest.approx(1.0)


def test_fit_sinusoid_ignores_independent_noise_on_average():
    rng = np.random.default_rng(3)
    times = np.arange(0.0, 10.0, 0.01)
    signal = 10 * np.sin(np.pi * times) + rng.standard_normal((200, times.size))
    fit = metrics.fit_sinusoid(times, signal, 0.5)
    assert abs(fit.amplitude.mean() - 10.0) < 0.01
    assert abs(fit.lead.mean()) < 1e-3
    assert fit.amplitude.shape == (200,)


@pytest.mark.parametrize(("times", "signal", "frequency", "name"), [
    (np.arange(5.0), np.zeros(4), 0.5, "signal"),
    (np.zeros((2, 2)), np.zeros(2), 0.5, "times"),
    (np.arange(5.0), np.zeros(5), 0.0, "frequency"),
    (np.arange(5.0), np.array([0, 1, np.nan, 0, 1]), 0.5, "signal"),
    (np.arange(5.0), np.zeros(5), 1.0, "times"),  # samples at whole periods: sin(ωt) = 0
])
def test_fit_sinusoid_bad_input(times, signal, frequency, name):
    with pytest.raises(ValueError, match=name):
        metrics.fit_sinusoid(times, signal, frequency)


def test_power_law_exponent_of_exact_power_laws():
    t = np.geomspace(0.01, 10.0, 50)
    assert metrics.power_law_exponent(t, 3.0 * t**2.5) == pytest.approx(2.5, abs=1e-12)
    assert metrics.power_law_exponent(t, 0.2 / t) == pytest.approx(-1.0, abs=1e-12)


@pytest.mark.parametrize(("x", "y", "name"), [
    ([1.0, 2.0], [1.0, 0.0], "y"),
    ([0.0, 2.0], [1.0, 2.0], "x"),
    ([1.0, 2.0, 3.0], [1.0, 2.0], "x and y"),
    ([2.0, 2.0], [1.0, 2.0], "x must not be all equal"),
])
def test_power_law_exponent_bad_input(x, y, name):
    with pytest.raises(ValueError, match=name):
        metrics.power_law_exponent(x, y)


def test_two_intervals_cannot_be_subtracted_the_runs_are_paired_first() -> None:
    first = metrics.mean_ci95(np.array([1.0, 2.0, 3.0]))
    with pytest.raises(TypeError, match="intervals cannot be subtracted: the difference of two "
                                        "conditions is mean_ci95 of their per-run differences"):
        first - first
    with pytest.raises(TypeError, match="intervals cannot be subtracted"):
        1.0 - first


def test_intervals_cannot_be_divided() -> None:
    a = metrics.mean_ci95(np.array([1.0, 2.0, 3.0]))
    for divide in (lambda: a / a, lambda: a / 2.0, lambda: 2.0 / a):
        with pytest.raises(TypeError, match="intervals cannot be divided: a share or ratio of "
                                            "two conditions is mean_ci95 of the per-run ratios"):
            divide()
