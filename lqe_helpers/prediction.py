"""Delay compensation by prediction, Tutorial eq. (7)."""

from __future__ import annotations

import numpy as np

from . import validation


def predict_ahead(estimates: np.ndarray, A: np.ndarray, steps: int) -> np.ndarray:
    """Predict each estimate ``steps`` samples ahead: ``z*_j = A^δ ẑ_{j−δ}`` (Tutorial eq. (7)).

    Parameters
    ----------
    estimates : array_like, shape (..., n, k)
        Estimates ``ẑ`` from a filter fed the delayed signal: row j is the estimate of
        the state at sample j.
    A : array_like, shape (k, k)
        Transition matrix of one sample.
    steps : int
        Delay δ in samples, 0 <= δ <= n − 1.

    Returns
    -------
    ndarray, shape (..., n, k)
        ``out[..., j, :] = A^δ · estimates[..., j − δ, :]``; the first δ rows are NaN
        because no estimate old enough exists yet.
    """
    estimates = validation.finite_array("estimates", estimates, min_ndim=2)
    n_steps, k = estimates.shape[-2:]
    A = validation.square_matrix("A", A, size=k)
    if A.ndim != 2:
        raise ValueError(f"A must have shape ({k}, {k}), got shape {A.shape}")
    steps = validation.count("steps", steps, minimum=0, maximum=n_steps - 1)
    ahead = np.linalg.matrix_power(A, steps)
    out = np.full(estimates.shape, np.nan)
    out[..., steps:, :] = estimates[..., : n_steps - steps, :] @ ahead.T
    return out


def propagate_covariance(P0: np.ndarray, A: np.ndarray, Q: np.ndarray,
                         steps: int) -> np.ndarray:
    """Covariance with no measurements: ``P(k+1) = A P(k) Aᵀ + Q`` (Lesson 0.5 eq. (9)).

    With ``Q = G σ² Gᵀ`` this is the lesson's ``F P Fᵀ + G σ_u² Gᵀ``: how uncertainty
    grows when the observer predicts (dead reckoning) instead of measuring.

    Parameters
    ----------
    P0 : array_like, shape (..., k, k)
        Covariance at step 0, symmetric positive semidefinite.
    A : array_like, shape (k, k)
        Transition matrix.
    Q : array_like, shape (k, k)
        Process noise covariance added each step.
    steps : int
        Number of steps to propagate, >= 0.

    Returns
    -------
    ndarray, shape (..., steps + 1, k, k)
        ``P(0) … P(steps)``.
    """
    A = validation.square_matrix("A", A)
    if A.ndim != 2:
        raise ValueError(f"A must have shape (k, k), got shape {A.shape}")
    k = A.shape[0]
    P = validation.covariance("P0", P0, size=k)
    Q = validation.covariance("Q", Q, size=k)
    steps = validation.count("steps", steps, minimum=0)
    out = [P]
    for _ in range(steps):
        P = A @ P @ A.T + Q
        P = 0.5 * (P + P.mT)
        out.append(P)
    return np.stack(out, axis=-3)
