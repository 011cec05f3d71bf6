"""The check of task (a): the student's filter of Tutorial eq. (5)."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import model, reference
from ._common import (
    FUNCTION_RTOL,
    SEED,
    CheckFailed,
    NotWrittenYet,
    as_result_array,
    call_student,
    close,
    match_mistake,
    passed,
    require_callable,
    tolerance_text,
)


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
    name = require_callable(my_filter, "my_filter", "check_filter")
    models = _filter_models()
    answers: dict[int, np.ndarray] = {}
    correct: dict[int, np.ndarray] = {}
    errors: dict[int, CheckFailed] = {}
    for index, m in enumerate(models):
        inputs = [array.copy() for array in m.args]
        try:
            output = call_student(my_filter, name, tuple(inputs), m.describe(),
                                  shape_hint=_FILTER_SHAPE_HINT)
        except NotWrittenYet:
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

    wrong = [i for i in answers if not close(answers[i], correct[i], FUNCTION_RTOL)]
    if not wrong and not errors:
        passed(f"{name} matches eq. (5) on {len(models)} random models (1–4 states, 1–3 "
               f"sensors, {_FILTER_STEPS} steps) to {tolerance_text(FUNCTION_RTOL)}")
        return

    mistake = match_mistake(_FILTER_MISTAKES, _filter_result, answers, correct)
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
            close(answer[-1], right[-1], FUNCTION_RTOL):
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
    array = as_result_array(output, name, (n, k), what)
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
