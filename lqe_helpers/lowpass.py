"""The steady-state filter as a fixed linear low-pass filter (issue 17 §3).

Once the gain has settled, Tutorial eq. (5) reads ``ẑ_j = M ẑ_{j−1} + K∞ y_j`` with the
fixed closed-loop matrix ``M = (I − K∞ C) A``: a time-invariant linear filter from the
readings to the estimate. Its poles say how fast it forgets, its frequency response how
it passes a movement of each frequency (gain and phase), and its response to white
reading noise how much noise gets through. Everything here follows from
:func:`~lqe_helpers.steady_state.steady_state`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import validation
from .steady_state import steady_state


@dataclass(frozen=True)
class LowPass:
    """The settled filter ``ẑ_j = M ẑ_{j−1} + K y_j`` of a ``k``-state, ``m``-sensor model.

    Attributes
    ----------
    dt : float
        Time step Δt (s).
    gain : ndarray, shape (..., k, m)
        ``K∞``, from :func:`~lqe_helpers.steady_state.steady_state`.
    closed_loop : ndarray, shape (..., k, k)
        ``M = (I − K∞ C) A``.
    noise : ndarray, shape (..., m, m)
        R, the readings' noise covariance (cm²) the gain was computed for.
    """

    dt: float
    gain: np.ndarray
    closed_loop: np.ndarray
    noise: np.ndarray

    @property
    def poles(self) -> np.ndarray:
        """Eigenvalues of M, shape (..., k), complex; all inside the unit circle."""
        return np.linalg.eigvals(self.closed_loop)

    @property
    def time_constants(self) -> np.ndarray:
        """``τ = −Δt / ln|λ|`` (s) of each pole, shape (..., k): the e-folding time of its
        mode's envelope (a pair of complex poles shares one τ and oscillates at
        ``arg λ / (2π Δt)`` Hz)."""
        return -self.dt / np.log(np.abs(self.poles))


def steady_lowpass(A: np.ndarray, C: np.ndarray, Q: np.ndarray, R: np.ndarray,
                   dt: float) -> LowPass:
    """The filter of Tutorial eq. (5) after its start-up, as a fixed linear filter.

    Parameters
    ----------
    A, C, Q, R : array_like
        As for :func:`~lqe_helpers.steady_state.steady_state`: A (k, k), C (m, k),
        Q (k, k), R (..., m, m) in cm² (a batch gives one filter per R).
    dt : float
        Time step Δt (s) of A, > 0, for time constants and frequencies.

    Returns
    -------
    LowPass
    """
    dt = validation.positive("dt", dt, "s")
    steady = steady_state(A, C, Q, R)  # validates A, C, Q, R
    A = np.asarray(A, dtype=float)
    C = np.asarray(C, dtype=float)
    k = A.shape[0]
    closed_loop = (np.eye(k) - steady.gain @ C) @ A
    return LowPass(dt, steady.gain, closed_loop,
                   np.broadcast_to(np.asarray(R, dtype=float), (*steady.gain.shape[:-2],
                                                                 C.shape[0], C.shape[0])))


@dataclass(frozen=True)
class FrequencyResponse:
    """How the settled filter passes a position that moves as a sinusoid.

    Attributes
    ----------
    frequency : ndarray, shape (f,)
        Frequencies (Hz).
    response : ndarray, shape (..., f), complex
        ``H``: a true position ``sin(2π f t)`` read by every sensor gives, once settled,
        the position estimate ``|H| sin(2π f t + arg H)``.
    """

    frequency: np.ndarray
    response: np.ndarray

    @property
    def gain(self) -> np.ndarray:
        """``|H|``: amplitude of the estimate over that of the movement (1 passes it)."""
        return np.abs(self.response)

    @property
    def phase(self) -> np.ndarray:
        """``arg H`` (rad), > 0 when the estimate runs ahead of the movement."""
        return np.angle(self.response)

    @property
    def lead(self) -> np.ndarray:
        """``arg H / (2π f)`` (s): the time by which the estimate runs ahead (< 0: lags),
        the ``lead`` of :func:`~lqe_helpers.metrics.fit_sinusoid` on a settled run."""
        return self.phase / (2.0 * np.pi * self.frequency)


def position_response(lowpass: LowPass, frequency: float | np.ndarray) -> FrequencyResponse:
    """Frequency response from the true position to the position estimate (state 0).

    With every sensor reading the position (rows ``[1, 0, …, 0]`` of C, as all the
    pack's senses do), a position ``e^{iωt}`` gives readings ``e^{iωjΔt}`` on every
    sensor and, once settled, the estimate ``X e^{iωjΔt}`` with
    ``X = (I − M e^{−iωΔt})⁻¹ K 1``; H is its position entry.

    Parameters
    ----------
    lowpass : LowPass
        From :func:`steady_lowpass`.
    frequency : float or array_like, shape (f,)
        Frequencies in Hz, each > 0 and below the Nyquist limit 1/(2Δt).

    Returns
    -------
    FrequencyResponse
        ``response`` of shape (..., f) for the batch (...) of ``lowpass``.
    """
    validation.instance("lowpass", lowpass, LowPass, "from steady_lowpass()")
    frequency = validation.positive_array("frequency", frequency, "Hz")
    frequency = np.atleast_1d(frequency)
    if frequency.ndim != 1:
        raise ValueError(f"frequency must be a number or shape (f,), got shape {frequency.shape}")
    nyquist = 0.5 / lowpass.dt
    if np.any(frequency >= nyquist):
        raise ValueError(f"frequency must be below the Nyquist limit 1/(2 dt) = {nyquist:g} Hz, "
                         f"got {frequency.max():g} Hz")
    M, K = lowpass.closed_loop, lowpass.gain
    k = M.shape[-1]
    validation.check_memory(f"frequency of shape {frequency.shape} with a batch of "
                            f"{M.shape[:-2]} filters",
                            4 * validation.elements((*M.shape[:-2], frequency.size, k, k)),
                            what="for the frequency response")
    delay = np.exp(-2j * np.pi * frequency * lowpass.dt)[:, None, None]  # (f, 1, 1)
    system = np.eye(k) - M[..., None, :, :] * delay                        # (..., f, k, k)
    drive = np.sum(K, axis=-1)[..., None, :, None]                         # (..., 1, k, 1)
    X = np.linalg.solve(system, np.broadcast_to(drive, (*system.shape[:-1], 1)))
    return FrequencyResponse(frequency, X[..., 0, 0])


def noise_variance(lowpass: LowPass) -> np.ndarray:
    """Variance (cm²) of the settled position estimate's response to the readings' noise.

    White reading noise of covariance R passes through the filter as
    ``X = M X Mᵀ + K R Kᵀ`` (a discrete Lyapunov equation, solved exactly with
    Kronecker products); the position entry ``X[0, 0]`` is the noise part of the
    MSE, the part that shrinks when the filter averages longer.

    Returns
    -------
    ndarray, shape (...)
    """
    validation.instance("lowpass", lowpass, LowPass, "from steady_lowpass()")
    M, K = lowpass.closed_loop, lowpass.gain
    k = M.shape[-1]
    validation.check_memory(f"a filter of k = {k} states with a batch of shape "
                            f"{M.shape[:-2]}", validation.elements(M.shape[:-2]) * k**4,
                            copies=3, what="for its Kronecker products (k⁴ numbers each)")
    driven = K @ lowpass.noise @ K.mT
    kron = M[..., :, None, :, None] * M[..., None, :, None, :]   # (M ⊗ M)[(i,j),(a,b)]
    system = np.eye(k * k) - kron.reshape(*M.shape[:-2], k * k, k * k)
    X = np.linalg.solve(system, driven.reshape(*driven.shape[:-2], k * k, 1))
    return X.reshape(*M.shape[:-2], k, k)[..., 0, 0]


@dataclass(frozen=True)
class SinusoidMSE:
    """The settled filter's MSE on a sinusoidal path, split as in notebook 01.

    Attributes
    ----------
    systematic : ndarray, shape (...)
        ``A²/2 · |H − 1|²`` (cm²): the mean square of the noise-free estimate's error.
    noise : ndarray, shape (...)
        :func:`noise_variance` (cm²).
    """

    systematic: np.ndarray
    noise: np.ndarray

    @property
    def total(self) -> np.ndarray:
        """Systematic plus noise part (cm²): the Monte Carlo MSE once settled."""
        return self.systematic + self.noise


def sinusoid_mse(lowpass: LowPass, amplitude: float, frequency: float) -> SinusoidMSE:
    """Predicted MSE of the settled filter on the path ``amplitude · sin(2π f t)``.

    The error of a linear filter splits exactly into its response to the path and its
    response to the noise, which are uncorrelated. On the path it is the sinusoid
    ``(H − 1) · amplitude · sin(…)``, whose mean square is ``amplitude² |H − 1|² / 2``.

    Parameters
    ----------
    lowpass : LowPass
    amplitude : float
        Path amplitude (cm), > 0.
    frequency : float
        Path frequency (Hz), > 0 and below the Nyquist limit.
    """
    amplitude = validation.positive("amplitude", amplitude, "cm")
    frequency = validation.positive("frequency", frequency, "Hz")
    response = position_response(lowpass, frequency).response[..., 0]
    with np.errstate(over="ignore"):
        systematic = amplitude * amplitude / 2.0 * np.abs(response - 1.0) ** 2
    if not np.all(np.isfinite(systematic)):
        raise ValueError(f"amplitude = {amplitude:g} cm is too large: its square overflows "
                         f"the float64 range")
    return SinusoidMSE(systematic, noise_variance(lowpass))


def variance_exponent(A: np.ndarray, C: np.ndarray, Q: np.ndarray, R: np.ndarray,
                      step: float = 1e-3) -> np.ndarray:
    """Local exponent ``d ln [P̂∞]pp / d ln s`` of the settled position variance under R → s R.

    A central difference of the steady state at ``R e^{±step}``: 1 where the filter just
    copies the readings (variance ∝ R), 5/6 where it is a slow averager of a random-jerk
    model (the continuous-time limit of a triple integrator: variance ∝ R^(5/6) Q^(1/6)).
    Halving R multiplies the variance by about ``2^(−exponent)``.

    Parameters
    ----------
    A, C, Q, R : array_like
        As for :func:`~lqe_helpers.steady_state.steady_state`; R (..., m, m) in cm².
    step : float
        Half-width of the difference in ln s, > 0 and <= 0.1.

    Returns
    -------
    ndarray, shape (...)
    """
    step = validation.positive("step", step)
    if step > 0.1:
        raise ValueError(f"step must be <= 0.1 (a local derivative), got {step}")
    R = validation.covariance("R", R, definite=True)
    scaled = np.stack([R * np.exp(step), R * np.exp(-step)])
    variances = steady_state(A, C, Q, scaled).estimate_covariance[..., 0, 0]
    return (np.log(variances[0]) - np.log(variances[1])) / (2.0 * step)
