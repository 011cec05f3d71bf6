"""The Linear Quadratic Estimator (Kalman filter) of Tutorial eq. (5), batched."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import validation


@dataclass(frozen=True)
class FilterResult:
    """Output of :func:`kalman_filter` for ``n`` measurements of a ``k``-state model.

    Attributes
    ----------
    estimates : ndarray, shape (..., n, k)
        ``ẑ_j``, the state estimate after measurement ``y_j`` (units of the state).
    gains : ndarray, shape (..., n, k, m)
        ``K`` used with ``y_j``.
    covariances : ndarray, shape (..., n, k, k)
        ``P`` after ``y_j``: the tutorial's ``P_{j+1}``, the covariance of the
        one-step prediction ``A ẑ_j`` that the next measurement is compared with.
    estimate_covariances : ndarray, shape (..., n, k, k)
        ``(I − K C) P_j``: the filter's own covariance of ``ẑ_j`` itself, the value to
        set beside an empirical mean squared error.
    innovation_covariances : ndarray, shape (..., n, m, m), or None
        ``S_j = C P_j Cᵀ + R``: the covariance the filter expects of the innovation
        ``y_j − C A ẑ_{j−1}`` (cm²), with ``P_j`` the prior before ``y_j`` (P0 for the
        first reading). :func:`~lqe_helpers.metrics.innovations` pairs it with the
        innovations themselves. None in a result assembled by hand.
    """

    estimates: np.ndarray
    gains: np.ndarray
    covariances: np.ndarray
    estimate_covariances: np.ndarray
    innovation_covariances: np.ndarray | None = None


@dataclass(frozen=True)
class CovarianceSequence:
    """Gains and covariances of Tutorial eq. (5): the part that ignores the data.

    Shapes are ``(..., n, k, m)`` and ``(..., n, k, k)`` with the batch axes of R and P0.
    """

    gains: np.ndarray
    covariances: np.ndarray
    estimate_covariances: np.ndarray


def _covariance_sequence(n_steps: int, A: np.ndarray, C: np.ndarray, Q: np.ndarray,
                        R: np.ndarray, P0: np.ndarray) -> CovarianceSequence:
    """Run the gain and covariance lines of Tutorial eq. (5) for ``n_steps`` steps.

    ``K_j = P_j Cᵀ (C P_j Cᵀ + R)⁻¹`` and ``P_{j+1} = A (P_j − K_j C P_j) Aᵀ + Q``,
    evaluated in a numerically careful but algebraically identical way:

    * the sensors are whitened with R's Cholesky factor L (``C_w = L⁻¹ C``, unit
      noise) and reduced to orthogonal rows ``c_i`` that carry independent
      information (:func:`_independent_rows`: two sensors of one state become one
      row), applied one scalar measurement at a time, so no nearly singular
      ``C P Cᵀ + R`` is ever inverted (two sensors reading the same state under a
      prior of 10¹⁰ cm² would lose ten digits in that inverse);
    * each scalar update has the gain ``g_i = P c_iᵀ / (c_i P c_iᵀ + 1)``, accurate to
      rounding because its denominator is >= 1, and the Joseph form
      ``P ← (I − g_i c_i) P (I − g_i c_i)ᵀ + g_i g_iᵀ``, a sum of positive semidefinite
      terms, so P stays a covariance for P0 from 10⁻⁶ to 10¹⁰ cm² and σ from 10⁻³ to
      10³ cm;
    * the gain of the whole measurement is assembled from the scalar gains: a reading
      applied at row i is corrected again by every later row, so column i of the
      gain for the rows is ``K_r[:, i] = (I − g_r c_r) ⋯ (I − g_{i+1} c_{i+1}) g_i``,
      and ``K = K_r U_rᵀ L⁻¹`` maps it back to the sensors. This equals
      ``P Cᵀ (C P Cᵀ + R)⁻¹`` to rounding (``tests/test_gain_precision.py``: 1e-12
      relative against 50-digit arithmetic for P0 up to 10¹⁰ and σ down to 10⁻³),
      where taking it from the updated covariance, ``P⁺ Cᵀ R⁻¹``, cancels up to all
      sixteen digits when one sensor reads several states.

    The prior ``P_{j+1}`` is symmetrised when it is formed, and that very matrix is
    both the next step's input and the returned ``covariances[..., j, :, :]``, so
    each returned gain belongs to the returned covariance before it.

    Once one step leaves P unchanged (every entry within 10⁻¹⁴ relative: the
    Riccati fixed point to rounding) the remaining steps repeat the last gain
    instead of re-rounding the same numbers. The check runs every few steps and
    always compares consecutive steps, so a covariance that cycles never passes.

    Inputs are assumed already validated by :func:`kalman_filter`; R (..., m, m) and
    P0 (..., k, k) may carry batch axes that broadcast against each other.
    """
    batch = np.broadcast_shapes(R.shape[:-2], P0.shape[:-2])
    k, m = A.shape[0], C.shape[0]
    R = np.broadcast_to(R, (*batch, m, m))
    chol = np.linalg.cholesky(R)
    whitened = np.linalg.solve(chol, np.broadcast_to(C, (*batch, m, k)))  # C_w = L⁻¹ C
    rows_matrix, to_sensors = _independent_rows(whitened, chol)
    rows = [(rows_matrix[..., i:i + 1, :], rows_matrix[..., i:i + 1, :].mT)
            for i in range(rows_matrix.shape[-2])]
    P = np.array(np.broadcast_to(P0, (*batch, k, k)))
    identity = np.eye(k)
    # np.dot skips matmul's broadcasting machinery, which dominates 3×3 products.
    mul = np.dot if P.ndim == 2 else np.matmul
    no_gain = np.zeros((*batch, k, m))
    estimate_covariances, gains, covariances = [], [], []
    for j in range(n_steps):
        prior = P
        K_w = None
        for row, row_T in rows:
            Pc = mul(P, row_T)
            g = Pc / (mul(row, Pc) + 1.0)
            L = identity - mul(g, row)
            P = mul(mul(L, P), L.mT) + mul(g, g.mT)
            # A reading applied at this row is corrected again by every later row.
            K_w = g if K_w is None else np.concatenate([mul(L, K_w), g], axis=-1)
        gains.append(no_gain if K_w is None else mul(K_w, to_sensors))
        estimate_covariances.append(P)
        P = mul(mul(A, P), A.T) + Q
        P = 0.5 * (P + P.mT)
        covariances.append(P)
        # P_{j+1} = f(P_j) for a fixed map f, so P_{j+1} = P_j means every later P is
        # the same. (Comparing P with itself several steps back would not do: a
        # covariance that cycles with that period would pass for converged.)
        if j % _CONVERGENCE_CHECK_EVERY == 0 and np.allclose(P, prior, rtol=_CONVERGED_RTOL,
                                                              atol=0.0):
            break
    converged = len(gains)
    stacks = [np.stack(s, axis=-3) for s in (estimate_covariances, gains, covariances)]
    if converged < n_steps:
        stacks = [np.concatenate([s, _repeat_last(s, n_steps - converged)], axis=-3)
                  for s in stacks]
    estimate_covariances, gains, covariances = stacks
    estimate_covariances = 0.5 * (estimate_covariances + estimate_covariances.mT)
    return CovarianceSequence(gains, covariances, estimate_covariances)


def _independent_rows(whitened: np.ndarray, chol: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The whitened sensors as orthogonal rows carrying independent information.

    With the SVD ``C_w = U Σ Vᵀ`` of rank r, the readings ``Uᵀ L⁻¹ y`` of the first r
    left singular vectors are ``Σ_r V_rᵀ z`` plus unit white noise, and the others
    carry noise only: updating with the r rows ``Σ_r V_rᵀ`` is the same update, and
    the gain for the original sensors is ``K = K_r U_rᵀ L⁻¹``. Sequential scalar
    updates are exact to rounding on such rows, whereas rows that repeat information
    (more sensors than states) would meet a covariance already reduced to rounding
    noise in the directions they see. Sensors that read the same state alone stay
    one row, the reliability-weighted combination of their readings.

    Parameters
    ----------
    whitened : ndarray, shape (..., m, k)
        ``C_w = L⁻¹ C``.
    chol : ndarray, shape (..., m, m)
        L, the Cholesky factor of R.

    Returns
    -------
    rows : ndarray, shape (..., r, k)
        ``Σ_r V_rᵀ``; r is the largest numerical rank over the batch (singular values
        above ``max(m, k) · eps`` times the largest).
    to_sensors : ndarray, shape (..., r, m)
        ``U_rᵀ L⁻¹``.
    """
    left, singular, right_T = np.linalg.svd(whitened, full_matrices=False)
    m, k = whitened.shape[-2:]
    tolerance = max(m, k) * np.finfo(float).eps * singular[..., :1]
    rank = int(np.max(np.sum(singular > tolerance, axis=-1), initial=0))
    rows = singular[..., :rank, None] * right_T[..., :rank, :]
    to_sensors = left[..., :, :rank].mT @ np.linalg.inv(chol)
    return rows, to_sensors


_CONVERGENCE_CHECK_EVERY = 16
_CONVERGED_RTOL = 1e-14


def _repeat_last(stack: np.ndarray, times: int) -> np.ndarray:
    """The last entry along axis -3 repeated ``times`` times."""
    last = stack[..., -1:, :, :]
    return np.broadcast_to(last, (*last.shape[:-3], times, *last.shape[-2:]))


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
    (R, P0) by :func:`_covariance_sequence`, and the estimates of every Monte Carlo
    run follow from ``ẑ ← (A − K C A) ẑ + K y_j`` in one vectorised pass.

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
    batch = validation.broadcast_batches(
        y=y.shape[:-2], R=R.shape[:-2], z0=z0.shape[:-1], P0=P0.shape[:-2], u=input_batch
    )

    covariance_batch = np.broadcast_shapes(R.shape[:-2], P0.shape[:-2])
    inputs_per_run = 0 if B is None else 2 * B.shape[1]
    validation.check_memory(
        f"y of shape {y.shape}, R of shape {R.shape}, z0 of shape {z0.shape} and P0 of shape "
        f"{P0.shape}",
        n_steps * (validation.elements(covariance_batch) * (3 * k * m + 6 * k * k + 2 * m * m)
                   + validation.elements(batch) * (4 * k + 2 * m + inputs_per_run)),
        what="for the estimates, gains and covariances")

    # Overflow is detected below and reported as a ValueError naming the inputs, not
    # left to NaN and RuntimeWarnings.
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        sequence = _covariance_sequence(n_steps, A, C, Q, R, P0)
        _refuse_overflow("the covariance P", sequence.covariances, A=A, Q=Q, R=R, P0=P0)
        _refuse_overflow("the gain K", sequence.gains, A=A, Q=Q, R=R, P0=P0)
        gains = sequence.gains
        # ẑ_j = M_j ẑ_{j-1} + K_j y_j + (I − K_j C) B u_j with M_j = A − K_j C A:
        # Tutorial eq. (5) rearranged so that the data enter once, for all j together.
        transitions_T = (A - gains @ (C @ A)).mT
        inputs = [(y, gains)]
        if B is not None:
            inputs.append((u, (np.eye(k) - gains @ C) @ B))
        if transitions_T.ndim == 3:
            estimates = _estimates_shared_gains(inputs, z0, transitions_T, batch)
        else:
            estimates = _estimates_swept_gains(inputs, z0, transitions_T, batch)
        innovation_covariances = _innovation_covariances(sequence.covariances, C, R, P0)
        _refuse_overflow("the innovation covariance S = C P Cᵀ + R", innovation_covariances,
                         C=C, R=R, P0=P0)
    # A NaN or inf never turns finite again in ẑ ← M ẑ + K y, so the last estimate of
    # each run tells whether any overflowed (and costs nothing next to the filter).
    if not np.all(np.isfinite(estimates[..., -1, :])):
        named = {"y": y, "A": A, "C": C, "z0": z0} | ({} if B is None else {"B": B, "u": u})
        raise ValueError(
            f"the estimates overflowed the float64 range (reached inf or NaN): the inputs "
            f"are too large together; their largest magnitudes are {_largest(named)}")

    def full(array: np.ndarray) -> np.ndarray:
        return np.broadcast_to(array, (*batch, *array.shape[-3:]))

    return FilterResult(
        estimates=estimates,
        gains=full(gains),
        covariances=full(sequence.covariances),
        estimate_covariances=full(sequence.estimate_covariances),
        innovation_covariances=full(innovation_covariances),
    )


def _largest(named: dict[str, np.ndarray]) -> str:
    """``"A 1e+200, Q 0.0023, …"``: the largest magnitude of each named array."""
    return ", ".join(f"{name} {float(np.max(np.abs(value))):.3g}"
                     for name, value in named.items())


def _refuse_overflow(what: str, stack: np.ndarray, **named: np.ndarray) -> None:
    """A ``ValueError`` naming the inputs if ``stack`` (..., n, a, b) holds inf or NaN."""
    bad = ~np.isfinite(stack)
    if np.any(bad):
        step = int(np.argmax(np.any(bad, axis=(-2, -1)).reshape(-1, stack.shape[-3])
                             .any(axis=0)))
        raise ValueError(
            f"{what} overflowed the float64 range (reached inf or NaN) at step {step}: "
            f"{', '.join(named)} are too large (or R too small) together; their largest "
            f"magnitudes are {_largest(named)}")


def _innovation_covariances(covariances: np.ndarray, C: np.ndarray, R: np.ndarray,
                            P0: np.ndarray) -> np.ndarray:
    """``S_j = C P_j Cᵀ + R`` for every step, from the priors ``P0, P_1, …, P_{n−1}``.

    ``covariances`` (..., n, k, k) holds the prior of the *next* step, so the prior of
    step j is ``covariances[j − 1]`` and P0 for j = 0. One batched product over the
    covariance batch (not over Monte Carlo runs): microseconds next to the filter.
    """
    batch, k = covariances.shape[:-3], covariances.shape[-1]
    priors = np.concatenate(
        [np.broadcast_to(P0, (*batch, k, k))[..., None, :, :], covariances[..., :-1, :, :]],
        axis=-3)
    m = C.shape[0]
    # Two flat 2-D products (matmul's broadcasting machinery dominates for 3 × 3 blocks):
    # X = P Cᵀ for every prior, then C P Cᵀ = (P Cᵀ)ᵀ Cᵀ since each P is symmetric.
    X = (priors.reshape(-1, k) @ C.T).reshape(*priors.shape[:-1], m)
    S = (X.mT.reshape(-1, k) @ C.T).reshape(*priors.shape[:-2], m, m) + R[..., None, :, :]
    return 0.5 * (S + S.mT)


def _estimates_shared_gains(inputs: list[tuple[np.ndarray, np.ndarray]], z0: np.ndarray,
                            transitions_T: np.ndarray, batch: tuple[int, ...]) -> np.ndarray:
    """Estimates when every run shares one gain sequence (``transitions_T`` is (n, k, k)).

    ``inputs`` pairs each signal (..., n, d) with its per-step matrices (n, k, d).
    Runs are flattened to one axis and time is put first, so each step is a single
    contiguous ``(runs, k) @ (k, k)`` product.
    """
    n_steps, k = transitions_T.shape[:2]
    runs = int(np.prod(batch))
    terms = []
    for signal, matrices in inputs:
        flat = np.broadcast_to(signal, (*batch, *signal.shape[-2:])).reshape(
            runs, n_steps, signal.shape[-1])
        terms.append(np.moveaxis(flat, 1, 0) @ matrices.mT)  # (n, runs, k)
    driven = sum(terms[1:], start=terms[0])
    z = np.broadcast_to(z0, (*batch, k)).reshape(runs, k)
    estimates = np.empty((n_steps, runs, k))
    for j in range(n_steps):
        z = np.dot(z, transitions_T[j]) + driven[j]
        estimates[j] = z
    return np.ascontiguousarray(np.moveaxis(estimates, 0, 1)).reshape(*batch, n_steps, k)


def _estimates_swept_gains(inputs: list[tuple[np.ndarray, np.ndarray]], z0: np.ndarray,
                           transitions_T: np.ndarray, batch: tuple[int, ...]) -> np.ndarray:
    """Estimates when the gains vary along batch axes (a sweep over R or P0)."""
    n_steps, k = transitions_T.shape[-3], transitions_T.shape[-2]
    driven = sum((matrices @ signal[..., None])[..., 0] for signal, matrices in inputs)
    z = np.broadcast_to(z0, (*batch, k))[..., None, :]
    estimates = np.empty((*batch, n_steps, k))
    for j in range(n_steps):
        z = z @ transitions_T[..., j, :, :] + driven[..., j, None, :]
        estimates[..., j, :] = z[..., 0, :]
    return estimates
