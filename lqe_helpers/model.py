"""The butterfly model: matrices of the state and observation equations.

State ``z = [p, v, a]``: position (cm), velocity (cm/s), acceleration (cm/s²).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from . import _matrices, validation

#: Sensors that can observe the butterfly, in the row order of ``C`` and ``R``.
SENSORS = ("vision", "proprioception")


def transition_matrix(dt: float) -> np.ndarray:
    """Constant-acceleration transition matrix A (Tutorial eq. (4); Lesson 0.5 eq. (1)).

    Parameters
    ----------
    dt : float
        Time step Δt in s, > 0.

    Returns
    -------
    ndarray, shape (3, 3)
        ``[[1, Δt, Δt²/2], [0, 1, Δt], [0, 0, 1]]``: position gains velocity·Δt plus
        acceleration·Δt²/2, velocity gains acceleration·Δt, acceleration is kept.
    """
    dt = validation.positive("dt", dt, "s")
    return validation.in_float_range(f"dt = {dt:g} s", lambda: np.array(
        [[1.0, dt, dt * dt / 2.0], [0.0, 1.0, dt], [0.0, 0.0, 1.0]]))


def jerk_input_matrix(dt: float) -> np.ndarray:
    """Input matrix G of a jerk held constant over one step (Lesson 0.5 eqs. (4)–(5)).

    A jerk ``j`` (cm/s³) held for Δt adds ``j Δt³/6`` to position, ``j Δt²/2`` to
    velocity and ``j Δt`` to acceleration: the exact integrals, as in the lesson's
    ``G = [Δt²/2, Δt]`` one derivative lower.

    Parameters
    ----------
    dt : float
        Time step Δt in s, > 0.

    Returns
    -------
    ndarray, shape (3, 1)
        ``[[Δt³/6], [Δt²/2], [Δt]]`` in s³, s², s.
    """
    dt = validation.positive("dt", dt, "s")
    return validation.in_float_range(
        f"dt = {dt:g} s", lambda: np.array([[dt**3 / 6.0], [dt**2 / 2.0], [dt]]))


def process_noise_covariance(dt: float, jerk_std: float) -> np.ndarray:
    """Process noise covariance ``Q = G σ_j² Gᵀ`` of a jerk held constant over each step.

    Lesson 0.5 eq. (9) propagates an input's variance through its input matrix:
    ``P(k+1) = F P Fᵀ + G σ_u² Gᵀ``. Here the unknown input is the butterfly's jerk,
    modelled as white noise held constant over each step with standard deviation
    ``σ_j`` (cm/s³). Its contribution is ``Q = σ_j² G Gᵀ`` with ``G`` from
    :func:`jerk_input_matrix`, so Q follows from one physical number instead of
    nine hand-tuned entries. Q has rank 1: the three components of the noise are
    perfectly correlated because one jerk drives them all.

    Parameters
    ----------
    dt : float
        Time step Δt in s, > 0.
    jerk_std : float
        Standard deviation σ_j of the jerk in cm/s³, >= 0.

    Returns
    -------
    ndarray, shape (3, 3)
        Q with units cm², cm²/s, cm²/s², ... (row i, column j: cm²/s^(i+j)).
    """
    jerk_std = validation.non_negative("jerk_std", jerk_std, "cm/s³")
    dt = validation.positive("dt", dt, "s")
    return validation.in_float_range(
        f"jerk_std = {jerk_std:g} cm/s³ with dt = {dt:g} s",
        lambda: _matrices.input_noise_covariance(jerk_input_matrix(dt), jerk_std))


def observation_matrix(sensors: Sequence[str] = ("vision",)) -> np.ndarray:
    """Observation matrix C: each sensor reads the position (Tutorial eq. (3)).

    Parameters
    ----------
    sensors : sequence of str
        Sensors in row order, each one of :data:`SENSORS`, e.g. ``("vision",)`` or
        ``("vision", "proprioception")``.

    Returns
    -------
    ndarray, shape (m, 3)
        One row ``[1, 0, 0]`` per sensor.
    """
    return _matrices.observation(len(sensor_names(sensors)))


def measurement_noise_covariance(sigmas: Sequence[float] | np.ndarray) -> np.ndarray:
    """Sensor noise covariance ``R = diag(σ²)`` of independent sensors (Tutorial eq. (6)).

    Parameters
    ----------
    sigmas : array_like, shape (..., m)
        Sensor noise standard deviations in cm, each > 0. Leading axes are batch axes,
        so a sweep over σ gives a stack of R matrices. R's size is refused beyond
        :data:`~lqe_helpers.validation.MEMORY_LIMIT_BYTES` (ValueError), before it is made.

    Returns
    -------
    ndarray, shape (..., m, m)
    """
    sigmas = validation.finite_array("sigmas", sigmas, min_ndim=1)
    validation.check_memory(f"sigmas of shape {sigmas.shape}",
                            validation.elements(sigmas.shape) * (sigmas.shape[-1] + 1),
                            what="for R, one row and column per sensor")
    if np.any(sigmas <= 0):
        raise ValueError(f"sigmas must all be > 0 cm, got {np.ravel(sigmas)[:6].tolist()}")
    validation.in_float_range(
        f"sigmas (largest {np.max(sigmas):g} cm, smallest {np.min(sigmas):g} cm)",
        lambda: sigmas**2, positive=True)
    return _matrices.noise_covariance(sigmas)


def diagonal_covariance(variance: float | np.ndarray, size: int = 3) -> np.ndarray:
    """Covariance ``variance · I`` such as the tutorial's ``P0 = diag(10⁵, 10⁵, 10⁵)``.

    Parameters
    ----------
    variance : float or array_like, shape (...)
        Variance of each component (cm², cm²/s², cm²/s⁴ for [p, v, a]), > 0. An
        array gives a batch of covariances.
    size : int
        Dimension k of the state.

    Returns
    -------
    ndarray, shape (..., size, size)
    """
    variance = validation.finite_array("variance", variance)
    if np.any(variance <= 0):
        raise ValueError(
            f"variance must be > 0, got {np.ravel(variance)[:6].tolist()}"
        )
    size = validation.count("size", size, minimum=1)
    validation.check_memory(f"size = {size} with variance of shape {variance.shape}",
                            (variance.size + 1) * size * size, what="for the covariances")
    return _matrices.scaled_identity(variance, size)



def sensor_names(sensors: Sequence[str]) -> tuple[str, ...]:
    """Check a choice of sensors and return it as a tuple of names.

    Parameters
    ----------
    sensors : sequence of str
        Distinct names from :data:`SENSORS` in row order, e.g. ``("vision",)``.

    Returns
    -------
    tuple of str

    Raises
    ------
    ValueError
        If ``sensors`` is a single string (``"vision"`` instead of ``("vision",)``),
        not a sequence at all (``None``), empty, or holds unknown or repeated names.
    """
    wanted = f"a non-empty sequence of names from {SENSORS}, e.g. ('vision',)"
    if isinstance(sensors, (str, bytes)):
        raise ValueError(
            f"sensors must be {wanted}, got the string {sensors!r}: write "
            f"({sensors!r},) with the comma for one sensor")
    try:
        names = tuple(sensors)
    except TypeError:
        raise ValueError(f"sensors must be {wanted}, got {sensors!r}") from None
    if len(names) == 0:
        raise ValueError(f"sensors must be {wanted}, got {sensors!r}")
    known = all(isinstance(s, str) and s in SENSORS for s in names)
    if not known or len(set(names)) != len(names):
        raise ValueError(f"sensors must be distinct names from {SENSORS}, got {names!r}")
    return names
