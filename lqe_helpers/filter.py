"""The Linear Quadratic Estimator (Kalman filter) of Tutorial eq. (5), batched.

:func:`kalman_filter` is the public entry: it checks its inputs and runs the engine's
core (:func:`lqe_helpers._engine.filter_run`, which checks nothing again).
"""

from __future__ import annotations

import numpy as np

from . import _engine, validation
from ._engine import CovarianceSequence, FilterResult

__all__ = ["FILTER_ARGS", "CovarianceSequence", "FilterResult", "kalman_filter"]

#: The parameters of a filter of eq. (5), in order: :func:`kalman_filter`'s first seven,
#: and a student's ``my_filter(y, A, C, Q, R, z0, P0)`` (its check, its explorers).
FILTER_ARGS = ("y", "A", "C", "Q", "R", "z0", "P0")


def kalman_filter(y: np.ndarray, A: np.ndarray, C: np.ndarray, Q: np.ndarray,
                  R: np.ndarray, z0: np.ndarray, P0: np.ndarray,
                  B: np.ndarray | None = None, u: np.ndarray | None = None) -> FilterResult:
    """Filter measurements with the Linear Quadratic Estimator of Tutorial eq. (5).

    For each measurement ``y_j`` (j = 0 … n−1), starting from ``ẑ = z0`` and ``P = P0``::

        K = P Cᵀ (C P Cᵀ + R)⁻¹
        ẑ ← A ẑ + K (y_j − C A ẑ)
        P ← A (P − K C P) Aᵀ + Q

    With a known input (Lesson 0.5 eq. (4), ``z_{j+1} = A z_j + B u_j``) the
    prediction ``A ẑ`` becomes ``A ẑ + B u_j`` in both places, where ``u_j`` is the
    input applied over the step that ends at ``y_j``. The input's own noise belongs
    in Q (Lesson 0.5 eq. (9)), so K and P are unchanged.

    Because K and P do not depend on the data they are computed once per distinct
    (R, P0) (``lqe_helpers._engine``), and the estimates of every Monte Carlo run
    follow from ``ẑ ← (A − K C A) ẑ + K y_j`` in one vectorised pass.

    Parameters
    ----------
    y : array_like, shape (..., n, m)
        Measurements (cm), n >= 1 time steps of m sensors; leading axes are batch
        axes (Monte Carlo runs, a parameter sweep, ...).
    A : array_like, shape (k, k)
        Transition matrix (Tutorial eq. (1)).
    C : array_like, shape (m, k)
        Observation matrix (Tutorial eq. (2)).
    Q : array_like, shape (k, k)
        Process noise covariance, symmetric positive semidefinite.
    R : array_like, shape (..., m, m)
        Sensor noise covariance (cm²), symmetric positive definite.
    z0 : array_like, shape (..., k)
        Initial state estimate.
    P0 : array_like, shape (..., k, k)
        Initial covariance, symmetric positive semidefinite.
    B : array_like, shape (k, p), optional
        Input matrix; give it together with ``u``.
    u : array_like, shape (..., n, p), optional
        Known inputs, one per measurement (e.g. an acceleration reading in cm/s²).

    Returns
    -------
    FilterResult
        Estimates, gains and covariances; batch axes are those of y, R, z0 and P0
        broadcast together.

    Raises
    ------
    ValueError
        If a shape does not fit, a value is not finite, or a covariance is not
        symmetric positive (semi)definite.
    """
    y = validation.finite_array("y", y, min_ndim=2)
    n_steps, m = y.shape[-2:]  # n_steps >= 1: validation refuses an empty y
    A = validation.square_matrix("A", A)
    if A.ndim != 2:
        raise ValueError(f"A must have shape (k, k), got shape {A.shape}")
    k = A.shape[0]
    C = validation.finite_array("C", C)
    if C.shape != (m, k):
        raise ValueError(
            f"C must have shape (m, k) = ({m}, {k}) to match y's {m} sensor(s) and A's "
            f"{k} states, got shape {C.shape}"
        )
    Q = validation.covariance("Q", Q, size=k)
    if Q.ndim != 2:
        raise ValueError(f"Q must have shape ({k}, {k}), got shape {Q.shape}")
    R = validation.covariance("R", R, size=m, definite=True)
    P0 = validation.covariance("P0", P0, size=k)
    z0 = validation.finite_array("z0", z0, min_ndim=1)
    if z0.shape[-1] != k:
        raise ValueError(f"z0 must have trailing length k = {k}, got shape {z0.shape}")
    if (B is None) != (u is None):
        raise ValueError(
            f"B and u must be given together, got B {'absent' if B is None else 'present'} "
            f"and u {'absent' if u is None else 'present'}"
        )
    input_batch: tuple[int, ...] = ()
    if B is not None:
        B = validation.finite_array("B", B, min_ndim=2)
        if B.ndim != 2 or B.shape[0] != k:
            raise ValueError(f"B must have shape ({k}, p), got shape {B.shape}")
        u = validation.finite_array("u", u, min_ndim=2)
        if u.shape[-2:] != (n_steps, B.shape[1]):
            raise ValueError(
                f"u must have trailing shape (n, p) = ({n_steps}, {B.shape[1]}) to match y "
                f"and B, got shape {u.shape}"
            )
        input_batch = u.shape[:-2]
    validation.broadcast_batches(
        y=y.shape[:-2], R=R.shape[:-2], z0=z0.shape[:-1], P0=P0.shape[:-2], u=input_batch
    )
    return _engine.filter_run(y, A, C, Q, R, z0, P0, B, u)
