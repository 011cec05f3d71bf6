"""What every check shares: tolerances, calling the student's code, arguments.

Every check runs a student's function through :func:`call_student` (the time limit and the
one-line reports of :mod:`lqe_helpers.student_code`), reads what it returned with
:func:`student_result`, and validates each value a student passes with
:func:`argument_array`, :func:`positive_number`, :func:`shaped_argument` or
:func:`keyed_entries` (a dict keyed as the task asks), so that a wrong type or shape is one
:class:`CheckFailed` naming the argument. ``__tracebackhide__`` keeps these frames out of
pytest's report; :class:`CheckFailed` keeps them out of Jupyter's. :class:`CheckFailed`,
:class:`NotWrittenYet` and :class:`TimedOut` are :mod:`lqe_helpers.student_code`'s (one
hierarchy of errors for students, re-exported here).
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Mapping, Sequence

import numpy as np

from .. import student_code
from ..student_code import CheckFailed, NotWrittenYet, TimedOut, calling

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: Seed of the random models the function checks use (fixed: a check gives the same
#: verdict and message every time it runs).
SEED = 2026

#: Relative tolerance of what a student's function or filter run returns (the estimates of
#: ``check_filter``, ``check_compensation``, ``check_smoother``, a trial's positions),
#: scaled by the largest entry of the correct result.
FUNCTION_RTOL = 1e-9

#: Relative tolerance of a mean squared error, of the expected value's size.
MSE_RTOL = 1e-6

#: Relative tolerance of a matrix or array the student computes as the check does (C, R,
#: P0, A, a steady-state variance, an RMS curve): it agrees to rounding.
MATRIX_RTOL = 1e-9

#: Tolerance (s) of a time read off a curve (a convergence or crossing time): a whole
#: number of samples, so exact to rounding.
TIME_ATOL = 1e-9

#: Relative tolerance (of the interval's scale: its mean or half-width, whichever is
#: larger) of a paired difference with its 95 % interval.
INTERVAL_RTOL = 1e-9

#: Tolerance used when matching a wrong answer of a function against a typical mistake.
MISTAKE_RTOL = 1e-6


#: Failures after which a check calls the student's function no more (it would not help).
STOP_CALLING = (NotWrittenYet, TimedOut)


def passed(text: str) -> None:
    """Print a check's one ✓ line."""
    print(f"✓ {text}")


def tolerance_text(value: float) -> str:
    """A tolerance for a message: 1e-09 as "1e-9", 0.5 as "0.5"."""
    mantissa, exponent = f"{value:.0e}".split("e")
    return f"{mantissa}e{int(exponent)}" if value < 1e-3 else f"{value:g}"


def time_limit_text() -> str:
    """What a ✓ line says of the time limit: "each call given at most 5 s"."""
    return f"each call given at most {calling.TIME_LIMIT:g} s"


# ------------------------------------------------------------------------------------------
# The student's functions
# ------------------------------------------------------------------------------------------

def require_callable(function: object, what: str, check: str) -> str:
    """The name of the student's function, or CheckFailed if ``function`` is not one."""
    if not callable(function):
        found = "None" if function is None else f"a {type(function).__name__}"
        raise CheckFailed(
            f"{check} needs your function {what} itself (its name, without parentheses or "
            f"arguments), got {found}")
    return student_code.function_name(function)


def call_student(function: Callable, *args: object, name: str, where: str,
                 arg_names: Sequence[str] | None = None, hint: str = "",
                 shape_hint: str = "", forbid: Sequence[Callable] = (),
                 allow: Sequence[Callable] = ()) -> object:
    """``student_code.call`` for a check: every failure is one CheckFailed.

    The student's function may run no function of the pack but those of ``allow`` (a
    function task writes its answer itself: ``forbid_pack``, see
    :mod:`lqe_helpers.checks.own_work`). :class:`NotWrittenYet` and :class:`TimedOut`
    (both CheckFailed) are :data:`STOP_CALLING`: a check stops at once, calling again would
    not help; everything else (an exception, an input changed in place, a function of the
    pack run, ...) is a CheckFailed that shows the student's own lines where it happened.
    """
    return student_code.call(function, *args, name=name, where=where, arg_names=arg_names,
                             hint=hint, shape_hint=shape_hint, forbid=forbid,
                             forbid_pack=True, allow=allow, failure=CheckFailed)


def answers_on_cases(cases: Sequence[object], call: Callable[[object], object],
                     answer: Callable[[object, object], np.ndarray],
                     ) -> tuple[dict[int, np.ndarray], dict[int, CheckFailed]]:
    """A function check's random cases: ``call(case)`` (the student's function through
    :func:`call_student`), then ``answer(output, case)`` (its output checked as an array).

    Returns the answers and the call's failures, each by the case's index. A failure of
    :data:`STOP_CALLING` (not written yet, timed out) stops at once, as does a CheckFailed
    of ``answer`` (a wrong type or shape); any other failure of the call is kept, so that a
    typical mistake can still be named from the other cases.
    """
    answers: dict[int, np.ndarray] = {}
    errors: dict[int, CheckFailed] = {}
    for index, case in enumerate(cases):
        try:
            output = call(case)
        except STOP_CALLING:
            raise
        except CheckFailed as failure:
            errors[index] = failure
            continue
        answers[index] = answer(output, case)
    return answers, errors


def student_result(value: object, *, name: str, what: str,
                   shape: Sequence[int | None] | None = None, allow_nan: bool = False,
                   where: str = "") -> np.ndarray:
    """``student_code.result_array`` for a check: a float64 array, or one CheckFailed.

    Floats of less than double precision are refused: a function check compares to 1e-9.
    """
    return student_code.result_array(value, name=name, what=what, shape=shape,
                                     allow_nan=allow_nan, double=True, where=where,
                                     failure=CheckFailed)


# ------------------------------------------------------------------------------------------
# Values the student passes to a check
# ------------------------------------------------------------------------------------------

def argument_array(value: object, name: str, what: str,
                   shape: Sequence[int | None] | None = None,
                   allow_nan: bool = False) -> np.ndarray:
    """A value the student passed, as a float array, or CheckFailed naming it.

    Parameters
    ----------
    value : object
        What was passed.
    name : str
        The argument's name as the student knows it ("C", "mse_filtered[4.5]").
    what : str
        What it must be ("a 2 × 3 matrix", "one number (cm²)").
    shape, allow_nan
        See :func:`lqe_helpers.student_code.array_problem`.
    """
    problem = student_code.array_problem(value, shape=shape, allow_nan=allow_nan,
                                         returned=False)
    if problem is not None:
        raise CheckFailed(f"{name} must be {what}, got {problem}")
    return np.asarray(value, dtype=float)


def positive_number(value: object, name: str, unit: str) -> float:
    """A number > 0 the student passed (σ, Δt, ...), or CheckFailed naming it."""
    what = f"a number > 0{f' {unit}' if unit else ''}"
    number = float(argument_array(value, name, what, shape=()))
    if number <= 0:
        raise CheckFailed(f"{name} must be {what}, got {number:g}")
    return number


def shaped_argument(value: object, name: str, shape: tuple[int, ...], what: str) -> np.ndarray:
    """The student's array ``name`` of ``shape`` (``what`` it holds), or CheckFailed naming it."""
    return argument_array(value, name, f"{what}, an array of shape {shape}", shape=shape)


def keyed_entries(values: object, name: str, keys: Sequence[Hashable], what: str, *,
                  keyed_by: str | None = None, entry: Callable[[Hashable], str] = repr,
                  advice: str = "") -> dict:
    """The student's dict ``name`` with an entry for each of ``keys``, or CheckFailed.

    A number as a key is compared as a float (``{10: …}`` serves the key 10.0, as does a
    NumPy number); a bool is not a number and serves no key.

    Parameters
    ----------
    values : object
        What the student passed, e.g. ``mse_filtered``.
    name : str
        Its name, for messages.
    keys : sequence
        The keys the task asks for, in order (numbers as floats, or names).
    what : str
        What its values are ("MSEs (cm²) of the readings").
    keyed_by : str, optional
        What the keys are, for the message when ``values`` is not a dict ("σ_v (cm)");
        default the keys themselves.
    entry : callable
        How a missing key is named ("'an eighth'", "for σ_v = 1.5 cm"); default its repr.
    advice : str
        Appended to the message of a missing key ("; use the names of periods as keys").

    Returns
    -------
    dict
        The student's value for each key of ``keys``, in their order.

    Raises
    ------
    CheckFailed
        If ``values`` is not a dict, or a key of ``keys`` is missing from it.
    """
    if not isinstance(values, Mapping):
        found = "None" if values is None else f"a {type(values).__name__}"
        if keyed_by is None:
            keyed_by = ", ".join(repr(key) for key in keys)
        raise CheckFailed(f"{name} must be a dict of {what} keyed by {keyed_by}, got {found}")
    found_keys = {_as_key(key): value for key, value in values.items()
                  if not isinstance(key, bool)}
    missing = [key for key in keys if key not in found_keys]
    if missing:
        have = ", ".join(repr(key) for key in values) or "none"
        raise CheckFailed(f"{name} has no entry {entry(missing[0])} (its keys: {have}){advice}")
    return {key: found_keys[key] for key in keys}


def _as_key(key: Hashable) -> Hashable:
    """A student's dict key as :func:`keyed_entries` compares it: numbers as floats."""
    return float(key) if isinstance(key, (int, float, np.integer, np.floating)) else key


def interval_list(values: object, name: str, one_per: str, size: int | None = None) -> list:
    """The student's list (or tuple) ``name`` of intervals, one per value of a grid.

    ``one_per`` says what each is for ("σ_a of sigma_a_grid"); ``size`` is how many the
    grid has (None: any number but 0). The items are judged later
    (:func:`~lqe_helpers.checks.judging.judge_interval`).

    Raises
    ------
    CheckFailed
        If ``values`` is not a list or tuple of that length.
    """
    is_list = isinstance(values, (list, tuple))
    if not is_list or len(values) != ((len(values) or 1) if size is None else size):
        found = (f"{len(values)} entries" if is_list
                 else "None" if values is None else f"a {type(values).__name__}")
        count = "" if size is None else f"{size} "
        raise CheckFailed(f"{name} must be a list of {count}metrics.Interval, one per "
                          f"{one_per}, got {found}")
    return list(values)


# ------------------------------------------------------------------------------------------
# Comparing results
# ------------------------------------------------------------------------------------------

def close(a: np.ndarray, b: np.ndarray, rtol: float) -> bool:
    """``a`` and ``b`` agree within ``rtol`` of the larger of 1 and b's largest entry.

    NaN must stand where NaN stands (a row with no value yet, e.g. before a delay).
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape:
        return False
    finite = np.isfinite(b)
    if not np.array_equal(np.isfinite(a), finite):
        return False
    if not finite.any():
        return True
    scale = max(1.0, float(np.max(np.abs(b[finite]))))
    with np.errstate(over="ignore", invalid="ignore"):
        return bool(np.all(np.abs(a[finite] - b[finite]) <= rtol * scale))


def match_mistake(mistakes: Sequence[str], compute: Callable[[str, int], np.ndarray | None],
                  answers: dict[int, np.ndarray], correct: dict[int, np.ndarray],
                  rows: Callable[[int, np.ndarray], np.ndarray] | None = None) -> str | None:
    """The first mistake whose result equals the student's answer on every case it can run.

    ``answers`` maps case index → the student's (right-shaped) result; ``compute(mistake,
    index)`` gives the mistaken result or None. A mistake counts only if it differs from
    the correct result on at least one case, so it really explains the wrong answer.
    ``rows(index, wrong)``, if given, is a boolean mask of the rows to compare; a case
    where it selects none is skipped.
    """
    for mistake in mistakes:
        explained = False
        consistent = True
        for index, answer in answers.items():
            wrong = compute(mistake, index)
            if wrong is None:
                continue
            part = rows(index, wrong) if rows is not None else slice(None)
            if rows is not None and not np.any(part):
                continue
            if not close(answer[part], wrong[part], MISTAKE_RTOL):
                consistent = False
                break
            if not close(correct[index][part], wrong[part], MISTAKE_RTOL):
                explained = True
        if consistent and explained:
            return mistake
    return None
