"""The number checks several notebooks share (check_mse, check_paired_difference).

They judge a student's number against the student's own arrays; the worked answer passes and
typical slips fail with their own message.
"""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, metrics, model, scenario, simulation
from lqe_helpers.filter import kalman_filter

# ------------------------------------------------------------------------------------------
# check_mse
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def tracking() -> dict[str, np.ndarray]:
    """Positions of the pack's scenario: truth, one run, and 20 Monte Carlo runs."""
    s = scenario.DEFAULT
    truth = s.truth[:, 0]
    noise = s.unit_noise(runs=20, sensors=("vision",))
    y = simulation.measure(truth, noise, [s.sigma_v])
    estimates = kalman_filter(y, s.A, model.observation_matrix(), s.Q,
                              model.measurement_noise_covariance([s.sigma_v]),
                              np.zeros(3), s.P0).estimates[..., 0]
    return {"truth": truth, "runs": estimates, "one": estimates[0], "burn": s.burn_in_steps}


def test_check_mse_passes_the_worked_solution(capsys, tracking) -> None:
    truth, one, runs, burn = (tracking[k] for k in ("truth", "one", "runs", "burn"))
    value = float(metrics.mse(one, truth, burn))
    line = assert_passes(capsys, checks.check_mse, value, one, truth, burn)
    assert "skipping the first 100 samples" in line and "rtol 1e-6" in line
    line = assert_passes(capsys, checks.check_mse, metrics.mse(runs, truth, burn), runs,
                         truth, burn)
    assert line.startswith("✓ 20 MSEs (one per run)")
    line = assert_passes(capsys, checks.check_mse, float(np.mean(metrics.mse(runs, truth))),
                         runs, truth)
    assert line.startswith("✓ mean MSE over 20 runs")
    # Within the stated tolerance, not beyond it.
    assert_passes(capsys, checks.check_mse, value * (1 + 5e-7), one, truth, burn)
    assert_fails("does not match", checks.check_mse, value * (1 + 1e-4), one, truth, burn)


def test_check_mse_names_each_typical_mistake(tracking) -> None:
    truth, one, burn = tracking["truth"], tracking["one"], tracking["burn"]
    error = one - truth
    cases = {
        "root mean squared error": np.sqrt(np.mean(error[burn:] ** 2)),
        "it is the MSE of the whole trial": np.mean(error ** 2),
        "sum of the squared errors": np.sum(error[burn:] ** 2),
        "the errors are not squared": np.mean(error[burn:]),
        "mean absolute error": np.mean(np.abs(error[burn:])),
        "MSE after skipping 1 sample, but burn_in_steps = 100": np.mean(error[1:] ** 2),
        "the errors are not squared (the mean error)": np.mean(error[burn:]),
    }
    for phrase, value in cases.items():
        assert_fails(phrase, checks.check_mse, value, one, truth, burn)


def test_check_mse_of_a_compensated_estimate_with_nan_rows(capsys, tracking) -> None:
    """Question (e): z* has NaN before δ; the burn-in skips them."""
    truth, one, burn = tracking["truth"], tracking["one"], tracking["burn"]
    compensated = np.concatenate([np.full(10, np.nan), one[:-10]])
    value = float(metrics.mse(compensated, truth, burn))
    assert_passes(capsys, checks.check_mse, value, compensated, truth, burn)
    assert_fails("root mean squared error", checks.check_mse, np.sqrt(value), compensated,
                 truth, burn)
    assert_fails("got NaN or inf at sample 0", checks.check_mse, value, compensated, truth)


def test_check_mse_wants_positions(tracking) -> None:
    states = np.stack([tracking["one"]] * 3, axis=-1)
    assert_fails("It expects positions (cm)", checks.check_mse, 1.0, states,
                 np.stack([tracking["truth"]] * 3, axis=-1))


def test_check_mse_refuses_what_is_not_a_number() -> None:
    truth = np.zeros(5)
    assert_fails("your MSE must be one number or one per run (cm²), got None",
                 checks.check_mse, None, np.ones(5), truth)
    assert_fails("got a complex number", checks.check_mse, 1 + 0j, np.ones(5), truth)
    assert_fails("burn_in_steps must be a whole number of samples >= 0, got 1.5",
                 checks.check_mse, 1.0, np.ones(5), truth, 1.5)
    assert_fails("estimate must be positions (cm), shape (n,) or (runs, n), got values too "
                 "large to square", checks.check_mse, 1.0, np.full(5, 1e200), truth)


# ------------------------------------------------------------------------------------------
# check_paired_difference
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def paired() -> tuple[np.ndarray, np.ndarray]:
    """Per-run MSEs of two filters on the same noise: strongly correlated."""
    rng = np.random.default_rng(12)
    shared = rng.gamma(20.0, 0.05, size=300)
    return shared + 0.05 + 0.02 * rng.normal(size=300), shared + 0.02 * rng.normal(size=300)


def test_check_paired_difference_passes_the_worked_solution(capsys, paired) -> None:
    first, second = paired
    line = assert_passes(capsys, checks.check_paired_difference,
                         metrics.mean_ci95(first - second), first, second)
    assert "over 300 runs" in line


def test_check_paired_difference_names_each_typical_mistake(paired) -> None:
    first, second = paired
    n = first.size
    right = metrics.mean_ci95(first - second)
    t = metrics.t_critical_95(n - 1)
    s = float(np.std(first - second, ddof=1))
    half_unpaired = t * np.sqrt((np.var(first, ddof=1) + np.var(second, ddof=1)) / n)

    def around(half: float) -> metrics.Interval:
        return metrics.Interval(right.mean, right.mean - half, right.mean + half, n)

    a, b = metrics.mean_ci95(first), metrics.mean_ci95(second)
    cases = [
        ("the sign is reversed", metrics.mean_ci95(second - first)),
        ("treats the two as independent samples (unpaired)", around(half_unpaired)),
        ("combines the two separate intervals",
         metrics.Interval(a.mean - b.mean, a.low - b.high, a.high - b.low, n)),
        ("uses the standard deviation of the differences", around(t * s)),
        ("the normal 1.96", around(1.959963984540054 * s / np.sqrt(n))),
        ("interval is a pair of numbers", (right.low, right.high)),
        ("interval is a number", right.mean),
        ("interval is over 299 runs", metrics.mean_ci95((first - second)[1:])),
    ]
    for phrase, interval in cases:
        assert_fails(phrase, checks.check_paired_difference, interval, first, second)


def test_check_paired_difference_validates_its_arrays(paired) -> None:
    first, second = paired
    right = metrics.mean_ci95(first - second)
    assert_fails("mse_first must be one MSE per Monte Carlo run (cm²), shape (runs,), got None",
                 checks.check_paired_difference, right, None, second)
    assert_fails("mse_second must hold one MSE per Monte Carlo run, shape (runs,) with runs "
                 ">= 2, got shape (1,)", checks.check_paired_difference, right, first,
                 second[:1])
    assert_fails("your interval.mean must be one number, got a complex number",
                 checks.check_paired_difference,
                 metrics.Interval(right.mean + 0j, right.low, right.high, right.runs),
                 first, second)
