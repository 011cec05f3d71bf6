"""The random cases of :func:`check_compensation` and its typical mistakes.

The right answers come from the pack's engine
(:func:`lqe_helpers.prediction.predict_ahead`); each typical mistake is eq. (7) with one
slip (a power or a shift off by one, A·δ, an entry-wise power, no shift, ...), computed
from the engine's delay, so no readable worked ``compensate`` lives here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..simulation import delay_signal
from .machinery import SEED
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: (states k, samples n, delay δ) of the compensation check; n >= 2δ + 3 so that every
#: shifted mistake has rows to compare.
CASE_SIZES = ((3, 12, 3), (2, 10, 1), (1, 8, 2), (4, 12, 4), (3, 11, 2))
COMPENSATE_ARGS = ("estimates", "A", "delay_steps")


@dataclass(frozen=True)
class Case:
    """Inputs of one call of the student's ``compensate`` (arrays read-only)."""

    estimates: np.ndarray
    A: np.ndarray
    delay: int

    def describe(self) -> str:
        n, k = self.estimates.shape
        return (f"estimates of shape {(n, k)} (k = {k} state{'s' * (k != 1)}), A of shape "
                f"{self.A.shape} and delay_steps = {self.delay}")


@remembered
def cases() -> tuple[Case, ...]:
    """The random cases of :func:`check_compensation`, from the fixed seed."""
    rng = np.random.default_rng(SEED + 1)
    cases = []
    for k, n, delay in CASE_SIZES:
        A = np.eye(k) + 0.4 * rng.normal(size=(k, k))
        estimates = 3.0 * rng.normal(size=(n, k))
        for array in (A, estimates):
            array.setflags(write=False)
        cases.append(Case(estimates, A, delay))
    return tuple(cases)


def mistaken(mistake: str, case: Case) -> np.ndarray | None:
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
        "single_A": lambda: moved(d, A),
        "times_delta": lambda: moved(d, d * A),
        "elementwise": lambda: moved(d, A**d),
        "no_shift": lambda: estimates @ power(d).T,
        "no_A": lambda: delay_signal(estimates, d),
        "wrong_side": lambda: moved(d, power(d).T),
    }[mistake]()


COMPENSATION_MISTAKES = {
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
    "single_A": (
        "A is applied once, not δ times: your z*_j is A ẑ_(j−δ), one step ahead. The "
        "estimate is δ samples old, so eq. (7) moves it δ steps ahead with the matrix "
        "power A^δ"),
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


def zero_delay_case() -> Case:
    """A case with δ = 0, where z* must be the estimates themselves."""
    rng = np.random.default_rng(SEED + 2)
    return Case(rng.normal(size=(6, 3)), np.eye(3) + 0.4 * rng.normal(size=(3, 3)), 0)
