"""The random models of :func:`check_filter`, their right estimates and its typical mistakes.

The right estimates come from the pack's engine (:func:`lqe_helpers.filter.kalman_filter`).
Each typical mistake is computed from the engine with one input changed where it can be
(R as σ, Q left out, the textbook order is the engine started one prediction later, ...)
or from the engine's gains with a changed update, so no readable worked filter lives here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import experiments, model
from ..filter import FILTER_ARGS, kalman_filter
from ..scenario import DEFAULT
from .machinery import SEED
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback


@dataclass(frozen=True)
class FilterCase:
    """One call of :func:`check_filter`: a small random model and its readings.

    All arrays float and read-only. Not :class:`lqe_helpers.experiments.FilterModel`,
    the model a filter of the butterfly assumes: this one is drawn at random and carries
    its readings ``y``.
    """

    y: np.ndarray
    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    z0: np.ndarray
    P0: np.ndarray
    #: What the case is, for the messages; empty for a random model.
    label: str = ""

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
        if self.label:
            return self.label
        return (f"a model with k = {self.k} state{'s' * (self.k != 1)} and m = {self.m} "
                f"sensor{'s' * (self.m != 1)} (y {self.y.shape}, A {self.A.shape}, "
                f"C {self.C.shape}, Q {self.Q.shape}, R {self.R.shape}, z0 {self.z0.shape}, "
                f"P0 {self.P0.shape})")

    def engine(self, **changed: np.ndarray):
        """The engine's result on this model, with the inputs in ``changed`` replaced."""
        inputs = dict(zip(FILTER_ARGS, self.args, strict=True))
        return kalman_filter(**{**inputs, **changed})


#: (states k, sensors m) of the random models, in the order they are tried. The first is
#: the butterfly's own model (3 states, vision only); the square (2, 2) model lets a
#: transposed C run so that it can be recognised.
FILTER_SIZES = ((3, 1), (2, 2), (1, 1), (4, 3), (3, 2), (2, 1))
#: Measurements per random model.
FILTER_STEPS = 15
#: The last case: the butterfly's whole trial (vision alone, the scenario's readings, all
#: its steps), so a filter that goes wrong only after the random models' few steps (a loop
#: bound, a gain frozen after a while) is caught here, not blamed in a later notebook.
TRIAL_LABEL = (f"the butterfly's whole trial (the vision-only model of the tasks, the "
               f"scenario's {DEFAULT.n_steps} readings)")


@remembered
def models() -> tuple[FilterCase, ...]:
    """The models of :func:`check_filter`, drawn once from :data:`SEED` (read-only), then
    the butterfly's whole trial (:data:`TRIAL_LABEL`)."""
    rng = np.random.default_rng(SEED)
    drawn = []
    for k, m in FILTER_SIZES:
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
        y = 3.0 * rng.normal(size=(FILTER_STEPS, m))
        arrays = [np.array(a, dtype=float) for a in (y, A, C, Q, R, z0, P0)]
        for array in arrays:
            array.setflags(write=False)
        drawn.append(FilterCase(*arrays))
    vision = experiments.filter_model(DEFAULT)
    arrays = [np.array(a, dtype=float) for a in (
        experiments.track(DEFAULT).measurements, vision.A, vision.C, vision.Q, vision.R,
        vision.z0, vision.P0)]
    for array in arrays:
        array.setflags(write=False)
    drawn.append(FilterCase(*arrays, label=TRIAL_LABEL))
    return tuple(drawn)


@remembered
def right_estimates(index: int) -> np.ndarray:
    """The engine's estimates (n, k) on model ``index`` (read-only)."""
    estimates = np.array(models()[index].engine().estimates)
    estimates.setflags(write=False)
    return estimates


def _matrix_sqrt(S: np.ndarray) -> np.ndarray:
    values, vectors = np.linalg.eigh(S)
    return vectors @ np.diag(np.sqrt(np.clip(values, 0.0, None))) @ vectors.T


def _gains_of(m: FilterCase, gain: str, update: str) -> list[np.ndarray]:
    """Gains of a mistaken covariance recursion: K from R alone, or P updated without A."""
    P, gains = m.P0, []
    for _ in range(m.n):
        if gain == "r_only":
            K = P @ m.C.T @ np.linalg.inv(m.R)
        else:
            K = P @ m.C.T @ np.linalg.inv(m.C @ P @ m.C.T + m.R)
        gains.append(K)
        P = P - K @ m.C @ P + m.Q if update == "without_a" else \
            m.A @ (P - K @ m.C @ P) @ m.A.T + m.Q
    return gains


def _estimates_with(m: FilterCase, gains, start: str, compare: str) -> np.ndarray:
    """Estimates from given gains; ẑ starts from A ẑ or ẑ, y is compared with C A ẑ or C ẑ."""
    z, rows = m.z0, []
    for y_j, K in zip(m.y, gains, strict=True):
        base = m.A @ z if start == "Az" else z
        seen = m.C @ m.A @ z if compare == "CAz" else m.C @ z
        z = base + K @ (y_j - seen)
        rows.append(z)
    return np.array(rows)


@remembered
def mistaken_estimates(mistake: str, index: int) -> np.ndarray | None:
    """Eq. (5) on model ``index`` with one of :data:`FILTER_MISTAKES`; None if it cannot run."""
    m = models()[index]
    with np.errstate(all="ignore"):        # some mistakes diverge; that is expected
        if mistake == "c_transposed":
            return m.engine(C=m.C.T).estimates if m.k == m.m else None
        if mistake == "r_sqrt":
            return m.engine(R=_matrix_sqrt(m.R)).estimates
        if mistake == "r_squared":
            return m.engine(R=m.R @ m.R).estimates
        if mistake == "gain_r_only":
            return _estimates_with(m, _gains_of(m, "r_only", "with_a"), "Az", "CAz")
        if mistake == "p_without_a":
            return _estimates_with(m, _gains_of(m, "full", "without_a"), "Az", "CAz")
        gains = m.engine().gains
        if mistake == "innovation_z":
            return _estimates_with(m, gains, "Az", "Cz")
        if mistake == "no_prediction":
            return _estimates_with(m, gains, "z", "Cz")
        if mistake == "no_prediction_ca":
            return _estimates_with(m, gains, "z", "CAz")
        if mistake == "no_q":
            return m.engine(Q=np.zeros_like(m.Q)).estimates
        if mistake == "p_before_k":        # K from next step's P: the engine one step on
            S = m.C @ m.P0 @ m.C.T + m.R
            K = m.P0 @ m.C.T @ np.linalg.inv(S)
            return m.engine(P0=m.A @ (m.P0 - K @ m.C @ m.P0) @ m.A.T + m.Q).estimates
        if mistake == "textbook":          # P predicted first: the engine from A P0 Aᵀ + Q
            return m.engine(P0=m.A @ m.P0 @ m.A.T + m.Q).estimates
        right = right_estimates(index)
        if mistake == "returns_prediction":
            return right @ m.A.T
        if mistake == "shifted":
            return np.vstack([m.z0, right[:-1]])
    raise ValueError(f"mistake must be one of {tuple(FILTER_MISTAKES)}, got {mistake!r}")


#: Typical mistakes in eq. (5) and what to tell the student, in the order they are tried.
FILTER_MISTAKES = {
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
