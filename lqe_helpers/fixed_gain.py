"""A filter with the LQE's model of motion but one fixed gain, and a tuner for that gain.

Once settled, eq. (5) applies the same gain ``K∞`` at every step: it is a fixed linear
filter. :func:`fixed_gain_filter` runs that recursion with any constant gain, and
:func:`tune_fixed_gain` finds the gain with the smallest Monte Carlo MSE against the true
path, which no observer has: the comparison says what the LQE's statistics buy (the right
gains without the truth, and the start-up) beside what a gain tuned on the truth can do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import metrics, validation


def fixed_gain_filter(y: np.ndarray, A: np.ndarray, C: np.ndarray, K: np.ndarray,
                      z0: np.ndarray) -> np.ndarray:
    """Estimates of the recursion of Tutorial eq. (5) with a constant gain.

    From ``ẑ = z0``, for each reading ``y_j`` (j = 0 … n−1)::

        ẑ ← A ẑ + K (y_j − C A ẑ)

    With ``K = K∞`` (:func:`~lqe_helpers.steady_state.steady_state`) this is the settled
    LQE; :func:`~lqe_helpers.filter.kalman_filter` gives the same estimates when its
    ``P0`` is the steady prediction covariance ``P∞``.

    Parameters
    ----------
    y : array_like, shape (..., n, m)
        Readings (cm), n >= 1 steps of m sensors; leading axes are runs.
    A : array_like, shape (k, k)
        Transition matrix (Tutorial eq. (1)).
    C : array_like, shape (m, k)
        Observation matrix (Tutorial eq. (2)).
    K : array_like, shape (..., k, m)
        The fixed gain; leading axes broadcast against y's (a grid of gains).
    z0 : array_like, shape (k,)
        Initial estimate.

    Returns
    -------
    ndarray, shape (broadcast of y.shape[:-2] and K.shape[:-2]) + (n, k)
        The estimates (position in cm, velocity in cm/s, acceleration in cm/s²).
    """
    y = validation.finite_array("y", y, min_ndim=2)
    n_steps, m = y.shape[-2:]
    A = validation.square_matrix("A", A)
    if A.ndim != 2:
        raise ValueError(f"A must have shape (k, k), got shape {A.shape}")
    k = A.shape[0]
    C = validation.finite_array("C", C)
    if C.shape != (m, k):
        raise ValueError(f"C must have shape (m, k) = ({m}, {k}) to match y's {m} sensor(s) "
                         f"and A's {k} states, got shape {C.shape}")
    K = validation.finite_array("K", K, min_ndim=2)
    if K.shape[-2:] != (k, m):
        raise ValueError(f"K must have shape (..., k, m) = (..., {k}, {m}), got shape {K.shape}")
    z0 = validation.finite_array("z0", z0, min_ndim=1)
    if z0.shape != (k,):
        raise ValueError(f"z0 must have shape ({k},), got shape {z0.shape}")
    batch = validation.broadcast_batches(y=y.shape[:-2], K=K.shape[:-2])
    validation.check_memory(f"y of shape {y.shape} and K of shape {K.shape}",
                            2 * validation.elements((*batch, n_steps, k)),
                            what="for the estimates")
    transition_T = np.broadcast_to((A - K @ C @ A).mT, (*batch, k, k))
    # Time first, so that each step reads and writes one contiguous (..., k) block.
    driven = np.moveaxis(np.einsum("...km,...nm->...nk", K, y), -2, 0)     # (n, ..., k)
    driven = np.ascontiguousarray(np.broadcast_to(driven, (n_steps, *batch, k)))
    z = np.broadcast_to(z0, (*batch, 1, k))
    estimates = np.empty((n_steps, *batch, k))
    for j in range(n_steps):
        z = z @ transition_T + driven[j, ..., None, :]
        estimates[j] = z[..., 0, :]
    estimates = np.moveaxis(estimates, 0, -2)
    return estimates


@dataclass(frozen=True)
class TunedGain:
    """The fixed gain with the smallest mean MSE on given runs, and that MSE.

    Attributes
    ----------
    gain : ndarray, shape (k, m)
        The tuned gain.
    mse : ndarray, shape (runs,)
        Each run's position MSE (cm²) with the tuned gain, after the burn-in.
    start_mse : ndarray, shape (runs,)
        The same with the starting gain.
    evaluations : int
        Gains tried.
    """

    gain: np.ndarray
    mse: np.ndarray
    start_mse: np.ndarray
    evaluations: int


def _position_mse(y: np.ndarray, A: np.ndarray, C: np.ndarray, gains: np.ndarray,
                  z0: np.ndarray, truth: np.ndarray, burn_in_steps: int) -> np.ndarray:
    """Per-run position MSE (cm²) of every gain of ``gains`` (g, k, m): shape (g, runs)."""
    estimates = fixed_gain_filter(y, A, C, gains[:, None], z0)     # (g, runs, n, k)
    return metrics.mse(estimates[..., 0], truth, burn_in_steps)


def tune_fixed_gain(y: np.ndarray, A: np.ndarray, C: np.ndarray, z0: np.ndarray,
                    truth: np.ndarray, start: np.ndarray, burn_in_steps: int = 0,
                    iterations: int = 40, rtol: float = 1e-7) -> TunedGain:
    """The fixed gain whose :func:`fixed_gain_filter` has the smallest mean position MSE.

    Minimises the mean over runs of the position MSE against ``truth`` (which needs the
    true path) by Levenberg–Marquardt steps on the gain's entries relative to ``start``
    (derivatives by finite differences, each step's trial gains in one batched call). A
    step is kept only if it lowers the mean MSE, so the result is never worse than
    ``start`` on these runs.

    Parameters
    ----------
    y : array_like, shape (runs, n, m)
        Readings (cm) of the runs the gain is tuned on.
    A, C : array_like
        The model of motion and the observation matrix, as for :func:`fixed_gain_filter`.
    z0 : array_like, shape (k,)
        Initial estimate.
    truth : array_like, shape (n,)
        True positions (cm).
    start : array_like, shape (k, m)
        The starting gain, e.g. the LQE's ``K∞``; every entry non-zero (it sets the scale
        of each entry's steps).
    burn_in_steps : int
        Samples left out of every MSE, as in :func:`~lqe_helpers.metrics.mse`.
    iterations : int
        Most Levenberg–Marquardt steps tried, >= 1.
    rtol : float
        Stop once a kept step lowers the mean MSE by less than this fraction, > 0.

    Returns
    -------
    TunedGain
    """
    y = validation.finite_array("y", y, min_ndim=3)
    if y.ndim != 3 or y.shape[0] < 1:
        raise ValueError(f"y must have shape (runs, n, m), got shape {y.shape}")
    start = validation.finite_array("start", start, min_ndim=2)
    if start.ndim != 2 or np.any(start == 0):
        raise ValueError(f"start must be a (k, m) gain with every entry non-zero, got "
                         f"{np.round(start, 6).tolist()}")
    truth = validation.finite_array("truth", truth, min_ndim=1)
    iterations = validation.count("iterations", iterations, minimum=1)
    rtol = validation.positive("rtol", rtol)
    scale = start.ravel()
    size = scale.size
    h = 1e-6

    def gains_of(x: np.ndarray) -> np.ndarray:
        return (x * scale).reshape(x.shape[:-1] + start.shape)

    def residuals(x: np.ndarray) -> np.ndarray:
        """Position errors after the burn-in of each gain of x (g, size): (g, runs·n')."""
        estimates = fixed_gain_filter(y, A, C, gains_of(x)[:, None], z0)[..., 0]
        return (estimates[..., burn_in_steps:] - truth[burn_in_steps:]).reshape(len(x), -1)

    x = np.ones(size)
    cost = np.mean(residuals(x[None])[0] ** 2)
    damping, evaluations = 1e-3, 1
    for _ in range(iterations):
        trial = np.vstack([x, x + h * np.eye(size)])
        errors = residuals(trial)
        evaluations += size
        jacobian = (errors[1:] - errors[0]).T / h                    # (samples, size)
        normal = jacobian.T @ jacobian
        gradient = jacobian.T @ errors[0]
        improved, gain_in_cost = False, 0.0
        for _ in range(10):
            step = np.linalg.solve(normal + damping * np.diag(np.diag(normal)), -gradient)
            new_error = residuals((x + step)[None])[0]
            evaluations += 1
            new_cost = np.mean(new_error**2)
            if new_cost < cost:
                improved, damping = True, max(damping / 3, 1e-9)
                gain_in_cost = (cost - new_cost) / cost
                x, cost = x + step, new_cost
                break
            damping *= 4
        if not improved or gain_in_cost < rtol:
            break
    runs_mse = _position_mse(y, A, C, gains_of(np.stack([np.ones(size), x])), z0, truth,
                             burn_in_steps)
    return TunedGain(gains_of(x), runs_mse[1], runs_mse[0], evaluations)
