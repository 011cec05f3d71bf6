"""The check of task (e): the delay compensation z*_j = A^δ ẑ_(j−δ)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import reference
from ._common import (
    FUNCTION_RTOL,
    SEED,
    CheckFailed,
    as_result_array,
    call_student,
    close,
    match_mistake,
    passed,
    require_callable,
    tolerance_text,
)

#: (states k, samples n, delay δ) of the compensation check; n >= 2δ + 3 so that every
#: shifted mistake has rows to compare.
_COMPENSATION_CASES = ((3, 12, 3), (2, 10, 1), (1, 8, 2), (4, 12, 4), (3, 11, 2))


@dataclass(frozen=True)
class _CompensationCase:
    estimates: np.ndarray
    A: np.ndarray
    delay: int

    def describe(self) -> str:
        n, k = self.estimates.shape
        return (f"estimates of shape {(n, k)} (k = {k} state{'s' * (k != 1)}), A of shape "
                f"{self.A.shape} and delay_steps = {self.delay}")


def _compensation_cases() -> list[_CompensationCase]:
    rng = np.random.default_rng(SEED + 1)
    cases = []
    for k, n, delay in _COMPENSATION_CASES:
        A = np.eye(k) + 0.4 * rng.normal(size=(k, k))
        cases.append(_CompensationCase(3.0 * rng.normal(size=(n, k)), A, delay))
    return cases


def _compensation_mistake(mistake: str, estimates: np.ndarray, A: np.ndarray,
                          delay: int) -> np.ndarray | None:
    n, k = estimates.shape
    power, shift = delay, delay
    if mistake == "power_minus_one":
        power = delay - 1
    elif mistake == "power_plus_one":
        power = delay + 1
    elif mistake == "shift_minus_one":
        shift = delay - 1
    elif mistake == "shift_plus_one":
        shift = delay + 1
    elif mistake in ("no_shift", "backwards"):
        shift = 0
    if power < 0 or shift < 0:
        return None
    matrix = np.linalg.matrix_power(A, power)
    if mistake == "times_delta":
        matrix = delay * A
    elif mistake == "elementwise":
        matrix = A ** delay
    elif mistake == "no_A":
        matrix = np.eye(k)
    elif mistake == "wrong_side":
        matrix = matrix.T
    out = np.full((n, k), np.nan)
    if mistake == "backwards":
        out[: n - delay] = estimates[delay:] @ matrix.T
    else:
        out[shift:] = estimates[: n - shift] @ matrix.T
    return out


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


def check_compensation(compensate: Callable[..., np.ndarray]) -> None:
    """Check a student's ``compensate(estimates, A, delay_steps)`` against Tutorial eq. (7).

    Expected: an array of the same shape (n, k) as ``estimates`` with
    ``z*_j = A^δ ẑ_{j−δ}`` for j >= δ and NaN rows for j < δ, within
    :data:`FUNCTION_RTOL` of the largest entry, on five random cases (1–4 states,
    δ = 1–4) and a case with δ = 0 (z* = ẑ).

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
    cases = _compensation_cases()
    answers: dict[int, np.ndarray] = {}
    correct: dict[int, np.ndarray] = {}
    for index, case in enumerate(cases):
        answers[index] = _run_compensation(compensate, name, case)
        correct[index] = reference.compensate(case.estimates, case.A, case.delay)

    def core(index: int) -> slice:
        return slice(cases[index].delay + 1, None)

    wrong_core = [i for i in answers
                  if not close(answers[i][core(i)], correct[i][core(i)], FUNCTION_RTOL)]
    if wrong_core:
        def compute(mistake: str, index: int) -> np.ndarray | None:
            case = cases[index]
            return _compensation_mistake(mistake, case.estimates, case.A, case.delay)

        def defined_core_rows(index: int, wrong: np.ndarray) -> np.ndarray:
            """The rows after the first δ + 1 where the mistake gives a value."""
            defined = np.all(np.isfinite(wrong), axis=1)
            defined[: core(index).start] = False
            return defined

        mistake = match_mistake(_COMPENSATION_MISTAKES, compute, answers, correct,
                                rows=defined_core_rows)
        if mistake is not None:
            raise CheckFailed(
                f"{name} does not follow eq. (7): {_COMPENSATION_MISTAKES[mistake]}.")
        index = wrong_core[0]
        raise CheckFailed(
            f"{name} does not give z*_j = A^δ ẑ_(j−δ) for j > δ on {cases[index].describe()}"
            f": rows from j = δ + 1 on differ from eq. (7), and not by one of the usual "
            f"mistakes. Check which estimate each row uses and which power of A")
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
        _check_compensation_head(name, answer, case)
    _check_zero_delay(compensate, name)
    passed(f"{name} matches eq. (7) (z*_j = A^δ ẑ_(j−δ), NaN before δ) on "
           f"{len(cases)} random cases (1–4 states, δ = 1–4) and with δ = 0, to "
           f"{tolerance_text(FUNCTION_RTOL)}")


def _run_compensation(compensate: Callable, name: str, case: _CompensationCase) -> np.ndarray:
    estimates, A = case.estimates.copy(), case.A.copy()
    output = call_student(compensate, name, (estimates, A, case.delay), case.describe(),
                          shape_hint=_COMPENSATION_SHAPE_HINT)
    if not np.array_equal(estimates, case.estimates) or not np.array_equal(A, case.A):
        raise CheckFailed(
            f"{name} changed its input estimates or A in place (on {case.describe()}). "
            f"Leave the inputs unchanged and return a new array")
    n, k = case.estimates.shape
    array = as_result_array(output, name, (n, k), "z*, the compensated estimates")
    delay = case.delay
    where = f"on {case.describe()}"
    if array.shape == (n, k):
        return array
    if array.shape == (n - delay, k):
        raise CheckFailed(
            f"{name} returned {n - delay} rows {where}: only the rows that exist. Keep "
            f"the shape of the estimates, (n, k) = {(n, k)}, with NaN in the first δ rows "
            f"so that row j is still time j")
    if array.shape == (n + delay, k):
        raise CheckFailed(
            f"{name} returned {n + delay} rows {where}; z* must have the same n = {n} rows "
            f"as the estimates, row j for time j")
    if array.shape == (k, n):
        raise CheckFailed(
            f"{name} returned shape {array.shape} {where}: transposed. Rows are time "
            f"steps, columns are states: shape (n, k) = {(n, k)}")
    raise CheckFailed(
        f"{name} returned an array of shape {array.shape} {where}; expected the shape "
        f"of the estimates, (n, k) = {(n, k)}")


def _check_compensation_head(name: str, answer: np.ndarray, case: _CompensationCase) -> None:
    """Rows j < δ must all be NaN."""
    delay = case.delay
    head = answer[:delay]
    if np.all(np.isnan(head)):
        return
    where = f"on {case.describe()}"
    if np.all(head == 0):
        found = "zeros"
    elif np.allclose(head, case.estimates[:delay], equal_nan=False):
        found = "the estimates ẑ_j themselves"
    elif np.allclose(head, case.estimates[:delay] @ np.linalg.matrix_power(case.A, delay).T):
        found = "A^δ ẑ_j, predictions from estimates that the delayed senses cannot have yet"
    else:
        found = "numbers"
    raise CheckFailed(
        f"{name}'s rows before j = δ hold {found} {where}. Nothing exists before j = δ "
        f"(the tutorial's hint): those rows must be NaN, so that a plot or an MSE cannot "
        f"mistake them for predictions")


_COMPENSATION_SHAPE_HINT = (
    "The shapes in one product or assignment do not fit: write the shape beside each "
    "term (the estimates are (n, k), one estimate ẑ_j is (k,), A^δ is (k, k)).")

_ZERO_DELAY_HINT = (
    "With delay_steps = 0 there is no delay: z* is the estimates themselves (A⁰ = I, no "
    "NaN rows). Watch out for slices that count from the end: they are empty when the "
    "count is 0.")


def _check_zero_delay(compensate: Callable, name: str) -> None:
    rng = np.random.default_rng(SEED + 2)
    estimates = rng.normal(size=(6, 3))
    A = np.eye(3) + 0.4 * rng.normal(size=(3, 3))
    case = _CompensationCase(estimates, A, 0)
    output = call_student(compensate, name, (estimates.copy(), A.copy(), 0), case.describe(),
                          hint=_ZERO_DELAY_HINT)
    array = as_result_array(output, name, (6, 3), "z*, the compensated estimates")
    if array.shape == (0, 3):
        raise CheckFailed(f"{name} returns an empty array when delay_steps = 0. "
                          f"{_ZERO_DELAY_HINT}")
    if not close(array, estimates, FUNCTION_RTOL):
        raise CheckFailed(
            f"{name} is wrong when delay_steps = 0 (on {case.describe()}): with no delay "
            f"z* must equal the estimates (A⁰ = I, no NaN rows); got shape {array.shape}")
