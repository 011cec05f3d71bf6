"""Checks of notebook 05, question (e): the delay compensation z*_j = A^δ ẑ_(j−δ) and its worth.

- :func:`check_compensation` (Task 1): the student's ``compensate`` on random cases,
  against the pack's :func:`lqe_helpers.prediction.predict_ahead`;
- :func:`check_delay_mse` (Task 2): the delayed and compensated MSEs of one run,
  recomputed from the scenario's draw with the engine;
- :func:`check_delay_difference` (Task 3): the paired delayed − compensated difference
  over the Monte Carlo runs, recomputed with :mod:`lqe_helpers.experiments`.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import experiments, metrics
from ..prediction import predict_ahead
from ..scenario import DEFAULT
from ..simulation import delay_signal
from .judging import interval_mistakes, judge, judge_interval, mse_mistakes
from .machinery import (
    FUNCTION_RTOL,
    INTERVAL_RTOL,
    MSE_RTOL,
    SEED,
    CheckFailed,
    call_student,
    close,
    match_mistake,
    passed,
    require_callable,
    student_result,
    time_limit_text,
    tolerance_text,
)

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: (states k, samples n, delay δ) of the compensation check; n >= 2δ + 3 so that every
#: shifted mistake has rows to compare.
_COMPENSATION_CASES = ((3, 12, 3), (2, 10, 1), (1, 8, 2), (4, 12, 4), (3, 11, 2))
_COMPENSATE_ARGS = ("estimates", "A", "delay_steps")


@dataclass(frozen=True)
class _Case:
    estimates: np.ndarray
    A: np.ndarray
    delay: int

    def describe(self) -> str:
        n, k = self.estimates.shape
        return (f"estimates of shape {(n, k)} (k = {k} state{'s' * (k != 1)}), A of shape "
                f"{self.A.shape} and delay_steps = {self.delay}")


@functools.cache
def _cases() -> tuple[_Case, ...]:
    rng = np.random.default_rng(SEED + 1)
    cases = []
    for k, n, delay in _COMPENSATION_CASES:
        A = np.eye(k) + 0.4 * rng.normal(size=(k, k))
        estimates = 3.0 * rng.normal(size=(n, k))
        for array in (A, estimates):
            array.setflags(write=False)
        cases.append(_Case(estimates, A, delay))
    return tuple(cases)


def _mistaken(mistake: str, case: _Case) -> np.ndarray | None:
    """Eq. (7) with one typical mistake; None if it cannot run on this case."""
    estimates, A, d = case.estimates, case.A, case.delay
    n = estimates.shape[0]

    def moved(shift: int, matrix: np.ndarray | None) -> np.ndarray | None:
        if matrix is None or not 0 <= shift < n:
            return None
        return delay_signal(estimates, shift) @ matrix.T

    def power(p: int) -> np.ndarray | None:
        return np.linalg.matrix_power(A, p) if p >= 0 else None

    if mistake == "backwards":
        out = np.full(estimates.shape, np.nan)
        out[: n - d] = estimates[d:] @ power(d).T
        return out
    return {
        "power_minus_one": lambda: moved(d, power(d - 1)),
        "power_plus_one": lambda: moved(d, power(d + 1)),
        "shift_minus_one": lambda: moved(d - 1, power(d)),
        "shift_plus_one": lambda: moved(d + 1, power(d)),
        "times_delta": lambda: moved(d, d * A),
        "elementwise": lambda: moved(d, A**d),
        "no_shift": lambda: estimates @ power(d).T,
        "no_A": lambda: delay_signal(estimates, d),
        "wrong_side": lambda: moved(d, power(d).T),
    }[mistake]()


_COMPENSATION_MISTAKES = {
    "power_minus_one": (
        "one power of A too few: your z*_j is A applied δ − 1 times to ẑ_(j−δ). Eq. (7) "
        "applies A δ times, once per sample of delay"),
    "power_plus_one": (
        "one power of A too many: your z*_j is A applied δ + 1 times to ẑ_(j−δ). Eq. (7) "
        "applies A δ times, once per sample of delay"),
    "shift_minus_one": (
        "off by one in the delay: your row j uses the estimate ẑ_(j−δ+1). Eq. (7) "
        "predicts from the estimate δ samples back, ẑ_(j−δ)"),
    "shift_plus_one": (
        "off by one in the delay: your row j uses the estimate ẑ_(j−δ−1). Eq. (7) "
        "predicts from the estimate δ samples back, ẑ_(j−δ)"),
    "times_delta": (
        "A is multiplied by the number δ (A·δ). Eq. (7) needs the matrix power A^δ: A "
        "applied δ times in a row, one matrix product per sample"),
    "elementwise": (
        "A^δ is computed entry by entry (each entry of A raised to the power δ). The "
        "matrix power is A multiplied by itself δ times with matrix products"),
    "no_shift": (
        "there is no shift: your row j is A^δ ẑ_j. Eq. (7) predicts from the estimate of "
        "δ samples earlier, ẑ_(j−δ), the newest one the delayed senses allow"),
    "backwards": (
        "the shift goes the wrong way: your row j uses ẑ_(j+δ), an estimate from the "
        "future. Eq. (7) uses ẑ_(j−δ), from δ samples earlier"),
    "no_A": (
        "A is not used: your row j is the delayed estimate ẑ_(j−δ) itself. Eq. (7) moves "
        "it δ steps ahead with A^δ"),
    "wrong_side": (
        "A^δ is applied from the wrong side: your rows are (A^δ)ᵀ ẑ_(j−δ), i.e. each "
        "estimate as a row times A^δ. Eq. (7) multiplies the column ẑ_(j−δ) by A^δ "
        "from the left"),
}

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
        before δ, A unused, ...
    """
    name = require_callable(compensate, "compensate", "check_compensation")
    cases = _cases()
    correct = {i: predict_ahead(case.estimates, case.A, case.delay)
               for i, case in enumerate(cases)}
    zero = _zero_delay_case()
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

        mistake = match_mistake(list(_COMPENSATION_MISTAKES),
                                lambda mistake, index: _mistaken(mistake, cases[index]),
                                answers, correct, rows=defined_core_rows)
        if mistake is not None:
            raise CheckFailed(
                f"{name} does not follow eq. (7): {_COMPENSATION_MISTAKES[mistake]}.")
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


def _run(compensate: Callable, name: str, case: _Case) -> np.ndarray:
    output = call_student(compensate, case.estimates, case.A, case.delay, name=name,
                          where=case.describe(), arg_names=_COMPENSATE_ARGS,
                          shape_hint=_SHAPE_HINT)
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


def _check_head(name: str, answer: np.ndarray, case: _Case) -> None:
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


def _zero_delay_case() -> _Case:
    rng = np.random.default_rng(SEED + 2)
    return _Case(rng.normal(size=(6, 3)), np.eye(3) + 0.4 * rng.normal(size=(3, 3)), 0)


def _check_zero_delay(compensate: Callable, name: str, case: _Case) -> None:
    output = call_student(compensate, case.estimates, case.A, 0, name=name,
                          where=case.describe(), arg_names=_COMPENSATE_ARGS,
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

_NAN_HINT = ("the first δ samples of a delayed or compensated estimate are NaN (nothing has "
             "arrived yet): leave out the first max(burn, δ) samples")


@functools.cache
def _trial() -> dict[str, object]:
    """The right MSEs (cm²) of Task 2 and the likely mistakes of each."""
    tracking = experiments.track(DEFAULT)
    estimates = tracking.result.estimates
    truth, burn, dt = DEFAULT.truth[:, 0], DEFAULT.burn_in_steps, DEFAULT.dt
    steps = DEFAULT.delay_steps(DEFAULT.delay)
    skip = max(burn, steps)
    delayed = delay_signal(estimates, steps)[:, 0]
    compensated = predict_ahead(estimates, DEFAULT.A, steps)[:, 0]

    def mse(x: np.ndarray, start: int = skip) -> float | None:
        with np.errstate(invalid="ignore"):
            value = float(np.mean((x[start:] - truth[start:]) ** 2))
        return value if np.isfinite(value) else None

    ahead = np.linalg.matrix_power(DEFAULT.A, steps)
    common = {
        "it is the MSE of the filter's estimate without any delay: shift the estimates δ "
        "samples later first": mse(estimates[:, 0]),
        "it is the MSE of the late readings, not of an estimate":
            mse(delay_signal(tracking.measurements, steps)[:, 0]),
    }
    compensated_mistakes = {
        "the compensation was applied to the delayed estimates, so it predicts from 2δ "
        "samples back: compensate the estimates as the filter gives them (row i is ẑ_i)":
            mse((delay_signal(estimates, 2 * steps) @ ahead.T)[:, 0]),
        "it is the MSE of the delayed estimate, not of the compensated one": mse(delayed),
        "there is no shift: A^δ ẑ_j predicts the present estimate δ samples into the future":
            mse((estimates @ ahead.T)[:, 0]),
        "the delayed estimate was moved one step (A), not δ steps (A^δ)":
            mse((delay_signal(estimates, steps) @ DEFAULT.A.T)[:, 0]),
        "the delay is one sample too long (δ + 1)":
            mse(predict_ahead(estimates, DEFAULT.A, steps + 1)[:, 0]),
        "the delay is one sample too short (δ − 1)":
            mse(predict_ahead(estimates, DEFAULT.A, steps - 1)[:, 0]),
        **common, **mse_mistakes(compensated, truth, skip, dt),
    }
    delayed_mistakes = {
        "it is the MSE of the compensated estimate, not of the delayed one": mse(compensated),
        "the delay is one sample too long (δ + 1)":
            mse(delay_signal(estimates, steps + 1)[:, 0]),
        "the delay is one sample too short (δ − 1)":
            mse(delay_signal(estimates, steps - 1)[:, 0]),
        **common, **mse_mistakes(delayed, truth, skip, dt),
    }
    for mistakes, signal in ((compensated_mistakes, compensated), (delayed_mistakes, delayed)):
        mistakes[f"it leaves out only the first δ = {steps} samples; leave out the burn-in "
                 f"too, max(burn, δ) = {skip}"] = mse(signal, steps) if steps < skip else None
    return {"delayed": mse(delayed), "compensated": mse(compensated),
            "delayed_mistakes": delayed_mistakes, "compensated_mistakes": compensated_mistakes}


def check_delay_mse(mse_delayed_run: float, mse_compensated_run: float) -> None:
    """Check Task 2's MSEs of the delayed and of the compensated position (one run).

    Recomputed from the task's own inputs before looking at the student's: the
    vision-only run of the scenario's draw (:func:`lqe_helpers.experiments.track`), its
    estimates delayed by δ = ``DEFAULT.delay`` / Δt samples
    (:func:`lqe_helpers.simulation.delay_signal`) and compensated
    (:func:`lqe_helpers.prediction.predict_ahead`); each MSE (cm²) after the first
    max(burn-in, δ) samples must agree within :data:`MSE_RTOL` relative.

    Parameters
    ----------
    mse_delayed_run, mse_compensated_run : float
        The student's MSEs (cm²).

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: the delayed estimates compensated, the two
        swapped, no shift, a delay a sample off, the undelayed estimate, the late
        readings, NaN from the first δ samples, the RMSE, ...
    """
    right = _trial()
    for name, value, kind in (("mse_delayed_run", mse_delayed_run, "delayed"),
                              ("mse_compensated_run", mse_compensated_run, "compensated")):
        judge(name, value, right[kind], MSE_RTOL, unit="cm²", nan_hint=_NAN_HINT,
              what=f"the {kind} position's MSE recomputed from the task's inputs",
              mistakes=right[f"{kind}_mistakes"])
    steps = DEFAULT.delay_steps(DEFAULT.delay)
    passed(f"the MSEs of the delayed and of the compensated position (δ = {steps} samples, "
           f"after the first {max(DEFAULT.burn_in_steps, steps)}) match the pack's engine on "
           f"the scenario's draw to {tolerance_text(MSE_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Task 3: many runs, paired
# ------------------------------------------------------------------------------------------

@functools.cache
def _monte_carlo() -> dict[str, np.ndarray]:
    """Per-run MSEs (runs,) (cm²): delayed, compensated and without delay (read-only)."""
    tracking = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    batch = experiments.delay_and_compensate(tracking, DEFAULT.delay)
    values = {"delayed": batch.mse("delayed"), "predicted": batch.mse("predicted"),
              "now": tracking.mse()}
    for array in values.values():
        array.setflags(write=False)
    return values


def check_delay_difference(gain: metrics.Interval) -> None:
    """Check Task 3's paired difference delayed − compensated MSE over the Monte Carlo runs.

    Recomputed from the task's inputs before looking at the student's: ``DEFAULT.mc_runs``
    vision-only runs (:func:`lqe_helpers.experiments.track`), delayed by ``DEFAULT.delay``
    and compensated (:func:`lqe_helpers.experiments.delay_and_compensate`), and
    ``metrics.mean_ci95`` of the per-run differences; mean and ends must agree within
    :data:`INTERVAL_RTOL` of the interval's scale.

    Parameters
    ----------
    gain : metrics.Interval
        The student's paired difference with its 95 % interval (cm²).

    Raises
    ------
    CheckFailed
        With the likely cause: the sign reversed, an unpaired interval, the filter
        without delay in place of one of the two, a ratio, one MSE alone, ...
    """
    runs = _monte_carlo()
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
    }
    judge_interval("gain", gain, metrics.mean_ci95(delayed - predicted), INTERVAL_RTOL,
                   unit="cm²", what="the paired difference delayed − compensated MSE "
                   "recomputed from the task's inputs",
                   mistakes=mistakes, nan_hint="is the delay given in seconds (d = "
                   f"{DEFAULT.delay:g} s), not in samples?")
    passed(f"delayed − compensated MSE, paired over {DEFAULT.mc_runs} runs: mean and 95 % "
           f"interval match the pack's engine on the scenario's draws to "
           f"{tolerance_text(INTERVAL_RTOL)} relative")
