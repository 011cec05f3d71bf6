"""Simulated butterflies and sensors: truth, fixed noise draws, measurements, delays."""

from __future__ import annotations

import numpy as np

from . import _engine, validation


def sinusoid_states(times: np.ndarray, amplitude: float, frequency: float) -> np.ndarray:
    """Exact position, velocity and acceleration of ``p(t) = amplitude · sin(2π f t)``.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times in s.
    amplitude : float
        Amplitude in cm, > 0.
    frequency : float
        Frequency f in Hz, > 0.

    Returns
    -------
    ndarray, shape (n, 3)
        Columns p (cm), v (cm/s), a (cm/s²), from the analytic derivatives.
    """
    times = validation.finite_array("times", times, min_ndim=1)
    amplitude = validation.positive("amplitude", amplitude, "cm")
    frequency = validation.positive("frequency", frequency, "Hz")
    validation.check_memory(f"times of shape {times.shape}", 5 * times.size,
                            what="for the states")
    omega = 2.0 * np.pi * frequency
    if not np.isfinite(amplitude * omega**2):
        raise ValueError(
            f"amplitude and frequency give an acceleration amplitude A (2π f)² beyond the "
            f"float64 range, got amplitude = {amplitude:g} cm and frequency = {frequency:g} Hz")
    phase = omega * times
    return np.stack(
        [amplitude * np.sin(phase),
         amplitude * omega * np.cos(phase),
         -amplitude * omega**2 * np.sin(phase)],
        axis=-1,
    )


def unit_noise(rng: np.random.Generator, n_steps: int, n_sensors: int,
               runs: int | None = None) -> np.ndarray:
    """Standard normal noise, one independent stream per sensor, to be scaled by σ.

    Drawing unit noise once and multiplying it by σ later means a σ slider changes
    the noise level only, never the noise pattern. Sensor s always draws from the
    s-th child of ``rng`` (:meth:`numpy.random.Generator.spawn`), so vision's noise is
    the same whether or not proprioception is simulated beside it, and run r's noise
    does not depend on how many runs are drawn.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of randomness, e.g. ``np.random.default_rng(seed)``.
    n_steps : int
        Number of samples n, >= 1.
    n_sensors : int
        Number of sensors m, >= 1.
    runs : int or None
        Number of Monte Carlo runs; ``None`` for a single run without a run axis.

    Returns
    -------
    ndarray, shape (n, m) or (runs, n, m)
    """
    if not isinstance(rng, np.random.Generator):
        raise ValueError(
            f"rng must be a numpy.random.Generator (np.random.default_rng(seed)), got {rng!r}"
        )
    n_steps = validation.count("n_steps", n_steps, minimum=1)
    n_sensors = validation.count("n_sensors", n_sensors, minimum=1)
    shape = (n_steps,) if runs is None else (validation.count("runs", runs, minimum=1), n_steps)
    validation.check_memory(
        ", ".join(f"{name} = {value}" for name, value in
                  (("runs", runs), ("n_steps", n_steps), ("n_sensors", n_sensors))
                  if value is not None),
        2 * validation.elements(shape) * n_sensors, what="for the noise")
    streams = rng.spawn(n_sensors)
    return np.stack([stream.standard_normal(shape) for stream in streams], axis=-1)


def measure(positions: np.ndarray, noise: np.ndarray, sigmas: np.ndarray) -> np.ndarray:
    """Noisy position readings ``y = p + σ · noise`` (Tutorial eq. (3), one column per sensor).

    Parameters
    ----------
    positions : array_like, shape (n,)
        True positions in cm.
    noise : array_like, shape (..., n, m)
        Unit noise from :func:`unit_noise`.
    sigmas : array_like, shape (..., m)
        Sensor noise standard deviations in cm, > 0; leading axes broadcast against
        noise's batch axes (e.g. a sweep of σ_p).

    Returns
    -------
    ndarray, shape (..., n, m)
        Measurements in cm.
    """
    positions = validation.finite_array("positions", positions, min_ndim=1)
    noise = validation.finite_array("noise", noise, min_ndim=2)
    sigmas = validation.finite_array("sigmas", sigmas, min_ndim=1)
    if np.any(sigmas <= 0):
        raise ValueError(f"sigmas must all be > 0 cm, got {np.ravel(sigmas)[:6].tolist()}")
    if positions.shape[-1] != noise.shape[-2] or sigmas.shape[-1] != noise.shape[-1]:
        raise ValueError(
            f"positions (n,), noise (..., n, m) and sigmas (..., m) must agree on n and m, "
            f"got shapes {positions.shape}, {noise.shape} and {sigmas.shape}"
        )
    return _engine.readings(positions, noise, sigmas)


def delay_signal(signal: np.ndarray, steps: int, axis: int = -2) -> np.ndarray:
    """What arrives ``steps`` samples late: ``out[j] = signal[j − steps]``, NaN before.

    Parameters
    ----------
    signal : array_like
        Any numeric array with time along ``axis``: measurements (..., n, m), estimates
        (..., n, k), or a position trace (n,) with ``axis=-1``. NaN is passed through.
    steps : int
        Delay δ in samples, 0 <= δ <= n − 1.
    axis : int
        The time axis.

    Returns
    -------
    ndarray
        Same shape as ``signal``; the first δ samples are NaN (nothing has arrived).
    """
    signal = validation.numeric_array("signal", signal)
    if signal.ndim == 0:
        raise ValueError(f"signal must have a time axis, got a scalar {signal.item()!r}")
    try:
        if isinstance(axis, bool) or not isinstance(axis, (int, np.integer)):
            raise IndexError
        n_steps = signal.shape[axis]
    except IndexError:
        one_trace = (" (a single trace of shape (n,) has only axis -1 = 0: pass axis=-1, or "
                     "delay the (n, m) readings and take a column afterwards)"
                     if signal.ndim == 1 and axis == -2 else "")
        raise ValueError(
            f"axis must name an axis of signal with shape {signal.shape}, got {axis!r}"
            f"{one_trace}"
        ) from None
    steps = validation.count("steps", steps, minimum=0, maximum=n_steps - 1)
    validation.check_memory(f"signal of shape {signal.shape}", 2 * signal.size,
                            what="for the delayed signal")
    moved = np.moveaxis(signal, axis, 0)
    out = np.full(moved.shape, np.nan)
    out[steps:] = moved[: n_steps - steps]
    return np.moveaxis(out, 0, axis)


def simulate_model_states(rng: np.random.Generator, A: np.ndarray, Q: np.ndarray,
                          mean0: np.ndarray, P0: np.ndarray, n_steps: int,
                          runs: int) -> np.ndarray:
    """Truth drawn from the filter's own model (Tutorial eq. (1)), for consistency checks.

    ``z_0 ~ N(A·mean0, P0)`` and ``z_j = A z_{j−1} + ω``, ``ω ~ N(0, Q)``: exactly the
    statistics Tutorial eq. (5) assumes when it starts from ``ẑ = mean0, P = P0``.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of randomness, e.g. ``np.random.default_rng(seed)``.
    A : array_like, shape (k, k)
        Transition matrix.
    Q : array_like, shape (k, k)
        Process noise covariance, symmetric positive semidefinite.
    mean0 : array_like, shape (k,)
        Mean of the state one step before sample 0.
    P0 : array_like, shape (k, k)
        Covariance of the state at sample 0, symmetric positive semidefinite.
    n_steps : int
        Number of samples n, >= 1.
    runs : int
        Number of independent runs, >= 1.

    Returns
    -------
    ndarray, shape (runs, n, k)
    """
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {rng!r}")
    A = validation.square_matrix("A", A)
    if A.ndim != 2:
        raise ValueError(f"A must have shape (k, k), got shape {A.shape}")
    k = A.shape[-1]
    Q = validation.covariance("Q", Q, size=k)
    if Q.ndim != 2:
        raise ValueError(f"Q must have shape ({k}, {k}), got shape {Q.shape}")
    P0 = validation.covariance("P0", P0, size=k)
    if P0.ndim != 2:
        raise ValueError(f"P0 must have shape ({k}, {k}), got shape {P0.shape}")
    mean0 = validation.finite_array("mean0", mean0, min_ndim=1)
    if mean0.shape != (k,):
        raise ValueError(f"mean0 must have shape ({k},) like A, got shape {mean0.shape}")
    n_steps = validation.count("n_steps", n_steps, minimum=1)
    runs = validation.count("runs", runs, minimum=1)
    validation.check_memory(f"runs = {runs} and n_steps = {n_steps}",
                            3 * runs * n_steps * k, what="for the states")
    with np.errstate(over="ignore", invalid="ignore"):
        # P0 and Q passed validation.covariance's scale-free check; numpy's own check uses
        # an absolute tolerance that cries wolf for Q ~ 1e200 cm², so it is switched off.
        first = rng.multivariate_normal(A @ mean0, P0, size=runs, method="eigh",
                                        check_valid="ignore")
        # One kick per transition: n − 1 of them, into samples 1 … n − 1.
        kicks = rng.multivariate_normal(np.zeros(k), Q, size=(runs, n_steps - 1), method="eigh",
                                        check_valid="ignore")
        states = np.empty((runs, n_steps, k))
        states[:, 0] = first
        for j in range(1, n_steps):
            states[:, j] = states[:, j - 1] @ A.T + kicks[:, j - 1]
    if not np.all(np.isfinite(states[:, -1])):  # inf or NaN stays non-finite
        raise ValueError(
            f"the simulated states overflowed the float64 range (reached inf or NaN): A, Q, "
            f"mean0 and P0 are too large together over {n_steps} steps (largest magnitudes: "
            f"A {np.max(np.abs(A)):.3g}, Q {np.max(np.abs(Q)):.3g}, mean0 "
            f"{np.max(np.abs(mean0)):.3g}, P0 {np.max(np.abs(P0)):.3g})")
    return states
