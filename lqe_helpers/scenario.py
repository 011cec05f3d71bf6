"""The one place that holds every constant the tutorial leaves to its MATLAB script.

Change a value here and every notebook, explorer and test follows.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from . import model, simulation, validation


def matched_jerk_std(amplitude: float, frequency: float, dt: float,
                     period_fraction: float = 0.25) -> float:
    """Jerk noise σ_j (cm/s³) whose random walk matches the sinusoid's change of acceleration.

    The filter treats the jerk as white noise held over each step, so its
    acceleration performs a random walk whose spread (standard deviation) after a time
    T is ``σ_j √(Δt T)``. This function sets that spread equal to the amplitude ``A ω²`` of the
    acceleration of ``A sin(ωt)`` (``ω = 2π f``) over ``T = period_fraction / f`` and
    returns ``σ_j = A ω² / √(Δt T)``.

    Parameters
    ----------
    amplitude : float
        Sinusoid amplitude A in cm, > 0.
    frequency : float
        Sinusoid frequency f in Hz, > 0.
    dt : float
        Time step Δt in s, > 0.
    period_fraction : float
        The time scale T as a fraction of the flight's period, > 0: ``T =
        period_fraction / f``. The default, a quarter, is the pack's choice.

    Returns
    -------
    float
        σ_j in cm/s³.
    """
    amplitude = validation.positive("amplitude", amplitude, "cm")
    frequency = validation.positive("frequency", frequency, "Hz")
    dt = validation.positive("dt", dt, "s")
    period_fraction = validation.positive("period_fraction", period_fraction)
    omega = 2.0 * np.pi * frequency
    time_scale = period_fraction / frequency
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        value = float(amplitude * omega**2 / np.sqrt(dt * time_scale))
    if not (np.isfinite(value) and value > 0):
        raise ValueError(
            f"amplitude, frequency, dt and period_fraction give σ_j = A ω² / √(Δt T) outside "
            f"the float64 range, got amplitude = {amplitude:g} cm, frequency = {frequency:g} "
            f"Hz, dt = {dt:g} s, period_fraction = {period_fraction:g}")
    return value


@dataclass(frozen=True)
class Scenario:
    """The butterfly, the observer and the simulation settings of Tutorial 5.

    Use :data:`DEFAULT`; make a variant with ``dataclasses.replace(DEFAULT, ...)``.
    """

    #: Time step Δt (s). 100 Hz: fast next to the 0.5 Hz flight, and the tutorial's
    #: 0.1 s sensory delay is then exactly δ = 10 steps.
    dt: float = 0.01
    #: Length of a simulated trial (s): five periods of the flight, 1 000 steps. Must be
    #: a whole number of time steps, as must :attr:`burn_in` and :attr:`delay`.
    duration: float = 10.0
    #: Amplitude A of the butterfly's sinusoidal path (cm): a hand-sized movement,
    #: large next to the 1.5–4.5 cm sensor noise of the questions.
    amplitude: float = 10.0
    #: Frequency f of the path (Hz): one slow sweep every 2 s, easy to follow by eye.
    frequency: float = 0.5
    #: Jerk noise σ_j behind Q (cm/s³). None: :func:`matched_jerk_std`, derived from
    #: the path (≈ 1 396 cm/s³ for the values above), near the MSE-optimal value.
    jerk_std: float | None = None
    #: Initial estimate z0 = [p, v, a] (cm, cm/s, cm/s²): the observer assumes the
    #: butterfly is at rest in the centre, while it really starts at 31 cm/s.
    z0: tuple[float, float, float] = (0.0, 0.0, 0.0)
    #: Vision noise σ_v (cm): question (a)'s first value.
    sigma_v: float = 1.5
    #: Proprioception noise σ_p (cm): question (c)'s value.
    sigma_p: float = 1.5
    #: Initial covariance P0 = p0_variance · I (cm², cm²/s², cm²/s⁴): question (c)'s
    #: diag(1, 1, 1), used wherever a question does not set P0 itself.
    p0_variance: float = 1.0
    #: Sensory delay d (s) of question (e).
    delay: float = 0.1
    #: Seed of every noise draw: any fixed integer; change it to see another draw.
    seed: int = 5
    #: Seed of the explorers' noise draw (the sliders' fixed noise pattern). Not
    #: :attr:`seed`, on purpose: an explorer at its default values then shows another
    #: run than the one a task computes, so it never prints a task's answer (issue 15).
    #: Any seed whose runs do not, by chance, round to a number a task prints
    #: (``tests/explorers/test_explorer_leaks.py`` checks every explorer's default view).
    explorer_seed: int = 25
    #: Monte Carlo runs behind every "is it better?" answer: enough for 95 %
    #: intervals a few percent wide, fast enough to recompute in a notebook cell.
    mc_runs: int = 300
    #: Time (s) skipped before MSEs, so they measure tracking, not the start-up
    #: transient from z0 (question (b) studies that transient on its own).
    burn_in: float = 1.0

    def __post_init__(self) -> None:
        validation.positive("dt", self.dt, "s")
        validation.positive("duration", self.duration, "s")
        steps = validation.whole_steps("duration", self.duration, self.dt)
        validation.check_memory(
            f"duration = {self.duration} s ({steps} steps of dt = {self.dt} s)",
            _NUMBERS_PER_STEP * steps,
            what="for one run's truth, readings, estimates, gains and covariances")
        if self.duration < 2 * self.dt:
            raise ValueError(
                f"duration must be at least two time steps of dt = {self.dt} s, got "
                f"{self.duration}")
        validation.positive("amplitude", self.amplitude, "cm")
        validation.positive("frequency", self.frequency, "Hz")
        if self.frequency >= 0.5 / self.dt:
            raise ValueError(
                f"frequency must be below the Nyquist limit 1/(2 dt) = {0.5 / self.dt} Hz, "
                f"got {self.frequency}"
            )
        if self.jerk_std is not None:
            validation.positive("jerk_std", self.jerk_std, "cm/s³")
        validation.finite_array("z0", self.z0)
        if np.shape(self.z0) != (3,):
            raise ValueError(f"z0 must hold 3 numbers [p, v, a], got {self.z0!r}")
        validation.positive("sigma_v", self.sigma_v, "cm")
        validation.positive("sigma_p", self.sigma_p, "cm")
        validation.positive("p0_variance", self.p0_variance, "cm²")
        self.delay_steps(self.delay)
        validation.count("seed", self.seed, minimum=0)
        validation.count("explorer_seed", self.explorer_seed, minimum=0)
        validation.count("mc_runs", self.mc_runs, minimum=2)
        validation.non_negative("burn_in", self.burn_in, "s")
        validation.whole_steps("burn_in", self.burn_in, self.dt)
        if self.burn_in >= self.duration:
            raise ValueError(
                f"burn_in must be shorter than duration = {self.duration} s, got {self.burn_in}"
            )

    # Time -----------------------------------------------------------------------------
    @property
    def n_steps(self) -> int:
        """Number of samples in a trial: :attr:`duration` / :attr:`dt`, a whole number."""
        return validation.whole_steps("duration", self.duration, self.dt)

    @property
    def times(self) -> np.ndarray:
        """Sample times (s), shape (n,)."""
        return np.arange(self.n_steps) * self.dt

    @property
    def burn_in_steps(self) -> int:
        """:attr:`burn_in` in samples, a whole number."""
        return validation.whole_steps("burn_in", self.burn_in, self.dt)

    def delay_steps(self, delay: float) -> int:
        """A delay in s as a whole number of samples δ = d / Δt.

        Raises ``ValueError`` unless ``0 <= delay < duration`` and ``delay`` is a
        whole multiple of :attr:`dt`.
        """
        seconds = validation.non_negative("delay", delay, "s")
        # The value as given, so that a float32 delay is judged at float32 precision.
        steps = validation.whole_steps("delay", delay, self.dt)
        if steps >= self.n_steps:
            raise ValueError(
                f"delay must be shorter than the trial ({self.duration} s), got {seconds} s"
            )
        return steps

    # Path -----------------------------------------------------------------------------
    @property
    def peak_speed(self) -> float:
        """Peak speed ``A · 2π f`` (cm/s) of the butterfly's path ``A sin(2π f t)``."""
        return float(self.amplitude * 2.0 * np.pi * self.frequency)

    # Model ----------------------------------------------------------------------------
    @property
    def process_jerk_std(self) -> float:
        """σ_j actually used for Q (cm/s³): :attr:`jerk_std`, or the matched value."""
        if self.jerk_std is not None:
            return float(self.jerk_std)
        return matched_jerk_std(self.amplitude, self.frequency, self.dt)

    @property
    def A(self) -> np.ndarray:
        """Transition matrix (3, 3) for :attr:`dt`."""
        return model.transition_matrix(self.dt)

    @property
    def Q(self) -> np.ndarray:
        """Process noise covariance (3, 3) from :attr:`process_jerk_std`."""
        return model.process_noise_covariance(self.dt, self.process_jerk_std)

    @property
    def P0(self) -> np.ndarray:
        """Default initial covariance ``p0_variance · I`` (3, 3)."""
        return model.diagonal_covariance(self.p0_variance)

    # Truth and noise ------------------------------------------------------------------
    @property
    def truth(self) -> np.ndarray:
        """True states [p, v, a] of the butterfly, shape (n, 3)."""
        return simulation.sinusoid_states(self.times, self.amplitude, self.frequency)

    def unit_noise(self, runs: int | None = None,
                   sensors: Sequence[str] = model.SENSORS) -> np.ndarray:
        """The scenario's fixed unit-noise draw: shape (n, m) or (runs, n, m).

        Always drawn for every sensor of :data:`~lqe_helpers.model.SENSORS` from
        ``np.random.default_rng(seed)``, then the requested columns are returned, so
        vision's noise is identical in vision-only and fused simulations, and run 0
        of a Monte Carlo batch is the single run shown in the figures.
        """
        sensors = model.sensor_names(sensors)
        if runs is not None:
            runs = validation.count("runs", runs, minimum=1)
            validation.check_memory(f"runs = {runs}",
                                    2 * runs * self.n_steps * len(model.SENSORS),
                                    what=f"for the noise of {self.n_steps} steps")
        rng = np.random.default_rng(self.seed)
        noise = simulation.unit_noise(rng, self.n_steps, len(model.SENSORS), runs=runs)
        return noise[..., [model.SENSORS.index(s) for s in sensors]]


#: Float64 numbers one simulated and filtered run holds per time step (times, truth,
#: noise, readings, estimates, gains, covariances and their temporaries), for the size
#: check of :attr:`Scenario.duration`.
_NUMBERS_PER_STEP = 64

#: The pack's scenario: every notebook starts from it.
DEFAULT = Scenario()
