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
    elif mistake == "A once":
        ahead = A
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
    line = assert_passes(capsys, checks.check_compensation, student_compensate)
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
    "A once": "A is applied once, not δ times",
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
        estimates[:] = student_compensate(estimates, A, delay_steps)
        return estimates

    assert_fails("compensate changed its input estimates in place", checks.check_compensation,
                 compensate)


def test_check_compensation_refuses_the_packs_own_eq7() -> None:
    """Issue 15 §2: calling the pack's answer is not writing eq. (7)."""
    from lqe_helpers import prediction
    from lqe_helpers.prediction import predict_ahead as ahead

    def compensate(estimates, A, delay_steps):
        return prediction.predict_ahead(estimates, A, delay_steps)

    def renamed(estimates, A, delay_steps):
        try:
            return ahead(estimates, A, delay_steps)
        except Exception:
            return reference.compensate(estimates, A, delay_steps)

    for function in (compensate, renamed, prediction.predict_ahead):
        assert_fails("runs the pack's own lqe_helpers.prediction.predict_ahead",
                     checks.check_compensation, function)


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
        return student_compensate(estimates, A, delay_steps) * 1e200

    assert_fails("compensate returned values too large to square", checks.check_compensation,
                 compensate)

    def with_inf(estimates, A, delay_steps):
        out = student_compensate(estimates, A, delay_steps)
        out[-1, 0] = np.inf
        return out

    assert_fails("with_inf returned an infinite value at index (11, 0)",
                 checks.check_compensation, with_inf)


# ------------------------------------------------------------------------------------------
# check_delay_signals (Task 2)
# ------------------------------------------------------------------------------------------

TRUTH = DEFAULT.truth[:, 0]
STEPS = DEFAULT.delay_steps(DEFAULT.delay)
#: Task 2's given inputs: the trial's readings (n, 1) and the model of the vision-only filter.
READINGS = simulation.measure(TRUTH, DEFAULT.unit_noise(sensors=("vision",)), [DEFAULT.sigma_v])
VISION = experiments.filter_model(DEFAULT)


def unguarded_filter(y, A, C, Q, R, z0, P0):
    """A student's eq. (5) loop, which (unlike the oracle) does not refuse NaN readings."""
    return reference.student_lqe_filter(y, A, C, Q, R, z0, P0)


def task2(slip: str = "") -> tuple:
    """Task 2 as a student writes it (the notebook's worked code), with one ``slip``.

    Returns (late_readings, delayed, compensated).
    """
    y, m = (READINGS / 100 if slip == "metres" else READINGS), VISION
    steps = STEPS + (slip == "one sample late")
    late_y = simulation.delay_signal(y, steps)
    if slip == "filter the late readings":
        estimates = unguarded_filter(late_y, m.A, m.C, m.Q, m.R, m.z0, m.P0)
    else:
        estimates = reference.lqe_filter(y, m.A, m.C, m.Q, m.R, m.z0, m.P0)   # my_filter
    late_readings = late_y[:, 0]
    if slip == "np.roll":
        late_readings = np.roll(y, steps, axis=0)[:, 0]
    elif slip == "truth seen late":
        late_readings = simulation.delay_signal(TRUTH, steps, axis=-1)
    column = 1 if slip == "velocity column" else 0
    delayed_states = simulation.delay_signal(estimates, steps)
    delayed = {"whole states": delayed_states, "not delayed": estimates[:, 0],
               "late readings": late_readings}.get(slip, delayed_states[:, column])
    source = delayed_states if slip == "compensate the delayed" else estimates
    compensated = student_compensate(source, DEFAULT.A, steps,
                                     mistake="A once" if slip == "A once" else "")[:, column]
    return late_readings, delayed, compensated


def test_check_delay_signals_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_delay_signals, *task2())
    assert "(δ = 10 samples) match the pack's engine on the scenario's draw to 1e-9" in line


def test_task2_inputs_are_those_of_the_engine() -> None:
    """The readings and model the notebook gives are the scenario's trial: the check's draw."""
    tracking = experiments.track(DEFAULT)
    np.testing.assert_array_equal(READINGS, tracking.measurements)
    np.testing.assert_allclose(reference.lqe_filter(READINGS, *(
        getattr(VISION, name) for name in ("A", "C", "Q", "R", "z0", "P0"))),
        tracking.result.estimates, rtol=0, atol=1e-10)


@pytest.mark.parametrize(("slip", "phrase"), [
    ("compensate the delayed", "compensated is not right: compensate was given the delayed "
                               "estimates, so it predicts from 2δ samples back"),
    ("one sample late", "late_readings is not right: the delay is one sample too long (δ + 1)"),
    ("late readings", "delayed is not right: it holds the late readings, not the delayed "
                      "estimate"),
    ("np.roll", "late_readings is not right: it was shifted with np.roll, which wraps"),
    ("whole states", "delayed has shape (1000, 3), whole states (p, v, a) per row: keep only "
                     "the positions, column 0"),
    ("not delayed", "delayed is not right: it is not delayed: these are the estimates as the "
                    "filter made them"),
    ("truth seen late", "late_readings is not right: it holds the true position seen late"),
    ("velocity column", "delayed is not right: it holds velocities (column 1 of the states"),
    ("A once", "compensated is not right: A is applied once, not δ times"),
    ("metres", "late_readings is not right: the readings are in metres"),
    ("filter the late readings", "delayed is NaN at every sample, also after j = δ = 10: was "
                                 "your my_filter run on the late readings?"),
])
def test_check_delay_signals_names_the_cause_of_wrong_science(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_delay_signals, *task2(slip))


def test_check_delay_signals_names_the_velocity_column_of_the_compensation() -> None:
    late, delayed, _ = task2()
    *_, velocities = task2("velocity column")
    assert_fails("compensated is not right: it holds velocities (column 1 of the states",
                 checks.check_delay_signals, late, delayed, velocities)


def test_check_delay_signals_catches_the_compensation_that_reverses_the_answer() -> None:
    """Issue 15: compensating the wrong estimates makes compensation look useless."""
    skip = max(DEFAULT.burn_in_steps, STEPS)

    def mse(x):
        return np.mean((x[skip:] - TRUTH[skip:]) ** 2)

    _, delayed, wrong = task2("compensate the delayed")
    assert mse(wrong) > 0.95 * mse(delayed) > 2 * mse(task2()[2])   # the benefit of (e) is gone
    assert_fails("given the delayed estimates", checks.check_delay_signals,
                 *task2("compensate the delayed"))


def test_check_delay_signals_asks_about_the_compensation_not_my_filter() -> None:
    """An unrecognised compensation is asked about A^δ and ẑ_(j−δ), not only my_filter."""
    late, delayed, compensated = task2()
    twisted = compensated + 0.5 * np.sin(np.arange(compensated.size))
    message = assert_fails("compensated does not match the signal recomputed",
                           checks.check_delay_signals, late, delayed, twisted)
    assert "which power of A moves it (A^δ" in message


def test_check_delay_signals_names_the_estimates_of_readings_in_metres() -> None:
    late, _, _ = task2()
    _, delayed, compensated = task2("metres")
    assert_fails("delayed is not right: the readings are in metres",
                 checks.check_delay_signals, late, delayed, compensated)
    right = task2()
    assert_fails("compensated is not right: the readings are in metres",
                 checks.check_delay_signals, late, right[1], compensated)


def test_check_delay_signals_names_nan_in_the_wrong_places() -> None:
    late, delayed, compensated = task2()
    shifted = compensated.copy()
    shifted[STEPS] = np.nan
    assert_fails("compensated must be NaN in exactly its first δ = 10 samples (nothing has "
                 "arrived before j = δ) and a number after; yours has NaN in 11 samples",
                 checks.check_delay_signals, late, delayed, shifted)


def test_check_delay_signals_refuses_another_draw() -> None:
    """Signals from another noise draw agree with each other but not with the task's."""
    other = scenario.Scenario(seed=DEFAULT.seed + 1)
    tracking = experiments.track(other)
    late = simulation.delay_signal(tracking.measurements, STEPS)[:, 0]
    _, delayed, compensated = task2()
    assert_fails("late_readings does not match the signal recomputed from the task's inputs",
                 checks.check_delay_signals, late, delayed, compensated)


def test_check_delay_signals_wants_arrays_of_positions() -> None:
    late, delayed, compensated = task2()
    assert_fails("late_readings must be positions (cm), an array of shape (1000,), got None",
                 checks.check_delay_signals, None, delayed, compensated)
    assert_fails("delayed must be positions (cm) of shape (1000,), one per sample, got shape "
                 "(990,)", checks.check_delay_signals, late, delayed[STEPS:], compensated)
    assert_fails("compensated has shape (1000, 1), one column per row",
                 checks.check_delay_signals, late, delayed, compensated[:, None])


# ------------------------------------------------------------------------------------------
# check_delay_difference (Task 3)
# ------------------------------------------------------------------------------------------


def task3(slip: str = "") -> tuple:
    """Task 3 as a student writes it (the notebook's worked code), with one ``slip``.

    Returns (gain, won_back).
    """
    tracking_mc = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    batch = experiments.delay_and_compensate(tracking_mc, DEFAULT.delay)
    mse_delayed, mse_predicted = batch.mse("delayed"), batch.mse("predicted")
    mse_now = tracking_mc.mse()
    gain = metrics.mean_ci95(mse_delayed - mse_predicted)
    won_back = metrics.mean_ci95((mse_delayed - mse_predicted) / (mse_delayed - mse_now))
    if slip == "reversed":
        gain = metrics.mean_ci95(mse_predicted - mse_delayed)
    elif slip == "against no delay":
        gain = metrics.mean_ci95(mse_delayed - mse_now)
    elif slip == "separate intervals":
        a, b = metrics.mean_ci95(mse_delayed), metrics.mean_ci95(mse_predicted)
        gain = metrics.Interval(a.mean - b.mean, a.low - b.high, a.high - b.low, a.runs)
    elif slip == "difference of means":
        gain = mse_delayed.mean() - mse_predicted.mean()
    elif slip == "fewer runs":
        gain = metrics.mean_ci95((mse_delayed - mse_predicted)[:100])
    elif slip == "share of the delayed MSE":
        won_back = metrics.mean_ci95(1 - mse_predicted / mse_delayed)
    elif slip == "share left":
        won_back = metrics.mean_ci95((mse_predicted - mse_now) / (mse_delayed - mse_now))
    elif slip == "per cent":
        won_back = metrics.mean_ci95(100 * (mse_delayed - mse_predicted)
                                     / (mse_delayed - mse_now))
    elif slip == "ratio of means":
        won_back = ((mse_delayed.mean() - mse_predicted.mean())
                    / (mse_delayed.mean() - mse_now.mean()))
    elif slip == "upside down":
        won_back = metrics.mean_ci95((mse_delayed - mse_now) / (mse_delayed - mse_predicted))
    elif slip == "numerator without parentheses":
        won_back = metrics.mean_ci95(mse_delayed - mse_predicted / (mse_delayed - mse_now))
    elif slip == "denominator without parentheses":
        won_back = metrics.mean_ci95((mse_delayed - mse_predicted) / mse_delayed - mse_now)
    elif slip == "divided by the undelayed MSE":
        won_back = metrics.mean_ci95((mse_delayed - mse_predicted) / mse_now)
    elif slip == "compensated over delayed":
        won_back = metrics.mean_ci95(mse_predicted / mse_delayed)
    elif slip == "denominator reversed":
        won_back = metrics.mean_ci95((mse_delayed - mse_predicted) / (mse_now - mse_delayed))
    elif slip == "numerator reversed":
        won_back = metrics.mean_ci95((mse_predicted - mse_delayed) / (mse_delayed - mse_now))
    elif slip == "names swapped":
        gain, won_back = won_back, gain
    return gain, won_back


def test_check_delay_difference_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_delay_difference, *task3())
    assert "delayed − compensated MSE, paired over 300 runs, and the share" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("reversed", "gain is not right: the sign is reversed"),
    ("against no delay", "it compares the delayed estimate with the filter without delay"),
    ("separate intervals", "it combines the two separate intervals"),
    ("difference of means", "gain is a number; it must be the metrics.Interval"),
    ("fewer runs", "gain is over 100 runs, but the task has 300"),
    ("share of the delayed MSE", "won_back is not right: it is the share of the delayed MSE"),
    ("share left", "won_back is not right: it is the share of the delay's cost that is left"),
    ("per cent", "won_back is not right: it is in per cent"),
    ("ratio of means", "won_back is a number; it must be the metrics.Interval"),
    ("upside down", "won_back is not right: the ratio is upside down"),
    ("numerator without parentheses", "won_back is not right: the numerator's parentheses "
                                      "are missing"),
    ("denominator without parentheses", "won_back is not right: the denominator's "
                                        "parentheses are missing"),
    ("divided by the undelayed MSE", "won_back is not right: it divides by the undelayed MSE"),
    ("compensated over delayed", "won_back is not right: it is compensated / delayed"),
    ("names swapped", "gain is not right: it is the share of the delay's cost won back"),
    ("denominator reversed", "won_back is not right: one of its two differences is reversed"),
    ("numerator reversed", "won_back is not right: one of its two differences is reversed"),
])
@pytest.mark.slow
def test_check_delay_difference_names_the_cause(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_delay_difference, *task3(slip))


def test_check_delay_difference_judges_against_the_engine() -> None:
    other = scenario.Scenario(seed=DEFAULT.seed + 1)
    tracking = experiments.track(other, runs=DEFAULT.mc_runs)
    batch = experiments.delay_and_compensate(tracking, DEFAULT.delay)
    delayed, predicted = batch.mse("delayed"), batch.mse("predicted")
    gain = metrics.mean_ci95(delayed - predicted)
    won_back = metrics.mean_ci95((delayed - predicted) / (delayed - tracking.mse()))
    assert_fails("does not match the paired difference delayed − compensated MSE",
                 checks.check_delay_difference, gain, task3()[1])
    assert_fails("won_back (mean 0.5", checks.check_delay_difference, task3()[0], won_back)


def test_check_compensation_says_float32_keeps_too_few_digits() -> None:
    def compensate(estimates, A, delay_steps):
        return student_compensate(estimates, A, delay_steps).astype(np.float32)

    assert_fails("compensate returned float32 numbers, which keep only about 6 digits: compute "
                 "in float64", checks.check_compensation, compensate)
