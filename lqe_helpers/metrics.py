"""Numbers the notebooks report: MSE, Monte Carlo intervals, convergence time, innovations."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import validation
from .distributions import chi2_quantile, t_critical_95  # t_critical_95: metrics.t_critical_95 too


def mse(estimate: np.ndarray, truth: np.ndarray, burn_in_steps: int = 0) -> np.ndarray:
    """Mean squared error over time, after skipping ``burn_in_steps`` samples.

    Parameters
    ----------
    estimate : array_like, shape (..., n)
        Estimated positions (cm); leading axes are runs or a parameter sweep. NaN is
        allowed within the burn-in (e.g. a prediction that does not exist yet).
    truth : array_like, shape (n,)
        True positions (cm).
    burn_in_steps : int
        Samples skipped at the start, 0 <= burn_in_steps < n.

    Returns
    -------
    ndarray, shape (...)
        MSE in cm².

    Raises
    ------
    ValueError
        If shapes differ on n, or NaN remains after the burn-in (e.g. a prediction
        that does not exist yet: raise the burn-in to at least the delay).
    """
    estimate = validation.numeric_array("estimate", estimate)
    truth = validation.finite_array("truth", truth, min_ndim=1)
    if truth.ndim != 1:
        raise ValueError(f"truth must have shape (n,), got shape {truth.shape}")
    if estimate.ndim < 1 or estimate.shape[-1] != truth.shape[-1]:
        columns = estimate.ndim >= 2 and estimate.shape[-2] == truth.shape[-1]
        hint = "; estimates (n, k) hold one column per state: pass column 0, the positions"
        raise ValueError(f"estimate must have shape (..., n) with n = {truth.shape[-1]} like "
                         f"truth, got shape {estimate.shape}" + (hint if columns else ""))
    n_steps = truth.shape[-1]
    burn_in_steps = validation.count("burn_in_steps", burn_in_steps, 0, n_steps - 1)
    kept = estimate[..., burn_in_steps:]
    if not np.all(np.isfinite(kept)):
        first = int(np.argmax(~np.all(np.isfinite(kept), axis=tuple(range(kept.ndim - 1)))))
        raise ValueError(
            f"estimate must be finite after burn_in_steps = {burn_in_steps}, got NaN or inf "
            f"at sample {burn_in_steps + first}; skip at least the samples with no estimate"
        )
    with np.errstate(over="ignore", invalid="ignore"):
        result = np.mean((kept - truth[burn_in_steps:]) ** 2, axis=-1)
    if not np.all(np.isfinite(result)):
        raise ValueError(
            f"estimate and truth differ by more than the float64 range allows squaring "
            f"(largest magnitudes {np.max(np.abs(kept)):.3g} and {np.max(np.abs(truth)):.3g} "
            f"cm): the squared error overflows")
    return result


@dataclass(frozen=True)
class Interval:
    """A Monte Carlo mean with its two-sided 95 % confidence interval."""

    mean: float
    low: float
    high: float
    runs: int

    @property
    def half_width(self) -> float:
        """Distance from the mean to either end of the interval."""
        return (self.high - self.low) / 2

    def __format__(self, spec: str) -> str:
        spec = spec or ".3g"
        return (f"{self.mean:{spec}} (95 % CI {self.low:{spec}} to {self.high:{spec}}, "
                f"{self.runs} runs)")

    def __str__(self) -> str:
        return format(self, "")

    def __sub__(self, other: object) -> Interval:
        raise TypeError("intervals cannot be subtracted: the difference of two conditions is "
                        "mean_ci95 of their per-run differences (paired, run by run)")

    def __truediv__(self, other: object) -> Interval:
        raise TypeError("intervals cannot be divided: a share or ratio of two conditions is "
                        "mean_ci95 of the per-run ratios (run by run)")

    __rsub__, __rtruediv__ = __sub__, __truediv__


def mean_ci95(samples: np.ndarray) -> Interval:
    """Mean of independent samples with a Student-t 95 % confidence interval.

    Parameters
    ----------
    samples : array_like, shape (runs,)
        One value per Monte Carlo run (e.g. per-run MSEs, or paired differences
        of two MSEs computed on the same noise), at least 2 runs.

    Returns
    -------
    Interval
        ``mean ± t(0.975, runs − 1) · s / √runs``.
    """
    samples = validation.finite_array("samples", samples)
    if samples.ndim == 0:
        raise ValueError(f"samples must be one value per run (at least 2), got one number "
                         f"({samples.item():.6g}): pass the per-run values, not their mean")
    if samples.ndim != 1 or samples.size < 2:
        raise ValueError(
            f"samples must be a 1-D array of at least 2 runs, got shape {samples.shape}"
        )
    runs = samples.size
    # In units of the largest magnitude, so that samples near the float64 limit give a
    # finite spread whenever the answer itself is finite.
    scale = float(np.max(np.abs(samples))) or 1.0
    unit = samples / scale
    mean = float(np.mean(unit)) * scale
    half = t_critical_95(runs - 1) * float(np.std(unit, ddof=1)) / np.sqrt(runs) * scale
    if not (np.isfinite(mean - half) and np.isfinite(mean + half)):
        raise ValueError(f"samples are too large for a float64 interval: the largest "
                         f"magnitude is {scale:.3g}")
    return Interval(mean, mean - half, mean + half, runs)


def convergence_time(squared_error: np.ndarray, dt: float, factor: float = 2.0) -> np.ndarray:
    """Time after which a squared-error curve stays within ``factor`` × its steady level.

    Definition used throughout the pack: the steady level is the curve's mean over
    the second half of the trial; the convergence time is the first sample time t
    such that the curve is <= factor × steady level at t and at every later sample.
    Apply it to the Monte Carlo mean of the squared position error, so that noise
    averages out and what remains is the filter's approach to steady state.

    Parameters
    ----------
    squared_error : array_like, shape (..., n)
        Squared error (cm²) per sample, e.g. a Monte Carlo mean; n >= 10.
    dt : float
        Time step in s.
    factor : float
        Tolerance above the steady level, > 1.

    Returns
    -------
    ndarray, shape (...)
        Convergence time in s (0 if the curve never leaves the band).
    """
    curve = validation.finite_array("squared_error", squared_error, min_ndim=1)
    if curve.shape[-1] < 10:  # the steady level is a mean over the second half
        raise ValueError(f"squared_error needs at least 10 samples along its last axis (time), "
                         f"got shape {curve.shape}: was the mean taken over the right axis?")
    if np.any(curve < 0):
        raise ValueError("squared_error must be >= 0, got negative values")
    dt = validation.positive("dt", dt, "s")
    factor = validation.positive("factor", factor)
    if factor <= 1:
        raise ValueError(f"factor must be > 1, got {factor}")
    n_steps = curve.shape[-1]
    steady = np.mean(curve[..., n_steps // 2:], axis=-1, keepdims=True)
    with np.errstate(over="ignore"):  # a threshold of inf leaves nothing outside
        outside = curve > factor * steady
    # Index just after the last sample outside the band (0 if none is outside).
    last_outside = n_steps - np.argmax(outside[..., ::-1], axis=-1)
    first_inside = np.where(np.any(outside, axis=-1), last_outside, 0)
    if int(first_inside.max()) * dt > np.finfo(float).max:
        raise ValueError(f"dt = {dt:g} s times {int(first_inside.max())} samples overflows "
                         f"the float64 range")
    return first_inside * dt


def convergence_time_ci95(squared_errors: np.ndarray, dt: float, rng: np.random.Generator,
                          factor: float = 2.0, resamples: int = 1000) -> Interval:
    """Convergence time of the Monte Carlo mean curve, with a bootstrap 95 % interval.

    Parameters
    ----------
    squared_errors : array_like, shape (runs, n)
        Squared position error (cm²) of each run.
    dt : float
        Time step in s.
    rng : numpy.random.Generator
        Source of the bootstrap resampling.
    factor : float
        As in :func:`convergence_time`.
    resamples : int
        Bootstrap resamples of the runs.

    Returns
    -------
    Interval
        ``mean``: :func:`convergence_time` of the mean curve over all runs; ``low``,
        ``high``: 2.5th and 97.5th percentiles over resampled sets of runs.
    """
    errors = validation.finite_array("squared_errors", squared_errors, min_ndim=2)
    if errors.ndim != 2 or errors.shape[0] < 2:
        raise ValueError(
            f"squared_errors must have shape (runs, n) with runs >= 2, got {errors.shape}"
        )
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {rng!r}")
    resamples = validation.count("resamples", resamples, minimum=10)
    runs = errors.shape[0]
    validation.check_memory(f"resamples = {resamples} with squared_errors of shape "
                            f"{errors.shape}", 2 * resamples * (runs + errors.shape[1]),
                            what="for the bootstrap")
    estimate = float(convergence_time(errors.mean(axis=0), dt, factor))
    counts = rng.multinomial(runs, np.full(runs, 1.0 / runs), size=resamples)
    curves = counts @ errors / runs
    times = convergence_time(curves, dt, factor)
    low, high = np.percentile(times, [2.5, 97.5])
    return Interval(estimate, float(low), float(high), runs)


@dataclass(frozen=True)
class SinusoidFit:
    """Least-squares fit ``amplitude · sin(2π f (t + lead))`` of signals to a known frequency.

    Attributes
    ----------
    amplitude : ndarray, shape (...)
        Amplitude of the fitted sinusoid, in the signal's unit (e.g. cm).
    lead : ndarray, shape (...)
        Time shift in s against ``sin(2π f t)``: > 0 means the signal runs ahead of
        it, < 0 that it lags behind. Within ± half a period.
    """

    amplitude: np.ndarray
    lead: np.ndarray


def fit_sinusoid(times: np.ndarray, signal: np.ndarray, frequency: float) -> SinusoidFit:
    """Amplitude and time lead of the best sinusoid of ``frequency`` through ``signal``.

    Solves ``signal ≈ a sin(ωt) + b cos(ωt)`` (ω = 2π f) by linear least squares over
    the samples, then writes it as ``R sin(ω (t + lead))`` with ``R = √(a² + b²)`` and
    ``lead = atan2(b, a) / ω``. Compared with the true path ``A sin(ωt)`` this tells
    whether an estimate overshoots (R > A) and whether it runs ahead (lead > 0) or
    trails behind (lead < 0).

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times in s (n >= 2, not all equal).
    signal : array_like, shape (..., n)
        Signals, one per leading index, in any unit.
    frequency : float
        Frequency f in Hz, > 0.

    Returns
    -------
    SinusoidFit
        ``amplitude`` and ``lead`` with the leading shape of ``signal``.
    """
    times = validation.finite_array("times", times, min_ndim=1)
    signal = validation.finite_array("signal", signal, min_ndim=1)
    frequency = validation.positive("frequency", frequency, "Hz")
    if times.ndim != 1 or times.size < 2:
        raise ValueError(f"times must have shape (n,) with n >= 2, got shape {times.shape}")
    if signal.shape[-1] != times.size:
        raise ValueError(
            f"signal must have shape (..., {times.size}) to match times, got shape "
            f"{signal.shape}")
    omega = 2.0 * np.pi * frequency
    with np.errstate(over="ignore", invalid="ignore"):
        phases = omega * times
    if not np.all(np.isfinite(phases)):
        raise ValueError(f"frequency = {frequency:g} Hz times the times (up to "
                         f"{np.max(np.abs(times)):g} s) overflows the float64 range")
    basis = np.stack([np.sin(phases), np.cos(phases)], axis=1)  # (n, 2)
    if np.linalg.matrix_rank(basis) < 2:
        raise ValueError(
            f"times must span enough of a period of {frequency} Hz to tell sine from cosine, "
            f"got {times.size} samples from {times[0]} to {times[-1]} s")
    flat = signal.reshape(-1, times.size).T  # (n, batch)
    (sine, cosine), *_ = np.linalg.lstsq(basis, flat, rcond=None)
    shape = signal.shape[:-1]
    amplitude = np.hypot(sine, cosine).reshape(shape)
    lead = (np.arctan2(cosine, sine) / omega).reshape(shape)
    return SinusoidFit(amplitude=amplitude, lead=lead)


def power_law_exponent(x: np.ndarray, y: np.ndarray) -> float:
    """Exponent ``a`` of the least-squares fit ``y ≈ c · x^a`` (the slope on log–log axes).

    Parameters
    ----------
    x, y : array_like, shape (n,)
        Positive values, n >= 2, ``x`` not all equal (e.g. time in s and an error in cm).

    Returns
    -------
    float
        The fitted exponent: 2.5 for a position spread that grows as t^{5/2}, say.
    """
    x = validation.positive_array("x", x, min_ndim=1)
    y = validation.positive_array("y", y, min_ndim=1)
    if x.ndim != 1 or x.shape != y.shape or x.size < 2:
        raise ValueError(
            f"x and y must have the same shape (n,) with n >= 2, got shapes {x.shape} and "
            f"{y.shape}")
    if np.ptp(x) == 0:
        raise ValueError(f"x must not be all equal, got {x.size} values of {x[0]:g}")
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


# Innovations (issue 17 §2): what an observer can check without the true path ---------------

@dataclass(frozen=True)
class Innovations:
    """The filter's surprises and the spread it expected of them.

    Attributes
    ----------
    values : ndarray, shape (..., n, m)
        ``e_j = y_j − C A ẑ_{j−1}`` (cm; ``ẑ_{−1} = z0``), ``+ C B u_j`` subtracted
        too when the filter had an input: each reading minus the filter's prediction of it.
    covariances : ndarray, shape (..., n, m, m)
        ``S_j = C P_j Cᵀ + R`` (cm²), their covariance if the filter's model is right
        (:attr:`~lqe_helpers.filter.FilterResult.innovation_covariances`).
    """

    values: np.ndarray
    covariances: np.ndarray


def innovations(y: np.ndarray, result: object, A: np.ndarray, C: np.ndarray, z0: np.ndarray,
                B: np.ndarray | None = None, u: np.ndarray | None = None) -> Innovations:
    """The innovations of a filter run: each reading minus the prediction the filter made of it.

    Parameters
    ----------
    y : array_like, shape (..., n, m)
        The readings the filter was given (cm).
    result : FilterResult
        What :func:`~lqe_helpers.filter.kalman_filter` returned for them.
    A, C, z0, B, u : array_like
        The same A (k, k), C (m, k), z0 (..., k) and, if used, B (k, p) and u (..., n, p)
        given to the filter.

    Returns
    -------
    Innovations
        Values (..., n, m) and covariances (..., n, m, m), batch axes of ``result``.
    """
    from .filter import FilterResult  # the engine imports nothing from here

    validation.instance("result", result, FilterResult, "from kalman_filter()")
    if result.innovation_covariances is None:
        raise ValueError("result must come from kalman_filter(), which fills "
                         "innovation_covariances; got a FilterResult without them")
    estimates = result.estimates
    n_steps, k = estimates.shape[-2:]
    m = result.innovation_covariances.shape[-1]
    y = validation.finite_array("y", y, min_ndim=2)
    if y.shape[-2:] != (n_steps, m):
        raise ValueError(f"y must have trailing shape (n, m) = ({n_steps}, {m}) like result, "
                         f"got shape {y.shape}")
    A = validation.shaped_array("A", A, (k, k))
    C = validation.shaped_array("C", C, (m, k))
    z0 = validation.finite_array("z0", z0, min_ndim=1)
    if z0.shape[-1] != k:
        raise ValueError(f"z0 must have trailing length k = {k}, got shape {z0.shape}")
    batch = validation.broadcast_batches(result=estimates.shape[:-2], y=y.shape[:-2],
                                         z0=z0.shape[:-1])
    validation.check_memory(f"y of shape {y.shape} with result's batch {estimates.shape[:-2]}",
                            3 * validation.elements((*batch, n_steps, max(k, m))),
                            what="for the innovations")
    previous = np.concatenate([np.broadcast_to(z0, (*batch, k))[..., None, :],
                               np.broadcast_to(estimates, (*batch, n_steps, k))[..., :-1, :]],
                              axis=-2)
    predicted = previous @ (C @ A).T
    if (B is None) != (u is None):
        raise ValueError("B and u must be given together, as to the filter")
    if B is not None:
        B = validation.finite_array("B", B, min_ndim=2)
        u = validation.finite_array("u", u, min_ndim=2)
        if B.shape[0] != k or B.ndim != 2 or u.shape[-2:] != (n_steps, B.shape[1]):
            raise ValueError(f"B must have shape ({k}, p) and u trailing shape ({n_steps}, p), "
                             f"got shapes {B.shape} and {u.shape}")
        predicted = predicted + u @ (C @ B).T
    return Innovations(y - predicted, np.broadcast_to(
        result.innovation_covariances, (*batch, n_steps, m, m)))


def nis(innovations: Innovations) -> np.ndarray:
    """Normalised innovation squared ``ε_j = e_jᵀ S_j⁻¹ e_j`` per step, shape (..., n).

    For a filter whose model (A, Q, R, P0) is right, each ``ε_j`` is chi-square
    distributed with m degrees of freedom (m sensors): mean m; and the ``ε_j`` of
    different steps are independent, because the innovations of a correct Kalman
    filter are white. Needs no true path: any observer can compute it.
    """
    validation.instance("innovations", innovations, Innovations, "from metrics.innovations()")
    e = innovations.values[..., None]
    return (e.mT @ np.linalg.solve(innovations.covariances, e))[..., 0, 0]


def innovation_log_likelihood(innovations: Innovations, burn_in_steps: int = 0) -> np.ndarray:
    """Log-likelihood of the readings under the filter's model, summed over steps.

    ``Σ_j −½ (ε_j + ln det(2π S_j))`` for j >= ``burn_in_steps`` (the prediction error
    decomposition of a Gaussian state-space model): larger means the model (e.g. its
    σ_j) explains the readings better. Needs no true path.

    Returns
    -------
    ndarray, shape (...)
        One value per run (nats).
    """
    epsilon = nis(innovations)
    burn_in_steps = validation.count("burn_in_steps", burn_in_steps, 0, epsilon.shape[-1] - 1)
    _, logdet = np.linalg.slogdet(2.0 * np.pi * innovations.covariances)
    return -0.5 * np.sum((epsilon + logdet)[..., burn_in_steps:], axis=-1)


def nis_band(sensors: int, samples: int, level: float = 0.95) -> tuple[float, float]:
    """Two-sided ``level`` band for the mean NIS of ``samples`` independent steps.

    The sum of ``samples`` independent χ²_m values is χ² with m·samples degrees of
    freedom, so the mean lies in ``[χ²_{m·s}((1−level)/2), χ²_{m·s}((1+level)/2)] / s``
    with probability ``level``. ``samples = 1`` gives the band of a single step; N steps
    of R runs give the band of the grand mean (samples = N·R).
    """
    sensors = validation.count("sensors", sensors, minimum=1)
    samples = validation.count("samples", samples, minimum=1)
    level = validation.positive("level", level)
    if level >= 1:
        raise ValueError(f"level must be in (0, 1), got {level}")
    df = sensors * samples
    return (chi2_quantile((1 - level) / 2, df) / samples,
            chi2_quantile((1 + level) / 2, df) / samples)


@dataclass(frozen=True)
class NISTest:
    """The mean NIS of a batch of runs beside what a correct model predicts.

    Attributes
    ----------
    mean : float
        NIS averaged over the steps after the burn-in and over the runs.
    expected : int
        Its expected value for a correct model: m, the number of sensors.
    low, high : float
        95 % band for that mean (:func:`nis_band` with samples = steps × runs).
    samples : int
        Steps × runs averaged.
    run_means : ndarray, shape (runs,)
        Each run's time average; 95 % of them lie in ``nis_band(m, steps)`` for a
        correct model.
    """

    mean: float
    expected: int
    low: float
    high: float
    samples: int
    run_means: np.ndarray

    @property
    def consistent(self) -> bool:
        """Whether the mean lies inside the band."""
        return self.low <= self.mean <= self.high


def nis_test(innovations: Innovations, burn_in_steps: int = 0) -> NISTest:
    """Mean NIS over steps (after ``burn_in_steps``) and runs, with its 95 % band.

    Every leading axis of the innovations counts as runs; the band assumes the steps
    and runs independent, as they are for a correct model.
    """
    epsilon = nis(innovations)
    n_steps, m = innovations.values.shape[-2:]
    burn_in_steps = validation.count("burn_in_steps", burn_in_steps, 0, n_steps - 1)
    kept = epsilon[..., burn_in_steps:].reshape(-1, n_steps - burn_in_steps)
    low, high = nis_band(m, kept.size)
    return NISTest(float(kept.mean()), m, low, high, kept.size, kept.mean(axis=-1))
