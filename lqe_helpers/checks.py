"""Instant feedback for the tasks of the notebooks: one ``check_…`` after each task.

A check that passes prints one line starting with "✓ " saying what was verified. A check
that fails raises :class:`CheckFailed` (an ``AssertionError``, so "Run All" stops at the
wrong step) with a message that says what is wrong without giving the code.

Function checks (:func:`check_filter`, :func:`check_compensation`) call the student's
function on several small random models drawn from a fixed seed, not only on the pack's
scenario, so that a hard-coded answer cannot pass. When the answer is wrong they compare
it with typical mistakes computed here (kept private) to name the mistake.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import metrics, model, reference

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
_MISTAKE_RTOL = 1e-6


class CheckFailed(AssertionError):
    """A task's answer is not right yet; the message says what is wrong."""


class _NotWrittenYet(CheckFailed):
    """The student's function still raises NotImplementedError."""


def _passed(text: str) -> None:
    print(f"✓ {text}")


def _tolerance(value: float) -> str:
    """A tolerance for a message: 1e-09 as "1e-9", 0.5 as "0.5"."""
    mantissa, exponent = f"{value:.0e}".split("e")
    return f"{mantissa}e{int(exponent)}" if value < 1e-3 else f"{value:g}"


# ------------------------------------------------------------------------------------------
# Shared helpers
# ------------------------------------------------------------------------------------------

def _function_name(function: object) -> str:
    return getattr(function, "__name__", "your function")


def _require_callable(function: object, what: str, check: str) -> str:
    if not callable(function):
        raise CheckFailed(
            f"{check} needs your function {what} itself (its name, without parentheses or "
            f"arguments), got a {type(function).__name__}")
    return _function_name(function)


def _close(a: np.ndarray, b: np.ndarray, rtol: float) -> bool:
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


def _describe_type(value: object) -> str:
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape}"
    if isinstance(value, (tuple, list)):
        return f"a {type(value).__name__} of {len(value)} items"
    return f"a {type(value).__name__}"


def _shape_text(item: object) -> str:
    """``item``'s array shape as text, or its type if it is not a rectangular array."""
    try:
        return str(np.shape(item))
    except ValueError:
        return type(item).__name__


def _as_result_array(output: object, name: str, expected: tuple[int, ...],
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
        shapes = ", ".join(_shape_text(item) for item in output)
        raise CheckFailed(
            f"{name} returned a tuple of {len(output)} items (shapes {shapes}); it must "
            f"return only {what}: one array of shape {expected}")
    if isinstance(output, list):
        raise CheckFailed(
            f"{name} returned a Python list; it must return {what} as one NumPy array of "
            f"shape {expected} (convert your list of rows into an array before returning)")
    if not isinstance(output, np.ndarray) and not np.isscalar(output):
        raise CheckFailed(
            f"{name} returned {_describe_type(output)}; it must return {what}, a NumPy "
            f"array of shape {expected}")
    try:
        array = np.asarray(output, dtype=float)
    except (TypeError, ValueError):
        raise CheckFailed(
            f"{name} returned {_describe_type(output)} that is not an array of numbers; it "
            f"must return {what}") from None
    return array


@dataclass(frozen=True)
class _FilterModel:
    """A small random model for :func:`check_filter` (all arrays float, read-only copies)."""

    y: np.ndarray
    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    z0: np.ndarray
    P0: np.ndarray

    @property
    def args(self) -> tuple[np.ndarray, ...]:
        return (self.y, self.A, self.C, self.Q, self.R, self.z0, self.P0)

    @property
    def k(self) -> int:
        return self.A.shape[0]

    @property
    def m(self) -> int:
        return self.C.shape[0]

    @property
    def n(self) -> int:
        return self.y.shape[0]

    def describe(self) -> str:
        return (f"a model with k = {self.k} state{'s' * (self.k != 1)} and m = {self.m} "
                f"sensor{'s' * (self.m != 1)} (y {self.y.shape}, A {self.A.shape}, "
                f"C {self.C.shape}, Q {self.Q.shape}, R {self.R.shape}, z0 {self.z0.shape}, "
                f"P0 {self.P0.shape})")


#: (states k, sensors m) of the random models, in the order they are tried. The first is
#: the butterfly's own model (3 states, vision only); the square (2, 2) model lets a
#: transposed C run so that it can be recognised.
_FILTER_SIZES = ((3, 1), (2, 2), (1, 1), (4, 3), (3, 2), (2, 1))
_FILTER_STEPS = 15


@functools.cache
def _filter_models() -> tuple[_FilterModel, ...]:
    """The models of :func:`check_filter`, drawn once from :data:`SEED` (read-only)."""
    rng = np.random.default_rng(SEED)
    models = []
    for k, m in _FILTER_SIZES:
        if (k, m) == (3, 1):
            dt = 0.05
            A = model.transition_matrix(dt)
            C = model.observation_matrix(("vision",))
            Q = model.process_noise_covariance(dt, 200.0)
            R = model.measurement_noise_covariance([1.5])
            P0 = np.diag(rng.uniform(0.5, 3.0, size=3))
        else:
            A = np.eye(k) + 0.3 * rng.normal(size=(k, k))
            C = rng.normal(size=(m, k))
            X = rng.normal(size=(k, k))
            Q = 0.2 * X @ X.T + 0.05 * np.eye(k)
            R = np.diag(rng.uniform(0.5, 3.0, size=m))   # independent sensors, as eq. (6)
            Z = rng.normal(size=(k, k))
            P0 = Z @ Z.T + 0.5 * np.eye(k)
        z0 = rng.normal(size=k)
        y = 3.0 * rng.normal(size=(_FILTER_STEPS, m))
        arrays = [np.array(a, dtype=float) for a in (y, A, C, Q, R, z0, P0)]
        for array in arrays:
            array.setflags(write=False)
        models.append(_FilterModel(*arrays))
    return tuple(models)


@functools.cache
def _filter_result(mistake: str, index: int) -> np.ndarray | None:
    """Eq. (5) on model ``index``: right (``mistake`` = "") or with one typical mistake."""
    model_ = _filter_models()[index]
    if not mistake:
        return reference.lqe_filter(*model_.args)
    with np.errstate(all="ignore"):        # some mistakes diverge; that is expected
        return _filter_mistake(mistake, *model_.args)


def _matrix_sqrt(S: np.ndarray) -> np.ndarray:
    values, vectors = np.linalg.eigh(S)
    return vectors @ np.diag(np.sqrt(np.clip(values, 0.0, None))) @ vectors.T


def _filter_mistake(mistake: str, y, A, C, Q, R, z0, P0) -> np.ndarray | None:
    """Eq. (5) with one typical mistake; None if the mistake cannot run on this model."""
    if mistake == "c_transposed":
        if C.shape[0] != C.shape[1]:
            return None
        C = C.T
    elif mistake == "r_sqrt":
        R = _matrix_sqrt(R)
    elif mistake == "r_squared":
        R = R @ R
    z, P = z0, P0
    rows = []
    for y_j in y:
        if mistake == "p_before_k":
            P = A @ (P - P @ C.T @ np.linalg.inv(C @ P @ C.T + R) @ C @ P) @ A.T + Q
        if mistake == "textbook":
            P = A @ P @ A.T + Q
        if mistake == "gain_r_only":
            K = P @ C.T @ np.linalg.inv(R)
        else:
            K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
        if mistake == "innovation_z":
            z = A @ z + K @ (y_j - C @ z)
        elif mistake == "no_prediction":
            z = z + K @ (y_j - C @ z)
        elif mistake == "no_prediction_ca":
            z = z + K @ (y_j - C @ A @ z)
        else:
            z = A @ z + K @ (y_j - C @ A @ z)
        if mistake == "no_q":
            P = A @ (P - K @ C @ P) @ A.T
        elif mistake == "p_without_a":
            P = P - K @ C @ P + Q
        elif mistake == "textbook":
            P = P - K @ C @ P
        elif mistake != "p_before_k":
            P = A @ (P - K @ C @ P) @ A.T + Q
        rows.append(A @ z if mistake == "returns_prediction" else z)
    estimates = np.array(rows)
    if mistake == "shifted":
        estimates = np.vstack([z0, estimates[:-1]])
    return estimates


#: Typical mistakes in eq. (5) and what to tell the student, in the order they are tried.
_FILTER_MISTAKES = {
    "c_transposed": (
        "C is used transposed. C has one row per sensor and one column per state "
        "(shape (m, k)), so C P Cᵀ is m × m and C A ẑ has one entry per sensor"),
    "r_sqrt": (
        "R is used as if it held standard deviations (your filter behaves as if R were "
        "the square root of the one given). R already holds variances (cm²): use it as "
        "it is, without taking roots"),
    "r_squared": (
        "R is squared before it is used. R already holds variances (cm²), the "
        "squares of the standard deviations: use it as it is"),
    "gain_r_only": (
        "K is computed with R alone. The matrix inverted in the gain (first line of "
        "eq. (5)) is the uncertainty of the predicted measurement, C P Cᵀ, plus R"),
    "innovation_z": (
        "the measurement y_j is compared with C ẑ, the previous estimate seen through "
        "C. Eq. (5) compares it with the prediction C A ẑ: first move ẑ one step with A"),
    "no_prediction": (
        "the prediction step is missing: the new ẑ starts from the previous ẑ. In "
        "eq. (5) it starts from A ẑ (the previous estimate moved one step by the model), "
        "and y_j is compared with C A ẑ"),
    "no_prediction_ca": (
        "the new ẑ starts from the previous ẑ instead of the prediction A ẑ (second "
        "line of eq. (5)); the innovation y_j − C A ẑ is right"),
    "no_q": (
        "Q is left out of the covariance update: P must grow by the process noise Q "
        "every step (third line of eq. (5)), otherwise the filter soon trusts its model "
        "too much and stops listening to the measurements"),
    "p_without_a": (
        "the covariance update leaves out A … Aᵀ: P − K C P must be carried one step "
        "through the model (A on the left, Aᵀ on the right) before Q is added"),
    "p_before_k": (
        "P is updated before K is computed, so K uses next step's covariance. In each "
        "step compute K from the current P first, then ẑ, then the new P"),
    "textbook": (
        "P is predicted (A P Aᵀ + Q) before K is computed, the textbook predict-then-"
        "update order. In the tutorial's eq. (5), K uses P as it is (P0 is already the "
        "covariance of the prediction A z0) and P is carried to the next step at the end "
        "of each step"),
    "returns_prediction": (
        "each row is the prediction A ẑ for the next step instead of the estimate ẑ "
        "after y_j itself. Store ẑ, not A ẑ"),
    "shifted": (
        "the rows are one step late: your row 0 is z0 and row j the estimate after "
        "y_(j−1). Row j must be the estimate after y_j; z0 is the starting point, not a row"),
}


def _match_mistake(mistakes: dict[str, str], compute: Callable[[str, int], np.ndarray | None],
                   answers: dict[int, np.ndarray], correct: dict[int, np.ndarray],
                   rows: Callable[[int], slice] | None = None) -> str | None:
    """The first mistake whose result equals the student's answer on every model it can run.

    ``answers`` maps model index → the student's (right-shaped) result; ``compute(mistake,
    index)`` gives the mistaken result or None. A mistake counts only if it differs from
    the correct result on at least one model, so it really explains the wrong answer.
    """
    for mistake in mistakes:
        explained = False
        consistent = True
        for index, answer in answers.items():
            wrong = compute(mistake, index)
            if wrong is None:
                continue
            part = rows(index) if rows is not None else slice(None)
            if not _close(answer[part], wrong[part], _MISTAKE_RTOL):
                consistent = False
                break
            if not _close(correct[index][part], wrong[part], _MISTAKE_RTOL):
                explained = True
        if consistent and explained:
            return mistake
    return None


def _call(function: Callable, name: str, args: tuple, where: str, shape_hint: str = "",
          hint: str = "") -> object:
    """``function(*args)``; NotImplementedError and other exceptions become CheckFailed.

    ``shape_hint`` is added to the message when the error is about shapes, ``hint``
    to every error message.
    """
    try:
        return function(*args)
    except NotImplementedError:
        raise _NotWrittenYet(
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


# ------------------------------------------------------------------------------------------
# (a) the filter
# ------------------------------------------------------------------------------------------

_FILTER_SHAPE_HINT = (
    "The shapes in one product or sum do not fit: write the shape beside each term (y_j is "
    "(m,), ẑ is (k,), C is (m, k), P and A are (k, k), R is (m, m), K is (k, m)).")


def check_filter(my_filter: Callable[..., np.ndarray]) -> None:
    """Check a student's filter ``my_filter(y, A, C, Q, R, z0, P0)`` against Tutorial eq. (5).

    The function is called on six small random models (1–4 states, 1–3 sensors, 15
    steps, from the fixed seed :data:`SEED`) and must return the estimates, an array of
    shape (n, k) whose row j is ẑ after y_j, equal to :func:`reference.lqe_filter` within
    :data:`FUNCTION_RTOL` of the largest estimate.

    Parameters
    ----------
    my_filter : callable
        The student's function.

    Raises
    ------
    CheckFailed
        If the function is not written yet, raises an error, returns something of the
        wrong type or shape, changes its inputs, or computes other numbers; the message
        names the mistake when it is a typical one.
    """
    name = _require_callable(my_filter, "my_filter", "check_filter")
    models = _filter_models()
    answers: dict[int, np.ndarray] = {}
    correct: dict[int, np.ndarray] = {}
    errors: dict[int, CheckFailed] = {}
    for index, m in enumerate(models):
        inputs = [array.copy() for array in m.args]
        try:
            output = _call(my_filter, name, tuple(inputs), m.describe(),
                           shape_hint=_FILTER_SHAPE_HINT)
        except _NotWrittenYet:
            raise
        except CheckFailed as failure:
            errors[index] = failure
            continue
        for label, given, original in zip(("y", "A", "C", "Q", "R", "z0", "P0"), inputs,
                                          m.args, strict=True):
            if not np.array_equal(given, original):
                raise CheckFailed(
                    f"{name} changed its input {label} in place (on {m.describe()}). A "
                    f"filter must leave its inputs unchanged: work on new arrays instead "
                    f"of modifying {label} (e.g. with +=)")
        answers[index] = _filter_output(output, name, m)
        correct[index] = _filter_result("", index)

    wrong = [i for i in answers if not _close(answers[i], correct[i], FUNCTION_RTOL)]
    if not wrong and not errors:
        _passed(f"{name} matches eq. (5) on {len(models)} random models (1–4 states, 1–3 "
                f"sensors, {_FILTER_STEPS} steps) to {_tolerance(FUNCTION_RTOL)}")
        return

    mistake = _match_mistake(_FILTER_MISTAKES, _filter_result, answers, correct)
    if mistake is not None:
        also = ""
        if errors:
            first = min(errors)
            also = (f" (On {models[first].describe()} it does not even run: "
                    f"{str(errors[first]).split(' — ')[0]}.)")
        raise CheckFailed(f"{name} does not follow eq. (5): {_FILTER_MISTAKES[mistake]}.{also}")
    if errors:
        raise errors[min(errors)]
    index = wrong[0]
    m, answer, right = models[index], answers[index], correct[index]
    if not np.all(np.isfinite(answer)):
        row = int(np.argmax(~np.all(np.isfinite(answer), axis=1)))
        raise CheckFailed(
            f"{name} returned NaN or infinite values from row {row} on, on {m.describe()}")
    if answer.shape[0] > 1 and np.allclose(answer, answer[-1], rtol=0, atol=0) and \
            _close(answer[-1], right[-1], FUNCTION_RTOL):
        raise CheckFailed(
            f"every row of {name}'s result is the last estimate (on {m.describe()}): the "
            f"same array was stored at every step and then changed in place. Store a "
            f"separate copy of ẑ at each step")
    scale = max(1.0, float(np.max(np.abs(right))))
    bad_rows = np.any(np.abs(answer - right) > FUNCTION_RTOL * scale, axis=1)
    row = int(np.argmax(bad_rows))
    if row == 0:
        where = ("Already the first estimate (after y_0, starting from ẑ = z0 and P = P0) "
                 "differs: check the gain K and the ẑ line of eq. (5)")
    else:
        first = "The first estimate is" if row == 1 else f"The first {row} estimates are"
        where = (f"{first} right, then row {row} differs: K and ẑ are right at the "
                 f"start, so check how P is carried to the next step (third line of "
                 f"eq. (5))")
    raise CheckFailed(
        f"{name} does not match eq. (5) on {m.describe()}. {where}. (Largest difference "
        f"{float(np.max(np.abs(answer - right))):.3g} where the estimates are of size "
        f"{scale:.3g}.)")


def _filter_output(output: object, name: str, m: _FilterModel) -> np.ndarray:
    """The filter's output as an (n, k) array, or a CheckFailed naming what came back."""
    n, k = m.n, m.k
    what = "the estimates ẑ"
    array = _as_result_array(output, name, (n, k), what)
    where = f"on {m.describe()}"
    shape = array.shape
    if shape == (n, k):
        return array
    if shape == (n + 1, k):
        first = ("its first row is z0" if np.allclose(array[0], m.z0)
                 else "one row too many")
        raise CheckFailed(
            f"{name} returned {n + 1} rows for {n} measurements ({first}) {where}. Row j "
            f"must be the estimate after y_j, so there are exactly n = {n} rows: z0 is "
            f"the starting point, not an estimate")
    if shape == (n, k, k):
        raise CheckFailed(
            f"{name} returned an array of shape {shape}, the shape of the covariances P, "
            f"{where}; it must return the estimates ẑ, shape (n, k) = {(n, k)}")
    if shape == (n, k, 1):
        raise CheckFailed(
            f"{name} returned shape {shape} {where}: each estimate is a column (k, 1). "
            f"Each row of the result must be a flat vector of k = {k} numbers, so the "
            f"result has shape (n, k) = {(n, k)}")
    if shape == (n, k, m.m):
        raise CheckFailed(
            f"{name} returned an array of shape {shape}, the shape of the gains K, "
            f"{where}; it must return the estimates ẑ, shape (n, k) = {(n, k)}")
    if shape == (k, n):
        raise CheckFailed(
            f"{name} returned shape {shape} {where}: the result is transposed. Rows are "
            f"time steps, columns are states: shape (n, k) = {(n, k)}")
    if shape == (k, k):
        raise CheckFailed(
            f"{name} returned one {k} × {k} matrix {where} (the last covariance P?); it "
            f"must return all n = {n} estimates ẑ, shape (n, k) = {(n, k)}")
    if shape == (k,):
        raise CheckFailed(
            f"{name} returned a single estimate of shape {shape} {where} (the last one?); "
            f"it must return one estimate per measurement, shape (n, k) = {(n, k)}")
    if shape == (n, m.m) and m.m != k:
        raise CheckFailed(
            f"{name} returned shape {shape} {where}: one column per sensor. It must "
            f"return the state estimates ẑ, one column per state: shape (n, k) = {(n, k)}")
    raise CheckFailed(
        f"{name} returned an array of shape {shape} {where}; expected the estimates, "
        f"shape (n, k) = {(n, k)} (n = {n} measurements, k = {k} states)")


# ------------------------------------------------------------------------------------------
# (c) fusion: C and R for vision + proprioception
# ------------------------------------------------------------------------------------------

def check_fusion(C: np.ndarray, R: np.ndarray, sigma_v: float, sigma_p: float) -> None:
    """Check C and R for vision and proprioception (Tutorial eqs. (3), (6)).

    Expected: ``C = [[1, 0, 0], [1, 0, 0]]`` (both senses read the position of the state
    [p, v, a]; vision is row 0, proprioception row 1) and ``R = diag(σ_v², σ_p²)`` in
    cm², each within :data:`MATRIX_RTOL`.

    Parameters
    ----------
    C : array_like, shape (2, 3)
        The student's observation matrix.
    R : array_like, shape (2, 2)
        The student's sensor noise covariance (cm²).
    sigma_v, sigma_p : float
        The noise standard deviations (cm) the student used, > 0.

    Raises
    ------
    CheckFailed
        With the mistake named: wrong shape, transposed C, a row not reading position,
        standard deviations instead of variances, off-diagonal terms, swapped rows, ...
    """
    sigma_v = _positive_number(sigma_v, "sigma_v", "cm")
    sigma_p = _positive_number(sigma_p, "sigma_p", "cm")
    C = _matrix_argument(C, "C")
    R = _matrix_argument(R, "R")
    _check_fusion_C(C)
    _check_fusion_R(R, sigma_v, sigma_p)
    _passed(f"C (2 × 3) reads the position p for vision and for proprioception, and "
            f"R = diag(σ_v², σ_p²) = diag({sigma_v**2:g}, {sigma_p**2:g}) cm² (2 × 2)")


def _positive_number(value: object, name: str, unit: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise CheckFailed(f"{name} must be a number > 0 {unit}, got {value!r}") from None
    if not np.isfinite(number) or number <= 0:
        raise CheckFailed(f"{name} must be a number > 0 {unit}, got {value!r}")
    return number


def _matrix_argument(value: object, name: str) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise CheckFailed(
            f"{name} must be an array of numbers, got {_describe_type(value)}") from None
    if not np.all(np.isfinite(array)):
        raise CheckFailed(f"{name} contains NaN or infinite values")
    return array


def _check_fusion_C(C: np.ndarray) -> None:
    position = np.array([1.0, 0.0, 0.0])
    if C.shape == (3, 2):
        raise CheckFailed(
            "C has shape (3, 2): it is transposed. C has one row per sensor (vision, "
            "proprioception) and one column per state (p, v, a): shape (2, 3)")
    if C.shape in ((3,), (1, 3)):
        raise CheckFailed(
            f"C has shape {C.shape}: one row only. With two senses C needs one row per "
            f"sensor, vision and proprioception: shape (2, 3)")
    if C.shape != (2, 3):
        raise CheckFailed(
            f"C must have shape (2, 3): one row per sensor (vision, proprioception), one "
            f"column per state (p, v, a); got shape {C.shape}")
    labels = ("vision", "proprioception")
    for row, label in enumerate(labels):
        if np.allclose(C[row], position, rtol=0, atol=MATRIX_RTOL):
            continue
        read = [s for s, c in zip(("position p", "velocity v", "acceleration a"), C[row],
                                  strict=True) if c != 0]
        reads = " and ".join(read) if read else "nothing (all zeros)"
        raise CheckFailed(
            f"C's row {row} ({label}) is {C[row].tolist()}, which reads {reads}. "
            f"{label.capitalize()} measures the position only: its row must pick out p "
            f"from the state [p, v, a], with weight 1")


def _check_fusion_R(R: np.ndarray, sigma_v: float, sigma_p: float) -> None:
    variances = np.array([sigma_v**2, sigma_p**2])
    if R.ndim < 2 and R.size == 2:
        raise CheckFailed(
            f"R has shape {R.shape}: a vector. R is a 2 × 2 covariance matrix with the "
            f"two variances on its diagonal")
    if R.shape != (2, 2):
        raise CheckFailed(
            f"R must have shape (2, 2), one row and column per sensor, got shape {R.shape}")

    def same(a: np.ndarray, b: np.ndarray) -> bool:
        return bool(np.allclose(a, b, rtol=MATRIX_RTOL, atol=0.0))

    expected = np.diag(variances)
    if same(R, expected):
        return
    off = R[0, 1] != 0 or R[1, 0] != 0
    diag = np.diag(R)
    if off:
        raise CheckFailed(
            f"R has off-diagonal entries ({R[0, 1]:g}, {R[1, 0]:g}). Vision and "
            f"proprioception are independent (Tutorial eq. (6)): their covariances, the "
            f"off-diagonal entries, are 0")
    if same(diag, np.array([sigma_v, sigma_p])):
        raise CheckFailed(
            f"R holds the standard deviations σ_v = {sigma_v:g} and σ_p = {sigma_p:g} cm. "
            f"R is a covariance: its diagonal holds variances, in cm²")
    if same(diag, variances[::-1]):
        raise CheckFailed(
            "R's rows are swapped: row 0 must be vision's variance and row 1 "
            "proprioception's, in the same order as the rows of C")
    if same(diag, np.array([sigma_v, sigma_p]) ** 4):
        raise CheckFailed("R's diagonal holds σ⁴: the variances σ² were squared again")
    raise CheckFailed(
        f"R's diagonal is {diag.tolist()} cm²; for σ_v = {sigma_v:g} cm and σ_p = "
        f"{sigma_p:g} cm it must hold their variances")


# ------------------------------------------------------------------------------------------
# (e) delay compensation
# ------------------------------------------------------------------------------------------

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
    name = _require_callable(compensate, "compensate", "check_compensation")
    cases = _compensation_cases()
    answers: dict[int, np.ndarray] = {}
    correct: dict[int, np.ndarray] = {}
    for index, case in enumerate(cases):
        answers[index] = _run_compensation(compensate, name, case)
        correct[index] = reference.compensate(case.estimates, case.A, case.delay)

    def core(index: int) -> slice:
        return slice(cases[index].delay + 1, None)

    wrong_core = [i for i in answers
                  if not _close(answers[i][core(i)], correct[i][core(i)], FUNCTION_RTOL)]
    if wrong_core:
        def compute(mistake: str, index: int) -> np.ndarray | None:
            case = cases[index]
            return _compensation_mistake(mistake, case.estimates, case.A, case.delay)

        mistake = _match_core(compute, answers, correct, core)
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
        if not _close(answer[delay], right[delay], FUNCTION_RTOL):
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
    _passed(f"{name} matches eq. (7) (z*_j = A^δ ẑ_(j−δ), NaN before δ) on "
            f"{len(cases)} random cases (1–4 states, δ = 1–4) and with δ = 0, to "
            f"{_tolerance(FUNCTION_RTOL)}")


def _match_core(compute: Callable[[str, int], np.ndarray | None],
                answers: dict[int, np.ndarray], correct: dict[int, np.ndarray],
                core: Callable[[int], slice]) -> str | None:
    """Like :func:`_match_mistake`, comparing only the rows a mistake gives a value for."""
    for mistake in _COMPENSATION_MISTAKES:
        explained, consistent = False, True
        for index, answer in answers.items():
            wrong = compute(mistake, index)
            if wrong is None:
                continue
            rows = core(index)
            defined = np.all(np.isfinite(wrong), axis=1)
            defined[: rows.start] = False
            if not defined.any():
                continue
            if not _close(answer[defined], wrong[defined], _MISTAKE_RTOL):
                consistent = False
                break
            if not _close(correct[index][defined], wrong[defined], _MISTAKE_RTOL):
                explained = True
        if consistent and explained:
            return mistake
    return None


def _run_compensation(compensate: Callable, name: str, case: _CompensationCase) -> np.ndarray:
    estimates, A = case.estimates.copy(), case.A.copy()
    output = _call(compensate, name, (estimates, A, case.delay), case.describe(),
                   shape_hint=_COMPENSATION_SHAPE_HINT)
    if not np.array_equal(estimates, case.estimates) or not np.array_equal(A, case.A):
        raise CheckFailed(
            f"{name} changed its input estimates or A in place (on {case.describe()}). "
            f"Leave the inputs unchanged and return a new array")
    n, k = case.estimates.shape
    array = _as_result_array(output, name, (n, k), "z*, the compensated estimates")
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
    output = _call(compensate, name, (estimates.copy(), A.copy(), 0), case.describe(),
                   hint=_ZERO_DELAY_HINT)
    array = _as_result_array(output, name, (6, 3), "z*, the compensated estimates")
    if array.shape == (0, 3):
        raise CheckFailed(f"{name} returns an empty array when delay_steps = 0. "
                          f"{_ZERO_DELAY_HINT}")
    if not _close(array, estimates, FUNCTION_RTOL):
        raise CheckFailed(
            f"{name} is wrong when delay_steps = 0 (on {case.describe()}): with no delay "
            f"z* must equal the estimates (A⁰ = I, no NaN rows); got shape {array.shape}")


# ------------------------------------------------------------------------------------------
# Numbers a task produces
# ------------------------------------------------------------------------------------------

def check_initial_covariance(P0: np.ndarray, variance: float) -> None:
    """Check that ``P0 = variance · I₃`` (cm², cm²/s², cm²/s⁴ on the diagonal).

    The tutorial writes the initial covariance as ``P0 = diag(10⁵, 10⁵, 10⁵) cm²``:
    a 3 × 3 diagonal matrix of variances. Tolerance :data:`MATRIX_RTOL` relative.

    Parameters
    ----------
    P0 : array_like, shape (3, 3)
        The student's initial covariance.
    variance : float
        The variance the question sets (cm²), e.g. 1 or 10⁵, > 0.

    Raises
    ------
    CheckFailed
        For a single number, a vector, a wrong size, off-diagonal entries, standard
        deviations instead of variances, or other diagonal values.
    """
    variance = _positive_number(variance, "variance", "cm²")
    P0 = _matrix_argument(P0, "P0")
    if P0.ndim == 0:
        raise CheckFailed(
            f"P0 is a single number ({float(P0):g}). The filter needs a 3 × 3 matrix, "
            f"one row and column per state (p, v, a), with the variances on its diagonal")
    if P0.shape == (3,):
        raise CheckFailed(
            "P0 is a vector of 3 numbers. It must be a 3 × 3 matrix with these variances "
            "on its diagonal and 0 elsewhere")
    if P0.shape != (3, 3):
        raise CheckFailed(
            f"P0 must be 3 × 3 (one row and column per state p, v, a), got shape {P0.shape}")
    off = P0 - np.diag(np.diag(P0))
    if np.any(off != 0):
        if np.allclose(P0, variance, rtol=MATRIX_RTOL, atol=0):
            raise CheckFailed(
                f"every entry of P0 is {variance:g}. Only the diagonal holds the "
                f"variances; the off-diagonal entries (covariances between p, v and a) "
                f"are 0")
        raise CheckFailed(
            "P0 has non-zero off-diagonal entries; diag(…) means the variances on the "
            "diagonal and 0 everywhere else")
    diagonal = np.diag(P0)

    def same(value: float) -> bool:
        return bool(np.allclose(diagonal, value, rtol=MATRIX_RTOL, atol=0))

    if same(variance):
        _passed(f"P0 = {variance:g} · I (3 × 3, diagonal) cm²")
        return
    if same(np.sqrt(variance)):
        raise CheckFailed(
            f"P0's diagonal holds √{variance:g} = {np.sqrt(variance):g}, a standard "
            f"deviation. P0 is a covariance: its diagonal holds the variance, {variance:g}")
    if same(variance**2):
        raise CheckFailed(
            f"P0's diagonal holds {variance:g}² = {variance**2:g}: the variance was squared "
            f"again. The diagonal holds the variance itself, {variance:g}")
    if not np.allclose(diagonal, diagonal[0], rtol=MATRIX_RTOL, atol=0):
        raise CheckFailed(
            f"P0's diagonal entries differ ({diagonal.tolist()}); diag({variance:g}, "
            f"{variance:g}, {variance:g}) has the same variance for each state")
    raise CheckFailed(
        f"P0's diagonal holds {diagonal[0]:g}, expected the variance {variance:g}")


def check_mse(value: float | np.ndarray, estimate: np.ndarray, truth: np.ndarray,
              burn_in_steps: int = 0) -> None:
    """Check a mean squared error against :func:`metrics.mse` (relative tolerance 1e-6).

    Parameters
    ----------
    value : float or array_like, shape (...)
        The student's MSE (cm²): one number for one run, one per run for a batch (or
        the mean over the runs as one number).
    estimate : array_like, shape (..., n)
        Estimated positions (cm).
    truth : array_like, shape (n,)
        True positions (cm).
    burn_in_steps : int
        Samples skipped at the start.

    Raises
    ------
    CheckFailed
        With the mistake named: RMSE instead of MSE, burn-in not skipped or a different
        one, a sum instead of a mean, errors not squared, ...
    """
    try:
        expected = metrics.mse(estimate, truth, burn_in_steps)
    except ValueError as error:
        positions = ("" if "NaN" in str(error) else
                     ". It expects positions (cm): estimate of shape (n,) or (runs, n) and "
                     "truth of shape (n,), e.g. the position column of the states")
        raise CheckFailed(f"check_mse could not compute the MSE from your estimate and "
                          f"truth: {error}{positions}") from None
    got = _matrix_argument(value, "value")
    if got.size == 1 and (expected.ndim == 0 or expected.size > 1):
        got = got.reshape(())   # one number: the MSE of one run, or the mean over runs
    estimate = np.asarray(estimate, dtype=float)
    truth = np.asarray(truth, dtype=float)
    runs = expected.size if expected.ndim else 0
    skipped = f"skipping the first {burn_in_steps} samples" if burn_in_steps else "whole trial"

    def same(a: np.ndarray, b: np.ndarray) -> bool:
        return bool(np.shape(a) == np.shape(b)
                    and np.allclose(a, b, rtol=MSE_RTOL, atol=0.0, equal_nan=False))

    if got.shape == expected.shape and same(got, expected):
        what = f"{runs} MSEs (one per run)" if runs else "MSE"
        _passed(f"{what} match{'es' * (not runs)} metrics.mse (positions, {skipped}) to "
                f"rtol {_tolerance(MSE_RTOL)}")
        return
    if runs and got.ndim == 0 and same(got, np.mean(expected)):
        _passed(f"mean MSE over {runs} runs matches metrics.mse (positions, {skipped}) to "
                f"rtol {_tolerance(MSE_RTOL)}")
        return
    if got.shape != expected.shape and not (runs and got.ndim == 0):
        raise CheckFailed(
            f"your MSE has shape {got.shape}, expected {expected.shape} (one MSE "
            f"{'per run' if runs else 'for the trial'}) for estimate of shape "
            f"{estimate.shape}")
    if not np.all(np.isfinite(got)):
        raise CheckFailed("your MSE contains NaN or infinite numbers")
    if got.shape != expected.shape:
        expected = np.mean(expected)
        estimate = estimate.reshape(-1, estimate.shape[-1])
    kept = estimate[..., burn_in_steps:] - truth[burn_in_steps:]

    def pooled(per_run: np.ndarray) -> np.ndarray:
        return per_run if np.ndim(per_run) == np.ndim(got) else np.mean(per_run)

    mistakes = [
        (np.sqrt(expected), "your MSE is the root mean squared error (RMSE, in cm): the MSE "
                            "is its square, in cm², without the root"),
        (expected * kept.shape[-1], "your MSE is the sum of the squared errors: the MSE is "
                                    "their mean over the samples"),
        (pooled(np.mean(kept, axis=-1)), "your MSE is the mean error (the errors are not "
                                         "squared): square each error, then average"),
        (pooled(np.mean(np.abs(kept), axis=-1)), "your MSE is the mean absolute error: square "
                                                 "each error, then average"),
        (pooled(np.var(kept, axis=-1)), "your MSE is the variance of the error (its mean is "
                                        "subtracted): the MSE averages the squared errors "
                                        "themselves, bias included"),
    ]
    for candidate, message in mistakes:
        if same(got, candidate) and not same(candidate, expected):
            raise CheckFailed(message)
    if burn_in_steps > 0 and np.all(np.isfinite(estimate)):
        whole = pooled(metrics.mse(estimate, truth, 0))
        if same(got, whole):
            raise CheckFailed(
                f"your MSE is the MSE of the whole trial: the first burn_in_steps = "
                f"{burn_in_steps} samples were not skipped")
    other = _matching_burn_in(got, estimate, truth)
    if other is not None and other != burn_in_steps:
        raise CheckFailed(
            f"your MSE is the MSE after skipping {other} sample{'s' * (other != 1)}, but "
            f"burn_in_steps = "
            f"{burn_in_steps}. Skip exactly the burn-in (in samples, not seconds) and tell "
            f"the check the same number")
    raise CheckFailed(
        f"your MSE does not match the MSE of these positions ({skipped}), and not by one of "
        f"the usual mistakes: the MSE is the mean over the samples of (estimate − truth)²")


def _matching_burn_in(got: np.ndarray, estimate: np.ndarray, truth: np.ndarray) -> int | None:
    """The burn-in (samples) whose MSE equals ``got``, if there is one.

    ``got`` has the shape of one MSE per run, or is one number for the mean over runs.
    """
    squared = (estimate - truth) ** 2
    if not np.all(np.isfinite(squared)):
        return None
    n = squared.shape[-1]
    tail_sums = np.cumsum(squared[..., ::-1], axis=-1)[..., ::-1]    # sum from b on
    per_burn_in = np.moveaxis(tail_sums / (n - np.arange(n)), -1, 0)  # (n, ...)
    if np.ndim(got) == 0 and per_burn_in.ndim > 1:
        per_burn_in = per_burn_in.reshape(n, -1).mean(axis=1)
    for b in range(n):
        if np.allclose(got, per_burn_in[b], rtol=MSE_RTOL, atol=0.0):
            return b
    return None


def check_convergence_time(value: float, squared_error: np.ndarray, dt: float,
                           factor: float = 2.0) -> None:
    """Check a convergence time against the pack's definition (:func:`metrics.convergence_time`).

    The convergence time is the first sample time after which the Monte Carlo mean of
    the squared error stays within ``factor`` × its mean over the second half of the
    trial. ``squared_error`` is either that mean curve, shape (n,), or the squared errors
    of every run, shape (runs, n), whose mean over runs is then taken here. Tolerance
    :data:`TIME_ATOL` s (the time is a whole number of samples).

    Parameters
    ----------
    value : float
        The student's convergence time (s).
    squared_error : array_like, shape (n,) or (runs, n)
        Squared position errors (cm²): the Monte Carlo mean curve, or every run.
    dt : float
        Time step (s), > 0.
    factor : float
        Width of the band around the steady level, as in :func:`metrics.convergence_time`.

    Raises
    ------
    CheckFailed
        With the mistake named: steps instead of seconds, one run or per-run times
        instead of the Monte Carlo mean, first entry into the band, ...
    """
    dt = _positive_number(dt, "dt", "s")
    factor = _positive_number(factor, "factor", "")
    curves = _matrix_argument(squared_error, "squared_error")
    if curves.ndim not in (1, 2):
        raise CheckFailed(
            f"squared_error must have shape (n,) (the Monte Carlo mean curve) or (runs, n) "
            f"(every run), got shape {curves.shape}")
    curve = curves if curves.ndim == 1 else curves.mean(axis=0)
    try:
        expected = float(metrics.convergence_time(curve, dt, factor))
    except ValueError as error:
        raise CheckFailed(f"check_convergence_time could not use squared_error: {error}") \
            from None
    got = _matrix_argument(value, "value")
    mean_of = "the Monte Carlo mean squared error" if curves.ndim == 2 else "the curve"

    def same(a: object, b: float) -> bool:
        return bool(np.allclose(a, b, rtol=0.0, atol=TIME_ATOL))

    if curves.ndim == 2 and got.shape == (curves.shape[0],):
        raise CheckFailed(
            f"your value holds one convergence time per run ({got.size} values). The definition "
            f"applies to the Monte Carlo mean: average the squared errors over the runs "
            f"first, then take one convergence time of that mean curve")
    if got.size != 1:
        raise CheckFailed(f"your convergence time must be one number (s), got shape {got.shape}")
    got = float(got.reshape(()))
    if not np.isfinite(got):
        raise CheckFailed(f"your convergence time must be a finite number of seconds, got {got}")
    if same(got, expected):
        _passed(f"convergence time matches the pack's definition (first time after which "
                f"{mean_of} stays within {factor:g} × its second-half level) to "
                f"{_tolerance(TIME_ATOL)} s")
        return
    single_run = ("your convergence time is that of a single run ({}). The definition "
                  "applies to the Monte Carlo mean: average the squared errors over the "
                  "runs first")
    mistakes = [
        (expected / dt, "your convergence time is in samples (time steps): give it in "
                        f"seconds, samples × Δt (Δt = {dt:g} s)"),
        (expected * 1000.0, "your convergence time is in milliseconds: give it in seconds"),
    ]
    if curves.ndim == 2:
        per_run = metrics.convergence_time(curves, dt, factor)
        mistakes += [
            (float(per_run[0]), single_run.format("the first")),
            (float(per_run[-1]), single_run.format("the last")),
            (float(np.mean(per_run)), "your convergence time is the mean of the runs' "
                                      "convergence times. The definition averages the "
                                      "squared errors over the runs first, then takes one "
                                      "convergence time"),
        ]
    n = curve.size
    steady = np.mean(curve[n // 2:])
    inside = curve <= factor * steady
    if inside.any():
        mistakes.append((float(np.argmax(inside)) * dt,
                         "your convergence time is the first time the curve enters the "
                         "band; the definition asks for the time after which it stays "
                         "inside for good (it may leave the band again after entering it)"))
    if expected > 0:
        mistakes.append((expected - dt,
                         "your convergence time is the time of the last sample outside the "
                         "band; the convergence time is the sample just after it, the "
                         "first that stays inside"))
    for level, text in ((np.mean(curve), "the mean of the whole curve"),
                        (curve[-1], "the last sample")):
        outside = curve > factor * level
        time = (n - int(np.argmax(outside[::-1]))) * dt if outside.any() else 0.0
        mistakes.append((time, f"the steady level is taken as {text}; the definition uses "
                               f"the mean over the second half of the trial"))
    for candidate, message in mistakes:
        if same(got, candidate) and not same(candidate, expected):
            raise CheckFailed(message)
    raise CheckFailed(
        f"your convergence time, {got:g} s, is not the convergence time of {mean_of} by the pack's "
        f"definition (first sample time after which it stays <= {factor:g} × its mean "
        f"over the second half of the trial), and not by one of the usual mistakes")


def check_paired_difference(interval: metrics.Interval, mse_first: np.ndarray,
                            mse_second: np.ndarray) -> None:
    """Check a paired Monte Carlo difference against ``metrics.mean_ci95(first − second)``.

    ``mse_first`` and ``mse_second`` hold one MSE per run, computed on the same noise
    in run r; the answer to "is the first larger?" is the mean of the per-run
    differences with its 95 % Student-t interval. Tolerance :data:`INTERVAL_RTOL`
    relative to the interval's scale.

    Parameters
    ----------
    interval : metrics.Interval
        The student's interval (anything with ``mean``, ``low``, ``high``; ``runs`` is
        compared too if present).
    mse_first, mse_second : array_like, shape (runs,)
        Per-run MSEs (cm²) of the two conditions, run r of both on the same noise.

    Raises
    ------
    CheckFailed
        With the mistake named: not an Interval, reversed sign, unpaired interval, two
        intervals subtracted, standard deviation instead of standard error, 1.96 instead
        of the t value, the interval of one MSE alone, ...
    """
    first = _runs_argument(mse_first, "mse_first")
    second = _runs_argument(mse_second, "mse_second")
    if first.shape != second.shape:
        raise CheckFailed(
            f"mse_first and mse_second must hold one MSE per run for the same runs, got "
            f"shapes {first.shape} and {second.shape}")
    if not all(hasattr(interval, attribute) for attribute in ("mean", "low", "high")):
        if isinstance(interval, (tuple, list)) and len(interval) == 2:
            found = "a pair of numbers"
        elif np.isscalar(interval) or isinstance(interval, np.ndarray):
            found = "a number (or array)" if np.isscalar(interval) else "an array"
        else:
            found = _describe_type(interval)
        raise CheckFailed(
            f"your interval is {found}; it must be the metrics.Interval that metrics.mean_ci95 "
            f"returns (its mean, low and high), since a difference means little without "
            f"its 95 % interval")
    runs = first.size
    if getattr(interval, "runs", runs) != runs:
        raise CheckFailed(
            f"your interval is over {interval.runs} runs, but mse_first has {runs}: use the "
            f"per-run differences of all {runs} runs")
    got = np.array([interval.mean, interval.low, interval.high], dtype=float)
    if not np.all(np.isfinite(got)):
        raise CheckFailed("your interval contains NaN or infinite numbers")
    difference = first - second
    expected = metrics.mean_ci95(difference)
    scale = max(abs(expected.mean), expected.half_width, 1e-300)

    def same(a: tuple[float, float, float]) -> bool:
        return bool(np.all(np.abs(got - np.asarray(a)) <= INTERVAL_RTOL * scale))

    def around(mean: float, half: float) -> tuple[float, float, float]:
        return (mean, mean - half, mean + half)

    if same((expected.mean, expected.low, expected.high)):
        _passed(f"paired difference: mean and 95 % interval match metrics.mean_ci95 of "
                f"mse_first − mse_second over {runs} runs (to {_tolerance(INTERVAL_RTOL)} "
                f"relative)")
        return
    t = metrics.t_critical_95(runs - 1)
    s = float(np.std(difference, ddof=1))
    one_first, one_second = metrics.mean_ci95(first), metrics.mean_ci95(second)
    reverse = metrics.mean_ci95(second - first)
    unpaired = t * np.sqrt((np.var(first, ddof=1) + np.var(second, ddof=1)) / runs)
    mistakes = [
        ((reverse.mean, reverse.low, reverse.high),
         "the sign is reversed: your interval is of mse_second − mse_first; the check "
         "(and the question) wants mse_first − mse_second"),
        (around(expected.mean, one_first.half_width + one_second.half_width),
         "your interval combines the two MSEs' separate intervals. The runs are paired "
         "(the same noise in run r), so take the interval of the per-run differences: it "
         "is much narrower because the shared noise cancels"),
        (around(expected.mean, unpaired),
         "your interval treats the two MSEs as independent samples (unpaired). The runs "
         "are paired (the same noise in run r): take the interval of the per-run "
         "differences"),
        (around(expected.mean, t * s),
         "your half-width uses the standard deviation of the differences; a 95 % interval "
         "of the mean uses its standard error, the standard deviation divided by √runs"),
        (around(expected.mean, 1.959963984540054 * s / np.sqrt(runs)),
         "your half-width uses the normal 1.96 instead of Student's t value for "
         f"{runs - 1} degrees of freedom (metrics.mean_ci95 does this for you)"),
        (around(expected.mean, t * float(np.std(difference)) / np.sqrt(runs)),
         "the standard deviation is the population one (divided by runs); a sample "
         "standard deviation divides by runs − 1"),
        ((one_first.mean, one_first.low, one_first.high),
         "your interval is that of mse_first alone, not of the differences "
         "mse_first − mse_second"),
        ((one_second.mean, one_second.low, one_second.high),
         "your interval is that of mse_second alone, not of the differences "
         "mse_first − mse_second"),
    ]
    for candidate, message in mistakes:
        if same(candidate):
            raise CheckFailed(message)
    if abs(got[0] - expected.mean) <= INTERVAL_RTOL * scale:
        raise CheckFailed(
            "the mean difference is right but the interval's ends are not those of "
            "metrics.mean_ci95 of the per-run differences")
    raise CheckFailed(
        "your interval is not the mean of mse_first − mse_second per run with its 95 % interval, "
        "and not by one of the usual mistakes")


def _runs_argument(value: object, name: str) -> np.ndarray:
    array = _matrix_argument(value, name)
    if array.ndim != 1 or array.size < 2:
        raise CheckFailed(
            f"{name} must hold one MSE per Monte Carlo run, shape (runs,) with runs >= 2, "
            f"got shape {array.shape}")
    return array


# ------------------------------------------------------------------------------------------
# Background (notebook 00) and bonus (notebook 06): the model's matrices and eq. (9)
# ------------------------------------------------------------------------------------------

#: Time steps (s) at which :func:`check_transition_matrix` calls the student's function:
#: the pack's own, and others (some > 1 s, where Δt, Δt² and Δt²/2 all differ clearly).
_TRANSITION_DTS = (0.01, 0.037, 0.25, 1.3, 2.5)


def _transition_mistakes(dt: float) -> dict[str, tuple[np.ndarray, str]]:
    """Typical wrong transition matrices for step ``dt`` and what to say about each."""
    right = model.transition_matrix(dt)
    no_half = right.copy()
    no_half[0, 2] = dt**2
    no_corner = right.copy()
    no_corner[0, 2] = 0.0
    half_dt = right.copy()
    half_dt[0, 2] = dt / 2
    return {
        "transposed": (right.T, "A is transposed: the state [p, v, a] is a column, so the "
                                "first row says how the new position is made from p, v and "
                                "a; the entries above the diagonal belong in the first rows"),
        "no_half": (no_half, "the corner entry (row 0, column 2) is Δt², but the Taylor "
                             "term of the position is Δt²/2 times the acceleration"),
        "no_corner": (no_corner, "the new position ignores the acceleration: with constant "
                                 "acceleration the position also moves by Δt²/2 · a (row 0, "
                                 "column 2)"),
        "half_dt": (half_dt, "the corner entry is Δt/2; the Taylor term is Δt²/2 (Δt "
                             "squared, then halved)"),
        "identity": (np.eye(3), "A is the identity: nothing moves. The position must grow "
                                "by Δt · v and the velocity by Δt · a"),
    }


def check_transition_matrix(make_A: Callable[[float], np.ndarray]) -> None:
    """Check a student's ``make_A(dt)`` against Tutorial eq. (4) (constant acceleration).

    The function is called at several time steps (:data:`_TRANSITION_DTS`, s) and must
    return the 3 × 3 matrix ``[[1, Δt, Δt²/2], [0, 1, Δt], [0, 0, 1]]`` for the state
    [p, v, a], equal to :func:`model.transition_matrix` within :data:`MATRIX_RTOL`.

    Parameters
    ----------
    make_A : callable
        The student's function of the time step Δt (s).

    Raises
    ------
    CheckFailed
        If the function is not written yet, raises, returns the wrong shape, or another
        matrix; the message names the typical mistakes (transposed, Δt² without the
        half, no acceleration term, an answer that ignores Δt, ...).
    """
    name = _require_callable(make_A, "make_A", "check_transition_matrix")
    answers = {}
    for dt in _TRANSITION_DTS:
        output = _call(make_A, name, (dt,), f"dt = {dt:g} s")
        array = _as_result_array(output, name, (3, 3), "the transition matrix A")
        if array.shape != (3, 3):
            raise CheckFailed(
                f"{name}({dt:g}) returned shape {array.shape}; A must be 3 × 3, one row and "
                f"one column per state (p, v, a)")
        answers[dt] = array
    wrong = [dt for dt, array in answers.items()
             if not _close(array, model.transition_matrix(dt), MATRIX_RTOL)]
    if not wrong:
        _passed(f"{name} gives eq. (4)'s A (constant acceleration) at {len(answers)} time "
                f"steps from {min(_TRANSITION_DTS):g} to {max(_TRANSITION_DTS):g} s, to "
                f"{_tolerance(MATRIX_RTOL)}")
        return
    first, last = answers[_TRANSITION_DTS[0]], answers[_TRANSITION_DTS[-1]]
    if len(wrong) < len(answers) and np.allclose(first, last) and not np.allclose(
            model.transition_matrix(_TRANSITION_DTS[0]),
            model.transition_matrix(_TRANSITION_DTS[-1])):
        raise CheckFailed(
            f"{name} returns the same matrix for every time step: it must use its argument "
            f"dt (the pack's Δt is only one of the steps tried)")
    for key in ("transposed", "no_half", "no_corner", "half_dt", "identity"):
        if all(_close(answers[dt], _transition_mistakes(dt)[key][0], MATRIX_RTOL)
               for dt in wrong):
            raise CheckFailed(f"{name}: {_transition_mistakes(wrong[0])[key][1]}")
    dt = wrong[0]
    raise CheckFailed(
        f"{name}({dt:g}) is not eq. (4)'s A: row 0 must turn [p, v, a] into the Taylor step "
        f"of the position, row 1 that of the velocity, row 2 keeps the acceleration")


#: (states k, inputs r) of the random cases of :func:`check_covariance_step`.
_COVARIANCE_CASES = ((3, 1), (2, 1), (4, 2), (1, 1), (3, 2))


@functools.cache
def _covariance_cases() -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray, float], ...]:
    """(P, F, G, σ) for each case, drawn from ``SEED + 2`` (read-only arrays)."""
    rng = np.random.default_rng(SEED + 2)
    cases = []
    for k, r in _COVARIANCE_CASES:
        X = rng.normal(size=(k, k))
        P = X @ X.T + 0.3 * np.eye(k)
        F = np.eye(k) + 0.5 * rng.normal(size=(k, k))
        G = rng.normal(size=(k, r))
        sigma = float(rng.uniform(1.5, 4.0))
        for array in (P, F, G):
            array.setflags(write=False)
        cases.append((P, F, G, sigma))
    return tuple(cases)


def _covariance_mistakes(P, F, G, sigma) -> dict[str, tuple[np.ndarray, str]]:
    noise = sigma**2 * G @ G.T
    return {
        "sides": (F.T @ P @ F + noise, "F and Fᵀ are on the wrong sides: the state moves as "
                                       "F z, so its covariance becomes F P Fᵀ (F on the left)"),
        "no_noise": (F @ P @ F.T, "the random input's covariance G σ² Gᵀ is not added: "
                                  "without it the uncertainty never grows by the noise"),
        "sigma": (F @ P @ F.T + sigma * G @ G.T, "σ is used where its square belongs: a "
                                                 "covariance adds variances, G σ² Gᵀ"),
        "no_transpose": (F @ P @ F + noise, "the second F is not transposed: F P Fᵀ"),
        "not_moved": (P + noise, "P is not carried through the model: the old covariance "
                                 "must be moved one step by F (F P Fᵀ) before the noise is "
                                 "added"),
    }


def check_covariance_step(predict_covariance: Callable[..., np.ndarray]) -> None:
    """Check ``predict_covariance(P, F, G, sigma)`` against Lesson 0.5 eq. (9).

    The function must return ``F P Fᵀ + G σ² Gᵀ``, the covariance one step later with
    no measurement, when the state moves as ``z(k+1) = F z(k) + G u(k)`` and the input u
    has standard deviation σ. It is called on five random cases (1–4 states, 1–2 inputs,
    from ``SEED + 2``) and must agree within :data:`MATRIX_RTOL`.

    Parameters
    ----------
    predict_covariance : callable
        The student's function of (P (k, k), F (k, k), G (k, r), sigma).

    Raises
    ------
    CheckFailed
        If the function is not written yet, raises, changes its inputs, returns the
        wrong shape, or another matrix; typical mistakes are named (F on the wrong
        sides, no noise term, σ instead of σ², no transpose, P not moved by F).
    """
    name = _require_callable(predict_covariance, "predict_covariance", "check_covariance_step")
    wrong = []
    for P, F, G, sigma in _covariance_cases():
        inputs = (P.copy(), F.copy(), G.copy(), sigma)
        where = f"P and F of shape {P.shape}, G of shape {G.shape}, sigma = {sigma:.3g}"
        output = _call(predict_covariance, name, inputs, where,
                       shape_hint="P and F are (k, k), G is (k, r): write each term's shape.")
        for label, given, original in zip(("P", "F", "G"), inputs, (P, F, G), strict=False):
            if not np.array_equal(given, original):
                raise CheckFailed(f"{name} changed its input {label} in place ({where}); "
                                  f"return a new matrix instead")
        array = _as_result_array(output, name, P.shape, "the new covariance P")
        if array.shape != P.shape:
            raise CheckFailed(f"{name} returned shape {array.shape} for {where}; the new "
                              f"covariance has the shape of P, {P.shape}")
        right = F @ P @ F.T + sigma**2 * G @ G.T
        if not _close(array, right, MATRIX_RTOL):
            wrong.append((array, P, F, G, sigma, where))
    if not wrong:
        _passed(f"{name} gives F P Fᵀ + G σ² Gᵀ (Lesson 0.5 eq. (9)) on "
                f"{len(_COVARIANCE_CASES)} random cases (1–4 states, 1–2 inputs), to "
                f"{_tolerance(MATRIX_RTOL)}")
        return
    for key in ("sides", "no_noise", "sigma", "no_transpose", "not_moved"):
        if all(_close(array, _covariance_mistakes(P, F, G, sigma)[key][0], MATRIX_RTOL)
               for array, P, F, G, sigma, _ in wrong):
            raise CheckFailed(f"{name} does not follow eq. (9): "
                              f"{_covariance_mistakes(*wrong[0][1:5])[key][1]}")
    raise CheckFailed(
        f"{name} does not give F P Fᵀ + G σ² Gᵀ on {wrong[0][5]}, and not by one of the "
        f"usual mistakes")


def check_bias_model(F: np.ndarray, G: np.ndarray, Q: np.ndarray, dt: float,
                     sigma_a: float) -> None:
    """Check F, G and Q of the biased acceleration model (Lesson 0.5 eqs. (4), (5), (9)).

    Expected, for the state [p, v, b] and the input u = a_r (cm/s²):
    ``F = [[1, Δt, −Δt²/2], [0, 1, −Δt], [0, 0, 1]]``, ``G = [Δt²/2, Δt, 0]ᵀ`` (shape
    (3, 1)) and ``Q = G σ_a² Gᵀ``, each within :data:`MATRIX_RTOL`
    (:mod:`lqe_helpers.bias_model`).

    Parameters
    ----------
    F : array_like, shape (3, 3)
    G : array_like, shape (3, 1)
    Q : array_like, shape (3, 3)
        The student's matrices.
    dt : float
        The time step they were built for (s), > 0.
    sigma_a : float
        The signal's noise they were built for (cm/s²), > 0.

    Raises
    ------
    CheckFailed
        With the mistake named: shapes, the bias added instead of removed, Δt² without
        the half, a row for the bias in G, σ_a instead of σ_a², ...
    """
    from . import bias_model

    dt = _positive_number(dt, "dt", "s")
    sigma_a = _positive_number(sigma_a, "sigma_a", "cm/s²")
    F = _matrix_argument(F, "F")
    G = _matrix_argument(G, "G")
    Q = _matrix_argument(Q, "Q")
    right_F = bias_model.transition_matrix(dt)
    right_G = bias_model.input_matrix(dt)
    if F.shape != (3, 3):
        raise CheckFailed(f"F must be 3 × 3 (state [p, v, b]), got shape {F.shape}")
    if G.shape == (3,):
        raise CheckFailed("G has shape (3,): make it a column, shape (3, 1), so that G σ² Gᵀ "
                          "is a 3 × 3 matrix")
    if G.shape != (3, 1):
        raise CheckFailed(f"G must have shape (3, 1): one row per state, one column for the "
                          f"single input; got shape {G.shape}")
    if not _close(F, right_F, MATRIX_RTOL):
        if _close(F[:, :2], right_F[:, :2], MATRIX_RTOL) and _close(F[:2, 2], -right_F[:2, 2],
                                                                      MATRIX_RTOL):
            raise CheckFailed(
                "F's last column adds the bias; the reading a_r = a + b carries the bias, so "
                "the model must remove its estimate: the entries are −Δt²/2 and −Δt")
        if _close(F[:, :2], right_F[:, :2], MATRIX_RTOL) and np.allclose(F[:2, 2], 0):
            raise CheckFailed(
                "F's last column does not correct for the bias (zeros above the diagonal): "
                "the bias estimate must be subtracted from the reading, −Δt²/2 and −Δt")
        if _close(F[0, 2], -dt**2, MATRIX_RTOL) or _close(F[0, 2], dt**2, MATRIX_RTOL):
            raise CheckFailed("F[0, 2] holds Δt²; the position integrates the acceleration "
                              "over a step with Δt²/2")
        raise CheckFailed(
            "F is not Lesson 0.5 eq. (5)'s transition matrix for [p, v, b]: p moves by Δt v "
            "and by Δt²/2 times (reading − bias), v by Δt times it, b stays")
    if not _close(G, right_G, MATRIX_RTOL):
        if _close(G[:2], right_G[:2], MATRIX_RTOL):
            raise CheckFailed("G's last entry must be 0: the reading does not change the bias")
        if _close(G[0], np.array([dt**2]), MATRIX_RTOL):
            raise CheckFailed("G[0] holds Δt²; the position takes Δt²/2 of the reading")
        raise CheckFailed("G is not Lesson 0.5 eq. (5)'s input matrix: the reading enters the "
                          "position with Δt²/2, the velocity with Δt, the bias not at all")
    right_Q = sigma_a**2 * right_G @ right_G.T
    if Q.shape != (3, 3):
        raise CheckFailed(f"Q must be 3 × 3, got shape {Q.shape}")
    if not _close(Q, right_Q, MATRIX_RTOL):
        if _close(Q, sigma_a * right_G @ right_G.T, MATRIX_RTOL):
            raise CheckFailed("Q uses σ_a where its square belongs: Q = G σ_a² Gᵀ (variances, "
                              "not standard deviations)")
        if _close(Q, sigma_a**2 * np.eye(3), MATRIX_RTOL) or _close(
                Q, sigma_a**2 * np.diag(right_G[:, 0]), MATRIX_RTOL):
            raise CheckFailed("Q is not pushed through G: the signal's noise reaches the "
                              "state the way the signal does, Q = G σ_a² Gᵀ")
        if _close(Q, sigma_a**2 * right_G.T @ right_G, MATRIX_RTOL):
            raise CheckFailed("Q is built as Gᵀ G (one number); the covariance is G σ_a² Gᵀ, "
                              "3 × 3")
        raise CheckFailed("Q is not G σ_a² Gᵀ (Lesson 0.5 eq. (9)) for the given σ_a")
    _passed(f"F, G and Q = G σ_a² Gᵀ match Lesson 0.5 eqs. (5), (9) for Δt = {dt:g} s and "
            f"σ_a = {sigma_a:g} cm/s², to {_tolerance(MATRIX_RTOL)}")
