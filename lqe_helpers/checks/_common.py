"""What every check shares: CheckFailed, tolerances, calling and comparing answers."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

#: Seed of the random models the function checks use (fixed: a check gives the same
#: verdict and message every time it runs).
SEED = 2026

#: Relative tolerance of :func:`check_filter` and :func:`check_compensation`, scaled by
#: the largest entry of the correct result.
FUNCTION_RTOL = 1e-9

#: Relative tolerance of :func:`check_mse`.
MSE_RTOL = 1e-6

#: Relative tolerance of :func:`check_initial_covariance` and :func:`check_fusion`.
MATRIX_RTOL = 1e-9

#: Tolerance (s) of :func:`check_convergence_time`: the time is a whole number of samples.
TIME_ATOL = 1e-9

#: Relative tolerance (of the interval's scale) of :func:`check_paired_difference`.
INTERVAL_RTOL = 1e-9

#: Tolerance used when matching a wrong answer against a typical mistake.
MISTAKE_RTOL = 1e-6


class CheckFailed(AssertionError):
    """A task's answer is not right yet; the message says what is wrong."""


class NotWrittenYet(CheckFailed):
    """The student's function still raises NotImplementedError."""


def passed(text: str) -> None:
    print(f"✓ {text}")


def tolerance_text(value: float) -> str:
    """A tolerance for a message: 1e-09 as "1e-9", 0.5 as "0.5"."""
    mantissa, exponent = f"{value:.0e}".split("e")
    return f"{mantissa}e{int(exponent)}" if value < 1e-3 else f"{value:g}"


# ------------------------------------------------------------------------------------------
# Shared helpers
# ------------------------------------------------------------------------------------------

def function_name(function: object) -> str:
    return getattr(function, "__name__", "your function")


def require_callable(function: object, what: str, check: str) -> str:
    if not callable(function):
        raise CheckFailed(
            f"{check} needs your function {what} itself (its name, without parentheses or "
            f"arguments), got a {type(function).__name__}")
    return function_name(function)


def close(a: np.ndarray, b: np.ndarray, rtol: float) -> bool:
    """``a`` and ``b`` agree within ``rtol`` of the larger of 1 and b's largest entry."""
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
    return bool(np.all(np.abs(a[finite] - b[finite]) <= rtol * scale))


def describe_type(value: object) -> str:
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape}"
    if isinstance(value, (tuple, list)):
        return f"a {type(value).__name__} of {len(value)} items"
    return f"a {type(value).__name__}"


def shape_text(item: object) -> str:
    """``item``'s array shape as text, or its type if it is not a rectangular array."""
    try:
        return str(np.shape(item))
    except ValueError:
        return type(item).__name__


def as_result_array(output: object, name: str, expected: tuple[int, ...],
                    what: str) -> np.ndarray:
    """The student's return value as a float array, or CheckFailed if it is not one.

    ``what`` describes the expected result (e.g. "the estimates ẑ") and ``expected`` its
    shape, for the message; the caller checks the shape itself.
    """
    if output is None:
        raise CheckFailed(
            f"{name} returned nothing (None); it must return {what}. Does it end by "
            f"returning the result?")
    if isinstance(output, tuple):
        shapes = ", ".join(shape_text(item) for item in output)
        raise CheckFailed(
            f"{name} returned a tuple of {len(output)} items (shapes {shapes}); it must "
            f"return only {what}: one array of shape {expected}")
    if isinstance(output, list):
        raise CheckFailed(
            f"{name} returned a Python list; it must return {what} as one NumPy array of "
            f"shape {expected} (convert your list of rows into an array before returning)")
    if not isinstance(output, np.ndarray) and not np.isscalar(output):
        raise CheckFailed(
            f"{name} returned {describe_type(output)}; it must return {what}, a NumPy "
            f"array of shape {expected}")
    try:
        array = np.asarray(output, dtype=float)
    except (TypeError, ValueError):
        raise CheckFailed(
            f"{name} returned {describe_type(output)} that is not an array of numbers; it "
            f"must return {what}") from None
    return array



def match_mistake(mistakes: dict[str, str], compute: Callable[[str, int], np.ndarray | None],
                  answers: dict[int, np.ndarray], correct: dict[int, np.ndarray],
                  rows: Callable[[int, np.ndarray], np.ndarray] | None = None) -> str | None:
    """The first mistake whose result equals the student's answer on every model it can run.

    ``answers`` maps model index → the student's (right-shaped) result; ``compute(mistake,
    index)`` gives the mistaken result or None. A mistake counts only if it differs from
    the correct result on at least one model, so it really explains the wrong answer.
    ``rows(index, wrong)``, if given, is a boolean mask of the rows to compare; a model
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


def call_student(function: Callable, name: str, args: tuple, where: str, shape_hint: str = "",
                 hint: str = "") -> object:
    """``function(*args)``; NotImplementedError and other exceptions become CheckFailed.

    ``shape_hint`` is added to the message when the error is about shapes, ``hint``
    to every error message.
    """
    try:
        return function(*args)
    except NotImplementedError:
        raise NotWrittenYet(
            f"{name} is not written yet: replace the line `raise NotImplementedError` "
            f"with your code, run its cell, then run this check again") from None
    except Exception as error:  # any error of the student's code is reported, not hidden
        text = str(error)
        extra = f" {hint}" if hint else ""
        if shape_hint and isinstance(error, ValueError) and any(
                word in text for word in ("matmul", "shape", "broadcast", "aligned")):
            extra += f" {shape_hint}"
        raise CheckFailed(
            f"{name} raised {type(error).__name__}: {text} — on {where}.{extra}") from error


def positive_number(value: object, name: str, unit: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise CheckFailed(f"{name} must be a number > 0 {unit}, got {value!r}") from None
    if not np.isfinite(number) or number <= 0:
        raise CheckFailed(f"{name} must be a number > 0 {unit}, got {value!r}")
    return number


def matrix_argument(value: object, name: str) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise CheckFailed(
            f"{name} must be an array of numbers, got {describe_type(value)}") from None
    if not np.all(np.isfinite(array)):
        raise CheckFailed(f"{name} contains NaN or infinite values")
    return array
