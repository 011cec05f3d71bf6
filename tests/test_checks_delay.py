"""Checks of notebook 05: the worked answers pass, realistic wrong answers fail saying why.

The wrong answers are written here as a student would write them (the task's own code with
one slip), independently of the mistakes :mod:`lqe_helpers.checks` computes to recognise
them. The worked compensation is the test oracle ``reference_loops`` (outside the package).
"""

from __future__ import annotations

import numpy as np
import pytest
import reference_loops as reference
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, experiments, metrics, scenario, simulation
from lqe_helpers.scenario import DEFAULT

# ------------------------------------------------------------------------------------------
# check_compensation
# ------------------------------------------------------------------------------------------


def student_compensate(estimates, A, delay_steps, *, mistake: str = ""):
    """A student's eq. (7), optionally with one mistake."""
    n, k = estimates.shape
    d = delay_steps
    ahead = np.linalg.matrix_power(A, d)
    if mistake == "A**d":
        ahead = A ** d
    elif mistake == "A*d":
        ahead = A * d
    elif mistake == "power d-1":
        ahead = np.linalg.matrix_power(A, d - 1)
    elif mistake == "no A":
        ahead = np.eye(k)
    fill = 0.0 if mistake == "zeros before" else np.nan
    out = np.full((n, k), fill)
    if mistake == "no shift":
        return estimates @ ahead.T
    if mistake == "shift d+1":
        for j in range(d + 1, n):
            out[j] = ahead @ estimates[j - d - 1]
        return out
    if mistake == "only existing rows":
        return estimates[: n - d] @ ahead.T
    if mistake == "slice from the end":
        out[d:] = estimates[:-d] @ ahead.T       # empty when d = 0
        return out
    if mistake == "row times matrix":
        out[d:] = estimates[: n - d] @ ahead
        return out
    if mistake == "estimates before":
        out[:d] = estimates[:d]
    for j in range(d, n):
        out[j] = ahead @ estimates[j - d]
    return out


def test_check_compensation_passes_the_worked_solution(capsys) -> None:
    line = assert_passes(capsys, checks.check_compensation, reference.compensate)
    assert "compensate matches eq. (7)" in line


COMPENSATION_MISTAKES = {
    "A**d": "A^δ is computed entry by entry",
    "A*d": "A is multiplied by the number δ (A·δ)",
    "power d-1": "one power of A too few",
    "no A": "A is not used",
    "no shift": "there is no shift",
    "shift d+1": "your row j uses the estimate ẑ_(j−δ−1)",
    "zeros before": "rows before j = δ hold zeros",
    "estimates before": "rows before j = δ hold the estimates ẑ_j themselves",
    "only existing rows": "only the rows that exist",
    "slice from the end": "slices that count from the end",
    "row times matrix": "A^δ is applied from the wrong side",
}


@pytest.mark.parametrize("mistake", COMPENSATION_MISTAKES)
def test_check_compensation_names_each_typical_mistake(mistake: str) -> None:
    def compensate(estimates, A, delay_steps):
        return student_compensate(estimates, A, delay_steps, mistake=mistake)

    message = assert_fails(COMPENSATION_MISTAKES[mistake], checks.check_compensation,
                           compensate)
    others = [p for m, p in COMPENSATION_MISTAKES.items() if m != mistake and p in message]
    assert not others, message


def test_check_compensation_rejects_a_hard_coded_answer() -> None:
    s = scenario.DEFAULT
    fixed = reference.compensate(s.truth, s.A, 10)

    def compensate(estimates, A, delay_steps):
        return fixed

    assert_fails("returned an array of shape (1000, 3)", checks.check_compensation, compensate)


def test_check_compensation_rejects_changing_the_estimates_in_place() -> None:
    def compensate(estimates, A, delay_steps):
        estimates[:] = reference.compensate(estimates, A, delay_steps)
        return estimates

    assert_fails("compensate changed its input estimates in place", checks.check_compensation,
                 compensate)


def test_check_compensation_says_not_written_yet() -> None:
    def compensate(estimates, A, delay_steps):
        raise NotImplementedError

    assert_fails("compensate is not written yet", checks.check_compensation, compensate)


def test_check_compensation_stops_an_endless_loop(monkeypatch) -> None:
    from lqe_helpers.student_code import calling

    monkeypatch.setattr(calling, "TIME_LIMIT", 0.2)

    def compensate(estimates, A, delay_steps):
        z_star = np.full(estimates.shape, np.nan)
        j = delay_steps
        while j < len(estimates):
            z_star[j] = A @ estimates[j - delay_steps]    # j is never increased
        return z_star

    assert_fails("compensate did not return within 0.2 s (in compensate, line",
                 checks.check_compensation, compensate)


def test_check_compensation_refuses_inf_and_huge_values() -> None:
    def compensate(estimates, A, delay_steps):
        return reference.compensate(estimates, A, delay_steps) * 1e200

    assert_fails("compensate returned values too large to square", checks.check_compensation,
                 compensate)

    def with_inf(estimates, A, delay_steps):
        out = reference.compensate(estimates, A, delay_steps)
        out[-1, 0] = np.inf
        return out

    assert_fails("with_inf returned an infinite value at index (11, 0)",
                 checks.check_compensation, with_inf)


# ------------------------------------------------------------------------------------------
# check_delay_mse (Task 2)
# ------------------------------------------------------------------------------------------

TRUTH = DEFAULT.truth[:, 0]
BURN = DEFAULT.burn_in_steps


def task2(slip: str = "") -> tuple[float, float]:
    """Task 2 as a student writes it (the notebook's worked code), with one ``slip``."""
    steps = DEFAULT.delay_steps(DEFAULT.delay) + (slip == "one sample late")
    tracking = experiments.track(DEFAULT)
    estimates = tracking.result.estimates
    late_readings = simulation.delay_signal(tracking.measurements, steps)[:, 0]
    delayed_estimates = simulation.delay_signal(estimates, steps)
    delayed = late_readings if slip == "late readings" else delayed_estimates[:, 0]
    source = delayed_estimates if slip == "compensate the delayed" else estimates
    compensated = student_compensate(source, DEFAULT.A, steps)[:, 0]
    skip = {"whole trial": 0, "skip only delta": steps}.get(slip, max(BURN, steps))
    mse_delayed_run = np.mean((delayed[skip:] - TRUTH[skip:]) ** 2)
    mse_compensated_run = np.mean((compensated[skip:] - TRUTH[skip:]) ** 2)
    if slip == "swapped":
        return mse_compensated_run, mse_delayed_run
    return mse_delayed_run, mse_compensated_run


def test_check_delay_mse_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_delay_mse, *task2())
    assert "δ = 10 samples, after the first 100" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("compensate the delayed", "mse_compensated_run = 4.96517 cm² is not right"),
    ("compensate the delayed", "the compensation was applied to the delayed estimates"),
    ("whole trial", "mse_delayed_run is NaN (not a number): the first δ samples"),
    ("skip only delta", "it leaves out only the first δ = 10 samples; leave out the burn-in too"),
    ("swapped", "mse_delayed_run = 1.9"),
    ("swapped", "it is the MSE of the compensated estimate, not of the delayed one"),
    ("one sample late", "mse_delayed_run = 5.99762 cm² is not right"),
    ("one sample late", "the delay is one sample too long (δ + 1)"),
    ("late readings", "it is the MSE of the late readings, not of an estimate"),
])
def test_check_delay_mse_names_the_cause_of_wrong_science(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_delay_mse, *task2(slip))


def test_check_delay_mse_catches_the_compensation_that_reverses_the_answer() -> None:
    """Issue 15: compensating the wrong estimates makes compensation look useless."""
    delayed, compensated = task2("compensate the delayed")
    assert compensated > 0.95 * delayed > 2 * task2()[1]   # the benefit of (e) is gone
    assert_fails("applied to the delayed estimates", checks.check_delay_mse, delayed,
                 compensated)


def test_check_delay_mse_wants_numbers() -> None:
    delayed, compensated = task2()
    assert_fails("mse_delayed_run must be one number (cm²), got None", checks.check_delay_mse,
                 None, compensated)
    assert_fails("mse_compensated_run must be one number (cm²), got text ('1.92')",
                 checks.check_delay_mse, delayed, "1.92")
    assert_fails("mse_compensated_run must be one number (cm²), got values too large to square",
                 checks.check_delay_mse, delayed, 1e300)


# ------------------------------------------------------------------------------------------
# check_delay_difference (Task 3)
# ------------------------------------------------------------------------------------------


def task3(slip: str = ""):
    """Task 3 as a student writes it (the notebook's worked code), with one ``slip``."""
    tracking_mc = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    batch = experiments.delay_and_compensate(tracking_mc, DEFAULT.delay)
    mse_delayed, mse_predicted = batch.mse("delayed"), batch.mse("predicted")
    mse_now = tracking_mc.mse()
    if slip == "reversed":
        return metrics.mean_ci95(mse_predicted - mse_delayed)
    if slip == "against no delay":
        return metrics.mean_ci95(mse_delayed - mse_now)
    if slip == "separate intervals":
        a, b = metrics.mean_ci95(mse_delayed), metrics.mean_ci95(mse_predicted)
        return metrics.Interval(a.mean - b.mean, a.low - b.high, a.high - b.low, a.runs)
    if slip == "difference of means":
        return mse_delayed.mean() - mse_predicted.mean()
    if slip == "fewer runs":
        return metrics.mean_ci95((mse_delayed - mse_predicted)[:100])
    return metrics.mean_ci95(mse_delayed - mse_predicted)


def test_check_delay_difference_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_delay_difference, task3())
    assert "delayed − compensated MSE, paired over 300 runs" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("reversed", "gain is not right: the sign is reversed"),
    ("against no delay", "it compares the delayed estimate with the filter without delay"),
    ("separate intervals", "it combines the two separate intervals"),
    ("difference of means", "gain is a number; it must be the metrics.Interval"),
    ("fewer runs", "gain is over 100 runs, but the task has 300"),
])
def test_check_delay_difference_names_the_cause(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_delay_difference, task3(slip))


def test_check_delay_difference_judges_against_the_engine() -> None:
    other = scenario.Scenario(seed=DEFAULT.seed + 1)
    batch = experiments.delay_and_compensate(experiments.track(other, runs=DEFAULT.mc_runs),
                                             DEFAULT.delay)
    gain = metrics.mean_ci95(batch.mse("delayed") - batch.mse("predicted"))
    assert_fails("does not match the paired difference delayed − compensated MSE",
                 checks.check_delay_difference, gain)


def test_check_compensation_says_float32_keeps_too_few_digits() -> None:
    def compensate(estimates, A, delay_steps):
        return reference.compensate(estimates, A, delay_steps).astype(np.float32)

    assert_fails("compensate returned float32 numbers, which keep only about 6 digits: compute "
                 "in float64", checks.check_compensation, compensate)
