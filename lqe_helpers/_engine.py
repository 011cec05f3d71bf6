"""The engine's unchecked core: Tutorial eqs. (3) and (5) on inputs already checked.

Internal to lqe_helpers, as :mod:`lqe_helpers._matrices` is for the model's matrices.
The public entries (:func:`lqe_helpers.filter.kalman_filter`,
:func:`lqe_helpers.simulation.measure`) check their inputs and call :func:`filter_run`
and :func:`readings`; so do the experiments' runs (``experiments.track``,
``bias_model.unbiased_run``) after checking their own inputs and building the model
themselves, so that a value (σ_v from a slider, say) is checked once on its way to the
filter, at the public entry it came through, and R is not factorised twice. Nothing
here checks its inputs' kinds, shapes or ranges; what it still refuses is what no entry
can foresee: a run too large for memory, and values that overflow float64.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import validation


@dataclass(frozen=True)
class FilterResult:
    """Output of :func:`~lqe_helpers.filter.kalman_filter` for ``n`` readings of ``k`` states.

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

    Inputs are assumed already validated (:func:`~lqe_helpers.filter.kalman_filter`);
    R (..., m, m) and P0 (..., k, k) may carry batch axes that broadcast together.
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



def readings(positions: np.ndarray, noise: np.ndarray, sigmas: np.ndarray) -> np.ndarray:
    """``y = p + σ · noise`` (Tutorial eq. (3)), shape (..., n, m), of inputs already checked.

    ``positions`` (n,) cm, ``noise`` (..., n, m), ``sigmas`` (..., m) cm, finite and > 0
    (:func:`lqe_helpers.simulation.measure` states and checks them).

    Raises
    ------
    ValueError
        If the readings would not fit in memory or overflow float64.
    """
    shape = np.broadcast_shapes(positions[..., :, None].shape, sigmas[..., None, :].shape,
                                noise.shape)
    validation.check_memory(
        f"positions of shape {positions.shape}, noise of shape {noise.shape} and sigmas of "
        f"shape {sigmas.shape}", 2 * validation.elements(shape), what="for the readings")
    with np.errstate(over="ignore", invalid="ignore"):
        values = positions[..., :, None] + sigmas[..., None, :] * noise
    if not np.all(np.isfinite(values)):
        raise ValueError(
            f"the readings overflowed the float64 range: positions, sigmas and noise are too "
            f"large together (largest magnitudes {np.max(np.abs(positions)):.3g} cm, "
            f"{np.max(sigmas):.3g} cm and {np.max(np.abs(noise)):.3g})")
    return values


def filter_run(y: np.ndarray, A: np.ndarray, C: np.ndarray, Q: np.ndarray, R: np.ndarray,
               z0: np.ndarray, P0: np.ndarray, B: np.ndarray | None = None,
               u: np.ndarray | None = None) -> FilterResult:
    """Tutorial eq. (5) on inputs already checked: the core of ``kalman_filter``.

    Float arrays of the shapes :func:`lqe_helpers.filter.kalman_filter` states (it checks
    them): y (..., n, m), A (k, k), C (m, k), Q (k, k), R (..., m, m) positive definite,
    z0 (..., k), P0 (..., k, k), B (k, p) and u (..., n, p) together or neither; batch
    axes broadcast together.

    Raises
    ------
    ValueError
        If the run would not fit in memory, or a covariance, gain or estimate overflows
        float64 (the message names the inputs' largest magnitudes).
    """
    n_steps, m = y.shape[-2:]
    k = A.shape[0]
    input_batch = () if u is None else u.shape[:-2]
    batch = np.broadcast_shapes(y.shape[:-2], R.shape[:-2], z0.shape[:-1], P0.shape[:-2],
                                input_batch)
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


def riccati(A: np.ndarray, C: np.ndarray, Q: np.ndarray, R: np.ndarray,
            max_doublings: int = 200, rtol: float = 1e-13
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The core of :func:`lqe_helpers.steady_state.steady_state` on inputs it has checked.

    A (k, k), C (m, k), Q (k, k), R (..., m, m) positive definite, (A, C) detectable.
    Returns P∞ (..., k, k), K∞ (..., k, m) and (I − K∞ C) P∞ (..., k, k), the fields of
    :class:`~lqe_helpers.steady_state.SteadyState` in order.

    Raises
    ------
    ValueError
        If the batch would not fit in memory, the readings carry no information at this
        scale, P overflows, or ``max_doublings`` steps end before ``rtol`` is reached.
    """
    k, m = A.shape[0], C.shape[0]
    batch = R.shape[:-2]
    validation.check_memory(f"R of shape {R.shape}",
                            16 * validation.elements(batch) * max(k, m) ** 2,
                            what="for the Riccati doubling")
    identity = np.eye(k)
    A_i = np.broadcast_to(A.T, (*batch, k, k))
    G_i = C.T @ np.linalg.solve(R, np.broadcast_to(C, (*batch, m, k)))
    if np.any(C) and np.any(np.all(G_i == 0, axis=(-2, -1))):
        raise ValueError(
            f"C and R must leave the readings some information, got Cᵀ R⁻¹ C = 0 in float64 "
            f"(C's largest magnitude {np.max(np.abs(C)):.3g}, R's {np.max(np.abs(R)):.3g}): "
            f"the sensors are worthless at this scale")
    H_i = np.broadcast_to(Q, (*batch, k, k))
    change = np.inf
    for doubling in range(1, max_doublings + 1):
        # Without a fixed point H grows without bound: overflow is detected just below.
        with np.errstate(over="ignore", invalid="ignore"):
            W = np.linalg.inv(identity + G_i @ H_i)
            A_next = A_i @ W @ A_i
            G_next = G_i + A_i @ W @ G_i @ A_i.mT
            H_next = H_i + A_i.mT @ H_i @ W @ A_i
            H_next = 0.5 * (H_next + H_next.mT)
        if not np.all(np.isfinite(H_next)):
            raise ValueError(
                # Not expected once (A, C) is detectable; kept so that a numerical
                # breakdown is reported, never returned as a steady state.
                f"the Riccati recursion has no finite fixed point for these A, C, Q and R "
                f"(P overflowed at doubling step {doubling}; largest magnitudes: A "
                f"{np.max(np.abs(A)):.3g}, C {np.max(np.abs(C)):.3g}, Q {np.max(np.abs(Q)):.3g}, "
                f"R {np.max(np.abs(R)):.3g}): their sizes leave the float64 range, or C does "
                f"not observe, or Q does not drive, every mode of A that does not decay"
            )
        change = np.max(np.abs(H_next - H_i)) / max(np.max(np.abs(H_next)), 1e-300)
        A_i, G_i, H_i = A_next, 0.5 * (G_next + G_next.mT), H_next
        if change <= rtol:
            P = H_i
            S = C @ P @ C.T + R
            gain = np.linalg.solve(S, C @ P).mT
            estimate = P - gain @ C @ P
            return P, gain, 0.5 * (estimate + estimate.mT)
    raise ValueError(
        f"max_doublings = {max_doublings} was too few to reach rtol = {rtol:g}: the last "
        f"relative change of P was {change:.3g}; allow more doubling steps (the default "
        f"is 200) or a larger rtol"
    )
