"""The tutorial's experiments, built from a :class:`~lqe_helpers.scenario.Scenario`.

Notebooks and explorers call these instead of assembling C, R, P0 and noise by
hand, so a question's setup is written once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from . import metrics, model, simulation, validation
from .filter import FilterResult, kalman_filter
from .prediction import predict_ahead
from .scenario import Scenario


@dataclass(frozen=True)
class Tracking:
    """One filtering experiment: what the sensors said and what the filter made of it.

    Attributes
    ----------
    scenario : Scenario
    sensors : tuple of str
        Sensor names, in the column order of ``measurements``.
    measurements : ndarray, shape (..., n, m)
        Noisy readings (cm); leading axes are Monte Carlo runs, then any sweep axes.
    result : FilterResult
        The filter's estimates, gains and covariances, same leading axes.
    """

    scenario: Scenario
    sensors: tuple[str, ...]
    measurements: np.ndarray
    result: FilterResult

    @property
    def positions(self) -> np.ndarray:
        """Estimated positions ẑ[p] (cm), shape (..., n)."""
        return self.result.estimates[..., 0]

    @property
    def position_variances(self) -> np.ndarray:
        """The filter's own variance of its position estimate (cm²), shape (..., n)."""
        return self.result.estimate_covariances[..., 0, 0]

    def mse(self) -> np.ndarray:
        """Per-run position MSE (cm²) after the scenario's burn-in, shape (...)."""
        return metrics.mse(self.positions, self.scenario.truth[:, 0],
                           self.scenario.burn_in_steps)

    def measurement_mse(self, sensor: str = "vision") -> np.ndarray:
        """Per-run MSE (cm²) of one sensor's raw readings after the burn-in, shape (...)."""
        if not isinstance(sensor, str) or sensor not in self.sensors:
            raise ValueError(
                f"sensor must be one of the sensors this run simulated, {self.sensors}, "
                f"got {sensor!r}"
            )
        column = self.sensors.index(sensor)
        return metrics.mse(self.measurements[..., column], self.scenario.truth[:, 0],
                           self.scenario.burn_in_steps)


def track(scenario: Scenario, sensors: Sequence[str] = ("vision",),
          sigmas: Sequence[float] | np.ndarray | None = None,
          assumed_sigmas: Sequence[float] | np.ndarray | None = None,
          p0_variance: float | np.ndarray | None = None,
          runs: int | None = None, noise: np.ndarray | None = None) -> Tracking:
    """Simulate the sensors and run the filter (Tutorial eqs. (3)–(6)).

    Parameters
    ----------
    scenario : Scenario
        Constants of the simulation.
    sensors : sequence of str
        ``("vision",)`` or ``("vision", "proprioception")``.
    sigmas : array_like, shape (..., m), optional
        True noise σ of each sensor (cm), > 0. Default: the scenario's σ_v and σ_p.
        Leading axes sweep σ in one call.
    assumed_sigmas : array_like, shape (..., m), optional
        The σ the filter believes in, used for R (cm), > 0. Default: ``sigmas``.
    p0_variance : float or array_like, shape (...), optional
        P0 = p0_variance · I (cm², cm²/s², cm²/s⁴), > 0. Default: the scenario's. An
        array sweeps P0.
    runs : int, optional
        Monte Carlo runs; None for the single run shown in figures (run 0).
    noise : array_like, shape (n, m) or (runs, n, m), optional
        Unit noise to scale by σ; default the scenario's fixed draw. Explorers pass
        a draw they keep, so a slider changes σ, never the noise pattern.

    Returns
    -------
    Tracking
        Leading axes: runs (if any), then the sweep axes of sigmas, assumed_sigmas and
        p0_variance broadcast together.
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    sensors = model.sensor_names(sensors)
    C = model.observation_matrix(sensors)
    defaults = {"vision": scenario.sigma_v, "proprioception": scenario.sigma_p}
    if sigmas is None:
        sigmas = [defaults[s] for s in sensors]
    sigmas = validation.positive_array("sigmas", sigmas, "cm", min_ndim=1)
    assumed = sigmas if assumed_sigmas is None else validation.positive_array(
        "assumed_sigmas", assumed_sigmas, "cm", min_ndim=1)
    for name, value in (("sigmas", sigmas), ("assumed_sigmas", assumed)):
        if value.shape[-1] != len(sensors):
            raise ValueError(
                f"{name} must have one σ per sensor {sensors} on its last axis, "
                f"got shape {value.shape}"
            )
    p0 = validation.positive_array(
        "p0_variance", scenario.p0_variance if p0_variance is None else p0_variance, "cm²")
    sweep = validation.broadcast_batches(
        sigmas=sigmas.shape[:-1], assumed_sigmas=assumed.shape[:-1], p0_variance=p0.shape
    )
    if noise is None:
        noise = scenario.unit_noise(runs, sensors)
    expected = (scenario.n_steps, len(sensors)) if runs is None else (
        runs, scenario.n_steps, len(sensors))
    noise = validation.shaped_array("noise", noise, expected, ", ".join(sensors))
    noise = noise.reshape(noise.shape[:-2] + (1,) * len(sweep) + noise.shape[-2:])
    y = simulation.measure(scenario.truth[:, 0], noise, sigmas)
    result = kalman_filter(
        y, scenario.A, C, scenario.Q, model.measurement_noise_covariance(assumed),
        np.asarray(scenario.z0, float), model.diagonal_covariance(p0),
    )
    return Tracking(scenario, sensors, y, result)


@dataclass(frozen=True)
class DelayedTracking:
    """Question (e): the filter fed a signal that arrives ``steps`` samples late.

    All arrays are on the wall-clock time axis: sample j is what the observer has at
    time j·Δt. The first δ samples are NaN: nothing has arrived yet.

    Attributes
    ----------
    tracking : Tracking
        The filter run on the measurement stream (indexed by when it was sensed).
    steps : int
        The delay δ in samples.
    delayed_measurements : ndarray, shape (..., n, m)
        ``y_{j−δ}``, the reading available at time j.
    delayed_estimates : ndarray, shape (..., n, 3)
        ``ẑ_{j−δ}``, the newest estimate at time j, uncompensated (Tutorial eq. (8)).
    predictions : ndarray, shape (..., n, 3)
        ``z*_j = A^δ ẑ_{j−δ}``, the compensated estimate (Tutorial eq. (7)).
    """

    tracking: Tracking
    steps: int
    delayed_measurements: np.ndarray
    delayed_estimates: np.ndarray
    predictions: np.ndarray

    def mse(self, which: str) -> np.ndarray:
        """Per-run position MSE (cm²) of ``"delayed"`` or ``"predicted"`` estimates.

        Skips the scenario's burn-in or the delay, whichever is longer.
        """
        arrays = {"delayed": self.delayed_estimates, "predicted": self.predictions}
        if not isinstance(which, str) or which not in arrays:
            raise ValueError(f"which must be one of {tuple(arrays)}, got {which!r}")
        scenario = self.tracking.scenario
        skip = max(scenario.burn_in_steps, self.steps)
        return metrics.mse(arrays[which][..., 0], scenario.truth[:, 0], skip)


def delay_and_compensate(tracking: Tracking, delay: float) -> DelayedTracking:
    """Delay a tracking experiment's signal by ``delay`` s and compensate by prediction.

    Parameters
    ----------
    tracking : Tracking
        A filter run, e.g. ``track(scenario, runs=...)``.
    delay : float
        Sensory delay d in s, a whole number of time steps (δ = d / Δt).
    """
    validation.instance("tracking", tracking, Tracking, "from track()")
    scenario = tracking.scenario
    steps = scenario.delay_steps(delay)
    estimates = tracking.result.estimates
    return DelayedTracking(
        tracking=tracking,
        steps=steps,
        delayed_measurements=simulation.delay_signal(tracking.measurements, steps),
        delayed_estimates=simulation.delay_signal(estimates, steps),
        predictions=predict_ahead(estimates, scenario.A, steps),
    )
