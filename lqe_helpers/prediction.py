"""Prediction without measurements: delay compensation (Tutorial eq. (7)) and open loop."""

from __future__ import annotations

import dataclasses

import numpy as np

from . import validation
from .scenario import Scenario


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
    validation.check_memory(f"estimates of shape {estimates.shape}", 2 * estimates.size,
                            what="for the predictions")
    with np.errstate(over="ignore", invalid="ignore"):
        ahead = np.linalg.matrix_power(A, steps)
        out = np.full(estimates.shape, np.nan)
        out[..., steps:, :] = estimates[..., : n_steps - steps, :] @ ahead.T
    if not np.all(np.isfinite(out[..., steps:, :])):
        raise ValueError(
            f"the predictions overflowed the float64 range (reached inf or NaN): A^steps with "
            f"steps = {steps} and the estimates are too large together (largest magnitudes: "
            f"A {np.max(np.abs(A)):.3g}, A^steps {np.max(np.abs(ahead)):.3g}, estimates "
            f"{np.max(np.abs(estimates)):.3g})")
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
    return _propagate(validation.covariance("P0", P0), A, Q, steps, "steps")


def _propagate(P: np.ndarray, A: np.ndarray, Q: np.ndarray, steps: int,
               steps_name: str) -> np.ndarray:
    """:func:`propagate_covariance` of a validated ``P``; ``steps_name`` is blamed for size."""
    A = validation.square_matrix("A", A)
    if A.ndim != 2:
        raise ValueError(f"A must have shape (k, k), got shape {A.shape}")
    k = A.shape[0]
    if P.shape[-2:] != (k, k):
        raise ValueError(f"P0 must have trailing shape ({k}, {k}) like A, got shape {P.shape}")
    Q = validation.covariance("Q", Q, size=k)
    if Q.ndim != 2:
        raise ValueError(f"Q must have shape ({k}, {k}), got shape {Q.shape}")
    steps = validation.count("steps", steps, minimum=0)
    validation.check_memory(f"{steps_name} ({steps} steps) with a start of shape {P.shape}",
                            (steps + 2) * P.size, what="for the covariances")
    out = np.empty((*P.shape[:-2], steps + 1, k, k))
    out[..., 0, :, :] = P
    with np.errstate(over="ignore", invalid="ignore"):
        for step in range(1, steps + 1):
            P = A @ P @ A.T + Q
            P = 0.5 * (P + P.mT)
            out[..., step, :, :] = P
    if not np.all(np.isfinite(P)):  # inf or NaN never turns finite again here
        raise ValueError(
            f"the covariance overflowed the float64 range (reached inf or NaN) within "
            f"{steps} steps: A, Q and the start are too large together (largest magnitudes: "
            f"A {np.max(np.abs(A)):.3g}, Q {np.max(np.abs(Q)):.3g}, start "
            f"{np.max(np.abs(out[..., 0, :, :])):.3g})")
    return out


@dataclasses.dataclass(frozen=True)
class OpenLoop:
    """Prediction with no measurements from a known estimate and covariance.

    Attributes
    ----------
    times : ndarray, shape (steps + 1,)
        Time since the last measurement (s).
    means : ndarray, shape (steps + 1, 3)
        ``A^k ẑ``: where the observer expects the butterfly (cm, cm/s, cm/s²).
    covariances : ndarray, shape (..., steps + 1, 3, 3)
        ``P(k)`` from ``P(k+1) = A P(k) Aᵀ + Q`` (Lesson 0.5 eq. (9)); leading axes
        are those of the starting covariance given to :func:`open_loop`.
    """

    times: np.ndarray
    means: np.ndarray
    covariances: np.ndarray

    @property
    def position_stds(self) -> np.ndarray:
        """Standard deviation of the predicted position (cm), shape (..., steps + 1)."""
        return np.sqrt(self.covariances[..., 0, 0])


def open_loop(scenario: Scenario, estimate: np.ndarray, covariance: np.ndarray,
              duration: float) -> OpenLoop:
    """Predict ``duration`` s ahead with no measurements (Tutorial eq. (1) without noise).

    The mean follows the model, ``ẑ(k+1) = A ẑ(k)``; the covariance grows as
    ``P(k+1) = A P(k) Aᵀ + Q`` (Lesson 0.5 eq. (9)), with the scenario's A and Q.

    Parameters
    ----------
    scenario : Scenario
        Supplies Δt, A and Q (through its σ_j).
    estimate : array_like, shape (3,)
        Estimate ``[p, v, a]`` when the measurements stop.
    covariance : array_like, shape (..., 3, 3)
        Its covariance, e.g. the filter's ``estimate_covariances`` at that time, or
        zeros for a perfectly known start; leading axes give a batch of predictions
        (e.g. one per σ of a sweep) sharing the same mean.
    duration : float
        Prediction horizon in s, > 0 and a whole number of the scenario's time steps.
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    estimate = validation.finite_array("estimate", estimate, min_ndim=1)
    if estimate.shape != (3,):
        raise ValueError(f"estimate must have shape (3,), got shape {estimate.shape}")
    covariance = validation.covariance("covariance", covariance, size=3)
    validation.positive("duration", duration, "s")
    # The value as given, so that a float32 duration is judged at float32 precision.
    steps = validation.whole_steps("duration", duration, scenario.dt)
    duration_text = f"duration = {duration} s"
    batch_text = (f" with covariance of shape {covariance.shape}" if covariance.ndim > 2
                  else "")
    validation.check_memory(f"{duration_text} ({steps} steps of {scenario.dt} s){batch_text}",
                            (steps + 2) * (covariance.size + 4), what="for the prediction")
    covariances = _propagate(covariance, scenario.A, scenario.Q, steps, duration_text)
    # (..., steps + 1, 3, 3) for a (..., 3, 3) start: P(0) … P(steps) along axis -3.
    means = np.empty((steps + 1, 3))
    means[0] = estimate
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(steps):
            means[k + 1] = scenario.A @ means[k]
    if not np.all(np.isfinite(means[-1])):
        raise ValueError(
            f"the predicted mean overflowed the float64 range within {duration_text}: "
            f"estimate's largest magnitude is {np.max(np.abs(estimate)):.3g}")
    return OpenLoop(np.arange(steps + 1) * scenario.dt, means, covariances)


def amplitude_crossing(loop: OpenLoop, amplitude: float) -> float | None:
    """First time (s) at which 2σ of the predicted position reaches ``amplitude`` (cm).

    Parameters
    ----------
    loop : OpenLoop
        A prediction from :func:`open_loop` started from one covariance (3, 3).
    amplitude : float
        Threshold in cm, > 0 (e.g. the path's amplitude A).

    Returns
    -------
    float or None
        The time in s since the last measurement, or None if 2σ stays below
        ``amplitude`` within the prediction's horizon.
    """
    if not isinstance(loop, OpenLoop):
        raise ValueError(f"loop must be an OpenLoop from open_loop(), got {type(loop).__name__}")
    if loop.covariances.ndim != 3:
        raise ValueError(
            f"loop must hold one prediction (covariances of shape (steps + 1, 3, 3)), got "
            f"a batch with covariances of shape {loop.covariances.shape}; call open_loop "
            f"with one covariance (3, 3) per crossing time wanted"
        )
    amplitude = validation.positive("amplitude", amplitude, "cm")
    above = 2 * loop.position_stds >= amplitude
    return float(loop.times[np.argmax(above)]) if above.any() else None
