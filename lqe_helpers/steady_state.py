"""The filter's steady state: the fixed point of the Riccati recursion in Tutorial eq. (5)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _engine, validation


@dataclass(frozen=True)
class SteadyState:
    """Limits of :func:`~lqe_helpers.filter.kalman_filter`'s outputs as ``j → ∞``.

    Attributes
    ----------
    covariance : ndarray, shape (..., k, k)
        ``P∞``: fixed point of ``P ← A (P − P Cᵀ (C P Cᵀ + R)⁻¹ C P) Aᵀ + Q``, the
        covariance of the one-step prediction.
    gain : ndarray, shape (..., k, m)
        ``K∞ = P∞ Cᵀ (C P∞ Cᵀ + R)⁻¹``.
    estimate_covariance : ndarray, shape (..., k, k)
        ``(I − K∞ C) P∞``: the covariance of the estimate ``ẑ`` itself, whose [0, 0]
        entry is the position error variance (cm²) an ideal model would reach.
    """

    covariance: np.ndarray
    gain: np.ndarray
    estimate_covariance: np.ndarray


def steady_state(A: np.ndarray, C: np.ndarray, Q: np.ndarray, R: np.ndarray,
                 max_doublings: int = 200, rtol: float = 1e-13) -> SteadyState:
    """Solve the filter's discrete algebraic Riccati equation by structured doubling.

    The structure-preserving doubling algorithm (Chu, Fan & Lin 2005) doubles the
    horizon each step (step i summarises 2^i steps of the recursion), so it reaches
    the fixed point in tens of cheap steps instead of thousands.
    Starting matrices: ``Aᵢ = Aᵀ``, ``Gᵢ = Cᵀ R⁻¹ C``, ``Hᵢ = Q``; each step::

        W = (I + Gᵢ Hᵢ)⁻¹
        Aᵢ₊₁ = Aᵢ W Aᵢ,  Gᵢ₊₁ = Gᵢ + Aᵢ W Gᵢ Aᵢᵀ,  Hᵢ₊₁ = Hᵢ + Aᵢᵀ Hᵢ W Aᵢ

    and ``Hᵢ → P∞``.

    Parameters
    ----------
    A : array_like, shape (k, k)
    C : array_like, shape (m, k)
    Q : array_like, shape (k, k)
        Symmetric positive semidefinite; (A, Q) must excite every unstable mode.
    R : array_like, shape (..., m, m)
        Symmetric positive definite; a batch gives one steady state per R.
    max_doublings : int
        Limit on the doubling steps (2^200 recursion steps).
    rtol : float
        Relative change of P below which the iteration stops.

    Returns
    -------
    SteadyState

    Raises
    ------
    ValueError
        If the inputs are invalid; if (A, C) is not detectable (C cannot see a mode of
        A that does not decay, such as the position when only the velocity is measured:
        see :func:`undetectable_modes`); if P overflows all the same; or if
        ``max_doublings`` steps end before the relative change of P falls to ``rtol``.
    """
    A = validation.square_matrix("A", A)
    if A.ndim != 2:
        raise ValueError(f"A must have shape (k, k), got shape {A.shape}")
    k = A.shape[0]
    C = validation.finite_array("C", C, min_ndim=2)
    if C.ndim != 2 or C.shape[1] != k:
        raise ValueError(f"C must have shape (m, {k}), got shape {C.shape}")
    m = C.shape[0]
    Q = validation.covariance("Q", Q, size=k)
    if Q.ndim != 2:
        raise ValueError(f"Q must have shape ({k}, {k}), got shape {Q.shape}")
    R = validation.covariance("R", R, size=m, definite=True)
    max_doublings = validation.count("max_doublings", max_doublings, minimum=1)
    rtol = validation.positive("rtol", rtol)
    directions, eigenvalues = undetectable_modes(A, C)
    if directions.shape[1]:
        shown = np.round(directions.T, 6) + 0.0  # + 0.0 turns -0.0 into 0.0
        eigenvalues = np.round(eigenvalues, 6) + 0.0
        raise ValueError(
            f"(A, C) must be detectable (C must observe every mode of A that does not "
            f"decay), got C = {C.tolist()}, which cannot see the state direction(s) "
            f"{shown.tolist()}, on which A has eigenvalue(s) {eigenvalues.tolist()} of "
            f"modulus >= 1: the error of the estimate there never shrinks, so the filter "
            f"has no steady state; add a sensor that reads those states"
        )

    return SteadyState(*_engine.riccati(A, C, Q, R, max_doublings, rtol))


#: Rank tolerance of the observability matrix, relative to its largest singular value.
OBSERVABILITY_RTOL = 1e-12
#: Modes of A with |λ| > 1 − this count as not decaying (a decay time of 10⁶ steps or
#: more). The margin also absorbs the rounding of repeated eigenvalues such as the
#: triple eigenvalue 1 of the constant-acceleration model.
DECAY_MARGIN = 1e-6


def undetectable_modes(A: np.ndarray, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The part of the state that C never sees, if A does not make it decay.

    (A, C) is detectable when every mode of A with ``|λ| >= 1`` is observable
    (Popov–Belevitch–Hautus test: ``[A − λI; C]`` has full column rank for those λ).
    Here the unobservable subspace ``N``, the null space of the observability matrix
    ``[C; C A; …; C A^{k−1}]``, is computed by SVD (rank tolerance
    :data:`OBSERVABILITY_RTOL` of the largest singular value). N is invariant under A
    and the eigenvalues of A restricted to N are exactly its unobservable modes, so
    (A, C) is detectable when all of them satisfy ``|λ| <= 1 −`` :data:`DECAY_MARGIN`.

    Parameters
    ----------
    A : ndarray, shape (k, k)
        Transition matrix, already validated.
    C : ndarray, shape (m, k)
        Observation matrix, already validated.

    Returns
    -------
    directions : ndarray, shape (k, d)
        A basis of N in reduced echelon form (each column 1 at its own pivot state and 0
        at the others' pivots, so ``[1, 0, 0]`` reads "the position"); d = 0 when (A, C)
        is detectable.
    eigenvalues : ndarray, shape (e,)
        The eigenvalues of A on N with ``|λ| > 1 −`` :data:`DECAY_MARGIN`, 1 <= e <= d
        (e = 0 when (A, C) is detectable).
    """
    k = A.shape[0]
    # The observable subspace of (A/s, C) is that of (A, C): scaling A by its largest
    # magnitude keeps C A^(k−1) finite for any A.
    scale = float(np.max(np.abs(A))) or 1.0
    blocks, block = [], C / (float(np.max(np.abs(C))) or 1.0)
    for _ in range(k):
        blocks.append(block)
        block = block @ (A / scale)
    _, singular, vt = np.linalg.svd(np.vstack(blocks))
    largest = singular[0] if singular.size else 0.0
    rank = int(np.sum(singular > OBSERVABILITY_RTOL * largest)) if largest > 0 else 0
    unobservable = vt[rank:].T                                       # (k, d)
    eigenvalues = np.linalg.eigvals(unobservable.T @ A @ unobservable)
    slow = eigenvalues[np.abs(eigenvalues) > 1.0 - DECAY_MARGIN]
    if slow.size == 0:
        return np.zeros((k, 0)), np.zeros(0)
    # Reduced echelon form: greedily pick the states that make the basis independent.
    pivots: list[int] = []
    for state in range(k):
        trial = unobservable[[*pivots, state]]
        if np.linalg.matrix_rank(trial, tol=1e-9) == len(pivots) + 1:
            pivots.append(state)
    echelon = np.linalg.solve(unobservable[pivots].T, unobservable.T).T
    echelon[np.abs(echelon) < 1e-12] = 0.0
    return echelon, slow.real if np.all(slow.imag == 0) else slow
