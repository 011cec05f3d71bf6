"""The biased-input model's equations: its matrices, the hand, the signal, dead reckoning.

Part of :mod:`lqe_helpers.bias_model` (notebook 06, Lesson 0.5), whose docstring gives
the state ``[p, v, b]`` and the time convention; the filter that uses these equations
and its runs are in :mod:`lqe_helpers.bias_model.tracking`.
"""

from __future__ import annotations

import numpy as np

from .. import _matrices, model, simulation, validation
from ..prediction import propagate_covariance
from ..scenario import Scenario

#: Column order of :func:`unit_noise`: vision's noise, then the acceleration signal's.
NOISE_COLUMNS = ("vision", "acceleration")

#: True bias b of the acceleration signal (cm/s²): a fifth of the hand's peak
#: acceleration A(2πf)² ≈ 99 cm/s², enough to wreck dead reckoning within a second.
DEFAULT_BIAS = 20.0
#: Noise σ_a of each acceleration reading (cm/s²), also a fifth of the peak acceleration.
DEFAULT_SIGMA_A = 20.0


def transition_matrix(dt: float) -> np.ndarray:
    """Transition matrix F of the biased-input model (Lesson 0.5 eq. (5)).

    Parameters
    ----------
    dt : float
        Time step Δt in s, > 0.

    Returns
    -------
    ndarray, shape (3, 3)
        ``[[1, Δt, −Δt²/2], [0, 1, −Δt], [0, 0, 1]]``: the bias estimate is removed
        from the input before it is integrated (Lesson 0.5 eq. (2)), and the bias
        itself is taken as constant.
    """
    dt = validation.positive("dt", dt, "s")
    return np.array([[1.0, dt, -dt * dt / 2.0], [0.0, 1.0, -dt], [0.0, 0.0, 1.0]])


def input_matrix(dt: float) -> np.ndarray:
    """Input matrix G of an acceleration held over one step (Lesson 0.5 eq. (5)).

    Parameters
    ----------
    dt : float
        Time step Δt in s, > 0.

    Returns
    -------
    ndarray, shape (3, 1)
        ``[[Δt²/2], [Δt], [0]]`` in s², s, s: what one step of a constant acceleration
        adds to position and velocity; the bias does not respond to the input.
    """
    dt = validation.positive("dt", dt, "s")
    return np.array([[dt * dt / 2.0], [dt], [0.0]])


def process_noise_covariance(dt: float, sigma_a: float) -> np.ndarray:
    """Covariance ``Q = G σ_a² Gᵀ`` that the input's noise adds each step (Lesson 0.5 eq. (9)).

    The acceleration signal's noise, independent of the state, passes through the
    same G as the signal, so its variance reaches position and velocity as
    ``G σ_a² Gᵀ``. The model adds nothing of its own: with the step-mean acceleration
    as input, the position update is exact up to a term of order Δt³ · jerk (about
    3e-5 cm per step here), far below what σ_a contributes.

    Parameters
    ----------
    dt : float
        Time step Δt in s, > 0.
    sigma_a : float
        Standard deviation σ_a of the signal's noise in cm/s², > 0.

    Returns
    -------
    ndarray, shape (3, 3)
        Q in cm², cm²/s, cm²/s² (zero in the bias row and column).
    """
    sigma_a = validation.positive("sigma_a", sigma_a, "cm/s²")
    return _matrices.input_noise_covariance(input_matrix(dt), sigma_a)


def step_accelerations(scenario: Scenario) -> np.ndarray:
    """True mean acceleration over the step that ends at each sample (cm/s²), shape (n,).

    ``(v(t_j) − v(t_j − Δt)) / Δt`` from the scenario's exact sinusoid: what an
    integrating acceleration sensor reports for that step. With it the noise-free,
    unbiased model of :func:`transition_matrix` and :func:`input_matrix` reproduces
    the true velocity to rounding and the position to within 0.001 cm over a trial.
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    times = scenario.times
    now = simulation.sinusoid_states(times, scenario.amplitude, scenario.frequency)
    before = simulation.sinusoid_states(times - scenario.dt, scenario.amplitude,
                                        scenario.frequency)
    return (now[:, 1] - before[:, 1]) / scenario.dt


def true_states(scenario: Scenario, bias: float) -> np.ndarray:
    """True states ``[p, v, b]`` at the sample times, shape (n, 3), units cm, cm/s, cm/s².

    Parameters
    ----------
    scenario : Scenario
        Supplies the path (the hand's sinusoid) and the sample times.
    bias : float
        The constant true bias b of the acceleration signal in cm/s² (any sign).
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    bias = validation.finite_number("bias", bias, "cm/s²")
    states = scenario.truth[:, :3].copy()
    states[:, 2] = bias
    return states


def initial_state(scenario: Scenario, bias: float) -> np.ndarray:
    """True state ``[p, v, b]`` at ``t = −Δt``, the time ``z0`` refers to, shape (3,)."""
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    bias = validation.finite_number("bias", bias, "cm/s²")
    p, v, _ = simulation.sinusoid_states(np.array([-scenario.dt]), scenario.amplitude,
                                         scenario.frequency)[0]
    return np.array([p, v, bias])


def acceleration_readings(accelerations: np.ndarray, bias: float | np.ndarray,
                          sigma_a: float | np.ndarray, noise: np.ndarray) -> np.ndarray:
    """Biased, noisy acceleration signal ``a_r = a + b + σ_a · noise`` (Lesson 0.5 eq. (2)).

    Parameters
    ----------
    accelerations : array_like, shape (n,)
        True acceleration over each step (cm/s²), e.g. :func:`step_accelerations`.
    bias : float or array_like, shape (...)
        Constant bias b in cm/s² (any sign); leading axes broadcast against noise's.
    sigma_a : float or array_like, shape (...)
        Noise standard deviation σ_a in cm/s², >= 0; broadcasts like ``bias``.
    noise : array_like, shape (..., n)
        Standard normal noise, e.g. column 1 of :func:`unit_noise`.

    Returns
    -------
    ndarray, shape (..., n)
        Readings in cm/s²; the batch axes of bias, sigma_a and noise broadcast together.
    """
    accelerations = validation.finite_array("accelerations", accelerations, min_ndim=1)
    if accelerations.ndim != 1:
        raise ValueError(
            f"accelerations must have shape (n,), got shape {accelerations.shape}"
        )
    bias = validation.finite_array("bias", bias)
    sigma_a = validation.finite_array("sigma_a", sigma_a)
    if np.any(sigma_a < 0):
        raise ValueError(
            f"sigma_a must be >= 0 cm/s², got {np.ravel(sigma_a)[:6].tolist()}"
        )
    noise = validation.finite_array("noise", noise, min_ndim=1)
    if noise.shape[-1] != accelerations.shape[0]:
        raise ValueError(
            f"noise must have trailing length n = {accelerations.shape[0]} like "
            f"accelerations, got shape {noise.shape}"
        )
    validation.broadcast_batches(bias=bias.shape, sigma_a=sigma_a.shape,
                                 noise=noise.shape[:-1])
    return accelerations + bias[..., None] + sigma_a[..., None] * noise


def dead_reckoning(readings: np.ndarray, start: np.ndarray, dt: float,
                   bias_estimate: float = 0.0) -> np.ndarray:
    """Integrate the acceleration signal with no correction (Lesson 0.5 eqs. (2) and (4)).

    From ``start`` at ``t = −Δt``, each reading ``u_j`` advances the state by
    ``z_j = F z_{j−1} + G u_j`` with F and G of Lesson 0.5 eq. (5) and the bias
    estimate held at ``bias_estimate``. This is how an observer with its eyes closed
    would track the hand: any error in the bias grows into a position error of
    ``b t² / 2``.

    Parameters
    ----------
    readings : array_like, shape (..., n)
        Acceleration signal u in cm/s², one reading per step.
    start : array_like, shape (..., 2) or (..., 3)
        Known position (cm) and velocity (cm/s) at ``t = −Δt``; a third entry, if
        given, is ignored in favour of ``bias_estimate``.
    dt : float
        Time step Δt in s, > 0.
    bias_estimate : float
        The constant b̂ (cm/s²) subtracted from every reading; 0 for an observer that
        does not know about the bias.

    Returns
    -------
    ndarray, shape (..., n, 3)
        ``[p, v, b̂]`` after each reading. Computed with running sums (the recursion
        solved for each sample), equal to the step-by-step recursion to rounding.
    """
    readings = validation.finite_array("readings", readings, min_ndim=1)
    start = validation.finite_array("start", start, min_ndim=1)
    if start.shape[-1] not in (2, 3):
        raise ValueError(
            f"start must have trailing length 2 [p, v] or 3 [p, v, b], got shape {start.shape}"
        )
    bias_estimate = validation.finite_number("bias_estimate", bias_estimate, "cm/s²")
    dt = validation.positive("dt", dt, "s")
    batch = validation.broadcast_batches(readings=readings.shape[:-1], start=start.shape[:-1])
    n_steps = readings.shape[-1]
    # The recursion solved with running sums: with w_i = u_i − b̂ and S_j = Σ_{i≤j} w_i,
    # v_j = v_start + Δt S_j and p_j = p_start + (j + 1) Δt v_start
    # + Δt² (Σ_{i<j} S_i + S_j / 2), the rows of F and G written out (p gains Δt v_{j−1}
    # + Δt²/2 w_j per step).
    corrected = np.broadcast_to(readings, (*batch, n_steps)) - bias_estimate
    sums = np.cumsum(corrected, axis=-1)
    earlier = np.zeros_like(sums)
    earlier[..., 1:] = np.cumsum(sums[..., :-1], axis=-1)
    position = np.broadcast_to(start[..., 0], batch)[..., None]
    velocity = np.broadcast_to(start[..., 1], batch)[..., None]
    elapsed = dt * np.arange(1, n_steps + 1)
    out = np.empty((*batch, n_steps, 3))
    out[..., 0] = position + elapsed * velocity + dt * dt * (earlier + sums / 2.0)
    out[..., 1] = velocity + dt * sums
    out[..., 2] = bias_estimate
    return out


def bias_drift(scenario: Scenario, bias: float) -> np.ndarray:
    """Position error (cm) of dead reckoning that ignores a bias b, shape (n,).

    A constant error b in the acceleration, integrated twice from a perfectly known
    start, displaces the position by ``b t² / 2`` (Lesson 0.5 eq. (1) with a = b),
    where t is the time since the start, ``t_j + Δt`` at sample j (the start is
    ``t = −Δt``). The discrete integration of :func:`dead_reckoning` gives exactly
    this value at every sample.
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    bias = validation.finite_number("bias", bias, "cm/s²")
    elapsed = scenario.times + scenario.dt
    return bias * elapsed**2 / 2.0


def dead_reckoning_spread(scenario: Scenario, sigma_a: float) -> np.ndarray:
    """Standard deviation (cm) of dead reckoning's position from the signal's noise, (n,).

    The covariance of Lesson 0.5 eq. (9), ``P(k+1) = F P Fᵀ + G σ_a² Gᵀ``, run from
    ``P = 0`` at the known start: how far the dead-reckoned position wanders even
    when the bias is known exactly. It grows roughly as ``σ_a √(Δt / 3) t^{3/2}``.
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    dt = scenario.dt
    covariances = propagate_covariance(np.zeros((3, 3)), transition_matrix(dt),
                                       process_noise_covariance(dt, sigma_a), scenario.n_steps)
    return np.sqrt(covariances[1:, 0, 0])


def unit_noise(scenario: Scenario, runs: int | None = None) -> np.ndarray:
    """Standard normal noise for vision and the acceleration signal, shape (..., n, 2).

    Column 0 is exactly vision's noise from :meth:`Scenario.unit_noise`, so a
    vision-only filter (``experiments.track``) sees the same camera noise and the
    two can be compared run by run. Column 1 is a third independent stream from the
    same seed, unused by the tutorial's sensors.

    Parameters
    ----------
    scenario : Scenario
        Supplies the seed and the number of samples.
    runs : int, optional
        Monte Carlo runs; None for the single run shown in figures (run 0).

    Returns
    -------
    ndarray, shape (n, 2) or (runs, n, 2)
        Columns in the order of :data:`NOISE_COLUMNS`.
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    streams = len(model.SENSORS) + 1
    rng = np.random.default_rng(scenario.seed)
    noise = simulation.unit_noise(rng, scenario.n_steps, streams, runs=runs)
    return noise[..., [model.SENSORS.index("vision"), streams - 1]]
