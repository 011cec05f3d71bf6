"""Checks of notebook 05, question (e): the delay compensation z*_j = A^δ ẑ_(j−δ) and its worth.

- :func:`check_compensation` (Task 1): the student's ``compensate`` on random cases,
  against the pack's :func:`lqe_helpers.prediction.predict_ahead`;
- :func:`check_delay_signals` (Task 2): the late readings, the delayed and the
  compensated position of one run, recomputed from the scenario's draw with the engine;
- :func:`check_delay_difference` (Task 3): the paired delayed − compensated difference
  over the Monte Carlo runs and the share of the delay's cost won back, recomputed with
  :mod:`lqe_helpers.experiments`.

Task 3's runs are :func:`lqe_helpers.checks.shared_runs.vision_runs`. The Going further
tasks are checked in :mod:`lqe_helpers.checks.delay_sweep` and
:mod:`lqe_helpers.checks.delay_further`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .. import experiments, metrics
from ..prediction import predict_ahead
from ..scenario import DEFAULT
from ..simulation import delay_signal
from . import compensation_cases
from .compensation_cases import COMPENSATE_ARGS, COMPENSATION_MISTAKES, Case, mistaken
from .judging import CM_PER_M, judge_interval
from .machinery import (
    FUNCTION_RTOL,
    INTERVAL_RTOL,
    MISTAKE_RTOL,
    CheckFailed,
    argument_array,
    call_student,
    close,
    match_mistake,
    passed,
    require_callable,
    student_result,
    time_limit_text,
    tolerance_text,
)
from .own_work import FUNCTION_TASKS
from .paired_mistakes import interval_mistakes, unit_mistakes
from .remembering import remembered
from .shared_runs import vision_runs

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

_SHAPE_HINT = (
    "The shapes in one product or assignment do not fit: write the shape beside each "
    "term (the estimates are (n, k), one estimate ẑ_j is (k,), A^δ is (k, k)).")
_ZERO_DELAY_HINT = (
    "With delay_steps = 0 there is no delay: z* is the estimates themselves (A⁰ = I, no "
    "NaN rows). Watch out for slices that count from the end: they are empty when the "
    "count is 0.")


def check_compensation(compensate: Callable[..., np.ndarray]) -> None:
    """Check a student's ``compensate(estimates, A, delay_steps)`` against Tutorial eq. (7).

    Expected: an array of the same shape (n, k) as ``estimates`` with
    ``z*_j = A^δ ẑ_{j−δ}`` for j >= δ and NaN rows for j < δ, equal to the pack's
    :func:`lqe_helpers.prediction.predict_ahead` (computed before the student's function
    runs) within :data:`FUNCTION_RTOL` of the largest entry, on five random cases (1–4
    states, δ = 1–4) and a case with δ = 0 (z* = ẑ); each call given at most
    :data:`lqe_helpers.student_code.TIME_LIMIT` s.

    Parameters
    ----------
    compensate : callable
        The student's function ``compensate(estimates, A, delay_steps)``.

    Raises
    ------
    CheckFailed
        With the mistake named: wrong shape, off-by-one delay or power, A·δ or an
        entry-wise power instead of A^δ, no shift, zeros or estimates instead of NaN
        before δ, A unused, ...; or if it runs the pack's own eq. (7)
        (:func:`lqe_helpers.prediction.predict_ahead`) instead of computing it.
    """
    name = require_callable(compensate, "compensate", "check_compensation")
    cases = compensation_cases.cases()
    correct = {i: predict_ahead(case.estimates, case.A, case.delay)
               for i, case in enumerate(cases)}
    zero = compensation_cases.zero_delay_case()
    answers = {i: _run(compensate, name, case) for i, case in enumerate(cases)}

    def core(index: int) -> slice:
        return slice(cases[index].delay + 1, None)

    wrong_core = [i for i in answers
                  if not close(answers[i][core(i)], correct[i][core(i)], FUNCTION_RTOL)]
    if wrong_core:
        def defined_core_rows(index: int, wrong: np.ndarray) -> np.ndarray:
            """The rows after the first δ + 1 where the mistake gives a value."""
            defined = np.all(np.isfinite(wrong), axis=1)
            defined[: core(index).start] = False
            return defined

        mistake = match_mistake(list(COMPENSATION_MISTAKES),
                                lambda mistake, index: mistaken(mistake, cases[index]),
                                answers, correct, rows=defined_core_rows)
        if mistake is not None:
            raise CheckFailed(
                f"{name} does not follow eq. (7): {COMPENSATION_MISTAKES[mistake]}.")
        raise CheckFailed(
            f"{name} does not give z*_j = A^δ ẑ_(j−δ) for j > δ on "
            f"{cases[wrong_core[0]].describe()}: rows from j = δ + 1 on differ from eq. (7), "
            f"and not by one of the usual mistakes. Check which estimate each row uses and "
            f"which power of A")
    for index, case in enumerate(cases):
        answer, right, delay = answers[index], correct[index], case.delay
        if not close(answer[delay], right[delay], FUNCTION_RTOL):
            if np.all(np.isnan(answer[delay])):
                raise CheckFailed(
                    f"{name}'s row j = δ is NaN (on {case.describe()}). The first "
                    f"prediction already exists at j = δ: z*_δ = A^δ ẑ_0. Only the rows "
                    f"j = 0 … δ − 1 are NaN")
            raise CheckFailed(
                f"{name}'s row j = δ is not A^δ ẑ_0 (on {case.describe()}), although the "
                f"later rows are right")
        _check_head(name, answer, case)
    _check_zero_delay(compensate, name, zero)
    passed(f"{name} matches eq. (7) (z*_j = A^δ ẑ_(j−δ), NaN before δ) on "
           f"{len(cases)} random cases (1–4 states, δ = 1–4) and with δ = 0, to "
           f"{tolerance_text(FUNCTION_RTOL)}, {time_limit_text()}")


def _run(compensate: Callable, name: str, case: Case) -> np.ndarray:
    output = call_student(compensate, case.estimates, case.A, case.delay, name=name,
                          where=case.describe(), arg_names=COMPENSATE_ARGS,
                          shape_hint=_SHAPE_HINT, allow=FUNCTION_TASKS["compensate"])
    n, k = case.estimates.shape
    what = f"z*, the compensated estimates, shape (n, k) = {(n, k)}"
    array = student_result(output, name=name, what=what, allow_nan=True, where=case.describe())
    delay, where = case.delay, f"on {case.describe()}"
    if array.shape == (n - delay, k):
        message = (f"returned {n - delay} rows {where}: only the rows that exist. Keep the "
                   f"shape of the estimates, (n, k) = {(n, k)}, with NaN in the first δ rows "
                   f"so that row j is still time j")
    elif array.shape == (n + delay, k):
        message = (f"returned {n + delay} rows {where}; z* must have the same n = {n} rows "
                   f"as the estimates, row j for time j")
    elif array.shape == (k, n) and k != n:
        message = (f"returned shape {array.shape} {where}: transposed. Rows are time "
                   f"steps, columns are states: shape (n, k) = {(n, k)}")
    elif array.shape != (n, k):
        message = (f"returned an array of shape {array.shape} {where}; expected the shape "
                   f"of the estimates, (n, k) = {(n, k)}")
    else:
        return student_result(array, name=name, what=what, shape=(n, k), allow_nan=True,
                              where=case.describe())
    raise CheckFailed(f"{name} {message}")


def _check_head(name: str, answer: np.ndarray, case: Case) -> None:
    """Rows j < δ must all be NaN."""
    delay = case.delay
    head = answer[:delay]
    if np.all(np.isnan(head)):
        return
    if np.all(head == 0):
        found = "zeros"
    elif np.allclose(head, case.estimates[:delay], equal_nan=False):
        found = "the estimates ẑ_j themselves"
    elif np.allclose(head, case.estimates[:delay] @ np.linalg.matrix_power(case.A, delay).T):
        found = "A^δ ẑ_j, predictions from estimates that the delayed senses cannot have yet"
    else:
        found = "numbers"
    raise CheckFailed(
        f"{name}'s rows before j = δ hold {found} on {case.describe()}. Nothing exists "
        f"before j = δ (the tutorial's hint): those rows must be NaN, so that a plot or an "
        f"MSE cannot mistake them for predictions")


def _check_zero_delay(compensate: Callable, name: str, case: Case) -> None:
    output = call_student(compensate, case.estimates, case.A, 0, name=name,
                          where=case.describe(), arg_names=COMPENSATE_ARGS,
                          allow=FUNCTION_TASKS["compensate"],
                          hint=_ZERO_DELAY_HINT)
    array = student_result(output, name=name, what="z*, the compensated estimates",
                           allow_nan=True, where=case.describe())
    if array.shape == (0, 3):
        raise CheckFailed(f"{name} returns an empty array when delay_steps = 0. "
                          f"{_ZERO_DELAY_HINT}")
    if not close(array, case.estimates, FUNCTION_RTOL):
        raise CheckFailed(
            f"{name} is wrong when delay_steps = 0 (on {case.describe()}): with no delay "
            f"z* must equal the estimates (A⁰ = I, no NaN rows); got shape {array.shape}")


# ------------------------------------------------------------------------------------------
# Task 2: one run, delayed and compensated
# ------------------------------------------------------------------------------------------

_SIGNALS = ("late_readings", "delayed", "compensated")


@remembered
def _trial() -> dict[str, object]:
    """Task 2 recomputed: the three signals (n,) (cm) and each one's likely mistakes."""
    tracking = experiments.track(DEFAULT)
    estimates, readings = tracking.result.estimates, tracking.measurements
    truth = DEFAULT.truth[:, 0]
    steps = DEFAULT.delay_steps(DEFAULT.delay)

    def late(x: np.ndarray, shift: int = steps, column: int = 0) -> np.ndarray:
        return delay_signal(x, shift)[:, column]

    def ahead(x: np.ndarray, shift: int = steps, column: int = 0) -> np.ndarray:
        return predict_ahead(x, DEFAULT.A, shift)[:, column]

    def rolled(x: np.ndarray) -> np.ndarray:
        return np.roll(x, steps, axis=0)[:, 0]

    signals = {"late_readings": late(readings), "delayed": late(estimates),
               "compensated": ahead(estimates)}
    metres = ("the readings are in metres (y divided by 100) while the model and the truth "
              "are in cm: use the readings y as they are, in cm")
    in_metres = experiments.filter_model(DEFAULT).filter(readings / CM_PER_M).estimates
    off_by_one = {"the delay is one sample too long (δ + 1)": steps + 1,
                  "the delay is one sample too short (δ − 1)": steps - 1}
    wrapped = ("it was shifted with np.roll, which wraps the last δ samples round to the "
               "start: nothing has arrived before j = δ, so those samples must be NaN "
               "(simulation.delay_signal does this)")
    velocities = ("it holds velocities (column 1 of the states, cm/s), not positions: the "
                  "position is column 0")
    signal_mistakes = {
        "late_readings": {
            "it is not delayed: these are the readings as they were taken, y_j. At time j "
                "the observer has only y_(j−δ)": readings[:, 0],
            wrapped: rolled(readings),
            "it holds the delayed estimate, not the delayed readings": signals["delayed"],
            "it holds the true position seen late, not the noisy readings y seen late":
                delay_signal(truth, steps, axis=-1),
            **{cause: late(readings, shift) for cause, shift in off_by_one.items()},
            metres: late(readings / CM_PER_M),
        },
        "delayed": {
            "it is not delayed: these are the estimates as the filter made them, ẑ_j. At "
                "time j the newest estimate is ẑ_(j−δ)": estimates[:, 0],
            wrapped: rolled(estimates),
            "it holds the late readings, not the delayed estimate": signals["late_readings"],
            "it holds the compensated estimate, not the delayed one": signals["compensated"],
            velocities: late(estimates, column=1),
            **{cause: late(estimates, shift) for cause, shift in off_by_one.items()},
            metres: late(in_metres),
        },
        "compensated": {
            "compensate was given the delayed estimates, so it predicts from 2δ samples "
                "back: give it the estimates as the filter made them (row i is ẑ_i)":
                (delay_signal(estimates, 2 * steps) @ np.linalg.matrix_power(
                    DEFAULT.A, steps).T)[:, 0],
            "it holds the delayed estimate, not the compensated one": signals["delayed"],
            "A is applied once, not δ times: it is A ẑ_(j−δ), one step ahead. The estimate is "
                "δ samples old, so eq. (7) moves it δ steps ahead with the matrix power A^δ":
                (delay_signal(estimates, steps) @ DEFAULT.A.T)[:, 0],
            velocities: ahead(estimates, column=1),
            **{cause: ahead(estimates, shift) for cause, shift in off_by_one.items()},
            metres: ahead(in_metres),
        },
    }
    return {"signals": signals, "signal_mistakes": signal_mistakes, "steps": steps}


def _judge_signal(name: str, value: object, right: np.ndarray, steps: int,
                  mistakes: dict[str, np.ndarray]) -> None:
    """A position signal (n,) (cm) with NaN before δ, against ``right``; CheckFailed if wrong."""
    n = right.shape[0]
    got = argument_array(value, name, f"positions (cm), an array of shape ({n},)",
                         allow_nan=True)
    if got.shape in ((n, 1), (n, 3)):
        what = "one column" if got.shape[1] == 1 else "whole states (p, v, a)"
        raise CheckFailed(f"{name} has shape {got.shape}, {what} per row: keep only the "
                          f"positions, column 0, as an array of shape ({n},)")
    if got.shape != right.shape:
        raise CheckFailed(f"{name} must be positions (cm) of shape ({n},), one per sample, "
                          f"got shape {got.shape}")
    if close(got, right, FUNCTION_RTOL):
        return
    for cause, wrong in mistakes.items():
        if close(got, wrong, MISTAKE_RTOL) and not close(right, wrong, MISTAKE_RTOL):
            raise CheckFailed(f"{name} is not right: {cause}")
    nan = np.isnan(got)
    if name != "late_readings" and nan[steps:].all():
        raise CheckFailed(
            f"{name} is NaN at every sample, also after j = δ = {steps}: was your my_filter "
            f"run on the late readings? Their first δ samples are NaN, and a filter fed one "
            f"NaN gives NaN from then on. Run it on the readings y as they were taken, then "
            f"shift its estimates δ samples later")
    if not np.array_equal(nan, np.isnan(right)):
        raise CheckFailed(
            f"{name} must be NaN in exactly its first δ = {steps} samples (nothing has "
            f"arrived before j = δ) and a number after; yours has NaN in {int(nan.sum())} "
            f"samples{f', the first at j = {int(np.argmax(nan))}' if nan.any() else ''}")
    raise CheckFailed(
        f"{name} does not match the signal recomputed from the task's inputs (to "
        f"{tolerance_text(FUNCTION_RTOL)} of its largest value), and not by one of the usual "
        f"mistakes: {_SIGNAL_HINTS[name]}")


#: What :func:`_judge_signal` asks when no usual mistake explains a signal.
_SIGNAL_HINTS = {
    "late_readings": "is it the trial's readings y, shifted δ samples later (row j = "
                     "y_(j−δ))?",
    "delayed": "is it your my_filter's estimates of the trial's readings y, shifted δ "
               "samples later (row j = ẑ_(j−δ))?",
    "compensated": "check which estimate row j starts from (ẑ_(j−δ), from your my_filter's "
                   "estimates of the trial's readings y) and which power of A moves it (A^δ, "
                   "with δ = steps)",
}


def check_delay_signals(late_readings: np.ndarray, delayed: np.ndarray,
                        compensated: np.ndarray) -> None:
    """Check Task 2: the late readings and the delayed and compensated positions of one run.

    Recomputed from the task's own inputs before looking at the student's: the
    vision-only filter of eq. (5) on the scenario's draw (the pack's engine, which the
    student's ``my_filter`` equals), its readings and estimates delayed by
    δ = ``DEFAULT.delay`` / Δt samples (:func:`lqe_helpers.simulation.delay_signal`) and
    compensated (:func:`lqe_helpers.prediction.predict_ahead`). Each signal's positions
    (n,) must agree within :data:`FUNCTION_RTOL` of its largest value, NaN exactly in the
    first δ samples.

    Parameters
    ----------
    late_readings, delayed, compensated : array_like, shape (n,)
        The student's y_(j−δ), ẑ_(j−δ) and z*_j positions (cm) on the wall-clock axis.

    Raises
    ------
    CheckFailed
        Naming the signal and the likely cause: not delayed, wrapped round by np.roll or
        a sample off, the delayed estimates compensated, two swapped, the true position
        for the readings, velocities or whole states for positions, the filter run on
        the late readings (NaN throughout), ...
    """
    right = _trial()
    for name, value in zip(_SIGNALS, (late_readings, delayed, compensated), strict=True):
        _judge_signal(name, value, right["signals"][name], right["steps"],
                      right["signal_mistakes"][name])
    passed(f"the late readings, the delayed and the compensated position (δ = "
           f"{right['steps']} samples) match the pack's engine on the scenario's draw to "
           f"{tolerance_text(FUNCTION_RTOL)} of each signal's largest value")


# ------------------------------------------------------------------------------------------
# Task 3: many runs, paired
# ------------------------------------------------------------------------------------------

@remembered
def monte_carlo_mses() -> dict[str, np.ndarray]:
    """Per-run MSEs (runs,) (cm²) at the question's delay: delayed, compensated, undelayed."""
    tracking = vision_runs()
    batch = experiments.delay_and_compensate(tracking, DEFAULT.delay)
    values = {"delayed": batch.mse("delayed"), "predicted": batch.mse("predicted"),
              "now": tracking.mse()}
    for array in values.values():
        array.setflags(write=False)
    return values


def check_delay_difference(gain: metrics.Interval, won_back: metrics.Interval) -> None:
    """Check Task 3: delayed − compensated MSE, paired, and the share of the delay's cost won back.

    Recomputed from the task's inputs before looking at the student's: ``DEFAULT.mc_runs``
    vision-only runs (:func:`lqe_helpers.experiments.track`), delayed by ``DEFAULT.delay``
    and compensated (:func:`lqe_helpers.experiments.delay_and_compensate`), and
    ``metrics.mean_ci95`` of the per-run differences delayed − compensated and of the
    per-run shares (delayed − compensated) / (delayed − undelayed); mean and ends must
    agree within :data:`INTERVAL_RTOL` of the interval's scale.

    Parameters
    ----------
    gain : metrics.Interval
        The student's paired difference with its 95 % interval (cm²).
    won_back : metrics.Interval
        The student's share of the delay's cost that compensation wins back, a fraction.

    Raises
    ------
    CheckFailed
        With the likely cause: the sign reversed, an unpaired interval, the filter
        without delay in place of one of the two, a ratio, one MSE alone, the share for
        the difference; for the share, the share of the delayed MSE, the share left, a
        ratio upside down, per cent, the undelayed MSE as the cost, parentheses missing,
        the difference for the share, ...
    """
    runs = monte_carlo_mses()
    delayed, predicted, now = runs["delayed"], runs["predicted"], runs["now"]
    mistakes = {
        **interval_mistakes(delayed, predicted, "the delayed MSE", "the compensated MSE"),
        "it compares the delayed estimate with the filter without delay; the task compares "
        "it with the compensated estimate": metrics.mean_ci95(delayed - now),
        "it compares the compensated estimate with the filter without delay; the task "
        "compares the delayed estimate with the compensated one":
            metrics.mean_ci95(predicted - now),
        "it is the interval of the ratio delayed / compensated; the task asks for the paired "
        "difference delayed − compensated": metrics.mean_ci95(delayed / predicted),
        "it is the share of the delay's cost won back (a fraction), which is won_back; gain "
        "is the paired difference delayed − compensated in cm²":
            metrics.mean_ci95((delayed - predicted) / (delayed - now)),
    }
    mistakes.update(unit_mistakes(delayed, predicted, "the delayed MSE", "the compensated MSE"))
    judge_interval("gain", gain, metrics.mean_ci95(delayed - predicted), INTERVAL_RTOL,
                   unit="cm²", what="the paired difference delayed − compensated MSE "
                   "recomputed from the task's inputs",
                   mistakes=mistakes, nan_hint="is the delay given in seconds (d = "
                   f"{DEFAULT.delay:g} s), not in samples?")
    cost, won = delayed - now, delayed - predicted
    right = metrics.mean_ci95(won / cost)
    share_mistakes = {
        "it is the share of the delayed MSE that compensation removes, (delayed − "
        "compensated) / delayed; the delay's cost is what it adds to the filter without "
        "delay, so divide by delayed − undelayed": metrics.mean_ci95(won / delayed),
        "it is the share of the delay's cost that is left, (compensated − undelayed) / "
        "(delayed − undelayed); the task asks for the share won back":
            metrics.mean_ci95((predicted - now) / cost),
        "the ratio is upside down: divide what compensation wins (delayed − compensated) by "
        "what the delay costs (delayed − undelayed)": metrics.mean_ci95(cost / won),
        "it is in per cent; give the share as a fraction (0.5 for half)":
            metrics.Interval(100 * right.mean, 100 * right.low, 100 * right.high, right.runs),
        "one of its two differences is reversed (the share is negative): it is (delayed − "
        "compensated) / (undelayed − delayed) or (compensated − delayed) / (delayed − "
        "undelayed). Both differences are delayed minus the other, and both are positive: "
        "(delayed − compensated) / (delayed − undelayed)": metrics.mean_ci95(won / (now - delayed)),
        "it divides by compensated − undelayed; the delay's cost is delayed − undelayed":
            metrics.mean_ci95(won / (predicted - now)),
        "it divides by the undelayed MSE; the delay's cost is what the delay adds to it, "
        "delayed − undelayed": metrics.mean_ci95(won / now),
        "it is compensated / delayed, the share of the delayed MSE that is left; the task "
        "asks for (delayed − compensated) / (delayed − undelayed)":
            metrics.mean_ci95(predicted / delayed),
        "the numerator's parentheses are missing: only the compensated MSE is divided. "
        "Write (delayed − compensated) / (delayed − undelayed)":
            metrics.mean_ci95(delayed - predicted / cost),
        "the denominator's parentheses are missing: it divides by the delayed MSE, then "
        "subtracts the undelayed one. Write (delayed − compensated) / (delayed − undelayed)":
            metrics.mean_ci95(won / delayed - now),
        "it is the paired difference delayed − compensated in cm², which is gain; won_back "
        "is the share of the delay's cost, (delayed − compensated) / (delayed − undelayed)":
            metrics.mean_ci95(won),
    }
    judge_interval("won_back", won_back, right, INTERVAL_RTOL,
                   what="the share (delayed − compensated) / (delayed − undelayed) per run, "
                   "recomputed from the task's inputs", mistakes=share_mistakes)
    passed(f"delayed − compensated MSE, paired over {DEFAULT.mc_runs} runs, and the share "
           f"of the delay's cost won back: means and 95 % intervals match the pack's engine "
           f"on the scenario's draws to {tolerance_text(INTERVAL_RTOL)} relative")
