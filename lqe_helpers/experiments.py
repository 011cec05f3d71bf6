"""The tutorial's experiments, built from a :class:`~lqe_helpers.scenario.Scenario`.

Notebooks, explorers and checks call these instead of assembling C, R, P0 and noise
by hand, so a question's setup is written once: :func:`filter_model` is the one
builder of the model a filter assumes (A, C, Q, R, z0, P0), :func:`track` simulates
the sensors and runs that filter, :func:`delay_and_compensate` delays its output.
Their results draw their own figures through :mod:`lqe_helpers.figures`
(:meth:`Tracking.figure`, ``.error_figure`` and those of :mod:`lqe_helpers.tracking_figures`,
:meth:`DelayedTracking.figure`); :mod:`lqe_helpers.own_runs` wraps a student's arrays in them.

Each public function checks its inputs once, at its entry (:mod:`._matrices` checks nothing again).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from . import _engine, _matrices, metrics, model, simulation, validation
from .filter import FilterResult, kalman_filter
from .prediction import predict_ahead
from .scenario import Scenario
from .steady_state import SteadyState, steady_state
from .tracking_figures import TrackingFigures

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Roles of the estimates :meth:`Tracking.figure` compares with its own, in order.
COMPARISON_ROLES = ("alternative", "reference")


@dataclass(frozen=True)
class FilterModel:
    """The model a filter assumes: what :func:`~lqe_helpers.filter.kalman_filter` takes.

    Built by :func:`filter_model` (the butterfly, Tutorial eqs. (1)–(6)), and inside
    :func:`lqe_helpers.bias_model.unbiased_run` (a known input, Lesson 0.5 eqs. (4)–(9)).
    Its arrays are read-only: one model may serve many runs.

    Attributes
    ----------
    A : ndarray, shape (k, k)
        Transition matrix.
    C : ndarray, shape (m, k)
        Observation matrix.
    Q : ndarray, shape (k, k)
        Process noise covariance.
    R : ndarray, shape (..., m, m)
        Sensor noise covariance (cm²); leading axes sweep σ.
    z0 : ndarray, shape (k,)
        Initial estimate.
    P0 : ndarray, shape (..., k, k)
        Initial covariance; leading axes sweep P0.
    B : ndarray, shape (k, p), or None
        Input matrix, for a filter driven by a known input.

    :meth:`filter` checks the readings it is given (and the model) through
    :func:`~lqe_helpers.filter.kalman_filter`. :meth:`steady_state` of a model made by
    :func:`filter_model` (which checked its inputs) runs the engine's core directly; of
    one made by hand (or changed with :func:`dataclasses.replace`), the checked
    :func:`~lqe_helpers.steady_state.steady_state`.
    """

    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    z0: np.ndarray
    P0: np.ndarray
    B: np.ndarray | None = None
    #: True only for a model :func:`filter_model` built from checked inputs (not an
    #: argument, so neither a caller nor :func:`dataclasses.replace` can set it).
    _checked: bool = field(default=False, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("A", "C", "Q", "R", "z0", "P0", "B"):
            value = getattr(self, name)
            if value is not None:
                array = np.array(value, dtype=float)
                array.flags.writeable = False
                object.__setattr__(self, name, array)

    def filter(self, y: np.ndarray, u: np.ndarray | None = None) -> FilterResult:
        """:func:`~lqe_helpers.filter.kalman_filter` of ``y`` (..., n, m) with this model.

        ``u`` (..., n, p) is the known input, for a model with ``B``.
        """
        return kalman_filter(y, self.A, self.C, self.Q, self.R, self.z0, self.P0,
                             B=self.B, u=u)

    def steady_state(self) -> SteadyState:
        """The filter's steady state (:func:`~lqe_helpers.steady_state.steady_state`).

        Of a model :func:`filter_model` built, the engine's core without a second
        check of its matrices (an explorer asks for it on every slider move).
        """
        if self._checked:
            return SteadyState(*_engine.riccati(self.A, self.C, self.Q, self.R))
        return steady_state(self.A, self.C, self.Q, self.R)


@dataclass(frozen=True)
class Tracking(TrackingFigures):
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
    model : FilterModel
        The model the filter assumed (its R from the assumed σ).
    """

    scenario: Scenario
    sensors: tuple[str, ...]
    measurements: np.ndarray
    result: FilterResult
    model: FilterModel

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

    def innovations(self) -> metrics.Innovations:
        """Each reading minus the filter's prediction of it, with its covariance S_j.

        What an observer can check without the true path
        (:func:`~lqe_helpers.metrics.innovations`; :func:`~lqe_helpers.metrics.nis_test`
        of the result says whether the filter's model is consistent with its readings).
        Values (..., n, m) in cm, covariances (..., n, m, m) in cm².
        """
        return metrics.innovations(self.measurements, self.result, self.model.A,
                                   self.model.C, self.model.z0)

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

    def figure(self, label: str = "filtered estimate", *,
               against: Mapping[str, Tracking] | None = None, readings: bool = True,
               title: str = "", run: int | tuple[int, ...] | None = None,
               reading_labels: Mapping[str, str] | None = None) -> Figure:
        """This run's estimate beside the truth, its error below: the standard figure.

        Built by :func:`lqe_helpers.figures.tracking_comparison_figure`, so a notebook
        passes one object instead of six arrays.

        Parameters
        ----------
        label : str
            Legend label of this tracking's estimate (drawn blue, the estimate's role).
        against : mapping of str to Tracking, optional
            Other filters' runs of the same scenario to compare, by legend label (at
            most two; drawn in the roles of :data:`COMPARISON_ROLES`, before this one).
        readings : bool
            Whether to draw this run's sensor readings ("vision readings", …).
        title : str
            Title of the top panel (say what changed, e.g. "σ_v = 1.5 cm").
        run : int or tuple of int, optional
            Which run of a batch (an index into the leading axes, the same in every
            tracking); required when there are leading axes.
        reading_labels : mapping of str to str, optional
            Legend label of a sensor's readings, by sensor (e.g. ``{"vision": "noisy
            vision"}``); default "<sensor> readings".

        Returns
        -------
        matplotlib.figure.Figure

        Raises
        ------
        ValueError
            If ``run`` does not pick one run, or ``against`` holds anything but at most
            two trackings of this scenario.
        """
        from . import figures

        against = dict(against or {})
        if len(against) > len(COMPARISON_ROLES) or not all(
                isinstance(other, Tracking) and other.scenario == self.scenario
                for other in against.values()):
            raise ValueError(
                f"against must map labels to at most {len(COMPARISON_ROLES)} Trackings of "
                f"this scenario, got {[type(other).__name__ for other in against.values()]}")
        estimates = {name: (validation.one_run(other.positions, run), role)
                     for (name, other), role in zip(against.items(),
                                                     COMPARISON_ROLES[:len(against)],
                                                     strict=True)}
        estimates[label] = (validation.one_run(self.positions, run), "estimate")
        shown = None
        if readings:
            measured = validation.one_run(self.measurements, run, trailing=2)
            names = dict(reading_labels or {})
            shown = {names.get(sensor, f"{sensor} readings"): (measured[:, column], sensor)
                     for column, sensor in enumerate(self.sensors)}
        return figures.tracking_comparison_figure(self.scenario.times, self.scenario.truth[:, 0],
                                                  estimates, readings=shown, title=title)

    def error_figure(self, noise_free: Mapping[float, np.ndarray], *,
                     run: int | tuple[int, ...] | None = 0) -> Figure:
        """:func:`lqe_helpers.systematic_error.error_figure` of this sweep over σ_v and
        ``noise_free`` (σ_v → noise-free positions (cm), (n,)): run ``run``'s errors."""
        from . import systematic_error
        return systematic_error.error_figure(self, noise_free, run=run)


def _sensor_sigmas(name: str, sigmas: object, sensors: tuple[str, ...]) -> np.ndarray:
    """``sigmas`` (cm) as an array of shape (..., m): finite, > 0, one σ per sensor."""
    sigmas = validation.positive_array(name, sigmas, "cm", min_ndim=1)
    if sigmas.shape[-1] != len(sensors):
        raise ValueError(
            f"{name} must have one σ per sensor {sensors} on its last axis, "
            f"got shape {sigmas.shape}"
        )
    validation.in_float_range(
        f"{name} (largest {np.max(sigmas):g} cm, smallest {np.min(sigmas):g} cm)",
        lambda: sigmas**2, positive=True)
    return sigmas


def _assemble(scenario: Scenario, sensors: tuple[str, ...], sigmas: np.ndarray,
              p0_variance: np.ndarray) -> FilterModel:
    """The model of :func:`filter_model` from inputs its caller has checked."""
    built = FilterModel(
        A=scenario.A, C=_matrices.observation(len(sensors)), Q=scenario.Q,
        R=_matrices.noise_covariance(sigmas), z0=np.asarray(scenario.z0, dtype=float),
        P0=_matrices.scaled_identity(p0_variance, 3),
    )
    object.__setattr__(built, "_checked", True)
    return built


def filter_model(scenario: Scenario, sensors: Sequence[str] = ("vision",),
                 sigmas: Sequence[float] | np.ndarray | None = None,
                 p0_variance: float | np.ndarray | None = None) -> FilterModel:
    """The model a filter of the butterfly assumes (Tutorial eqs. (1)–(6)): the one builder.

    ``A`` and ``Q`` of the scenario's Δt and σ_j, ``C`` with one row ``[1, 0, 0]`` per
    sensor (eq. (3)), ``R = diag(σ²)`` (eq. (6)), ``z0`` of the scenario and
    ``P0 = p0_variance · I``. :func:`track` runs the filter with this model; its
    :meth:`~FilterModel.steady_state` gives the theory the notebooks compare with.

    Parameters
    ----------
    scenario : Scenario
        Supplies Δt, Q, z0 and the defaults.
    sensors : sequence of str
        ``("vision",)`` or ``("vision", "proprioception")``.
    sigmas : array_like, shape (..., m), optional
        The σ the filter assumes for each sensor (cm), > 0; default the scenario's σ_v
        and σ_p. Leading axes sweep σ (a stack of R).
    p0_variance : float or array_like, shape (...), optional
        P0 = p0_variance · I (cm², cm²/s², cm²/s⁴), > 0; default the scenario's. An
        array sweeps P0 (a stack of P0), broadcasting against the sweep of σ.

    Returns
    -------
    FilterModel

    Raises
    ------
    ValueError
        If an input is of the wrong kind, shape or range.
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    sensors = model.sensor_names(sensors)
    if sigmas is None:
        sigmas = _default_sigmas(scenario, sensors)
    sigmas = _sensor_sigmas("sigmas", sigmas, sensors)
    p0 = validation.positive_array(
        "p0_variance", scenario.p0_variance if p0_variance is None else p0_variance, "cm²")
    validation.broadcast_batches(sigmas=sigmas.shape[:-1], p0_variance=p0.shape)
    return _assemble(scenario, sensors, sigmas, p0)


def _default_sigmas(scenario: Scenario, sensors: tuple[str, ...]) -> list[float]:
    """The scenario's σ of each sensor (cm)."""
    return [scenario.sigma_v if sensor == "vision" else scenario.sigma_p for sensor in sensors]


def readings(scenario: Scenario, sensors: Sequence[str] = ("vision",),
             sigmas: Sequence[float] | np.ndarray | None = None) -> np.ndarray:
    """The sensors' readings of the scenario's trial, unfiltered (Tutorial eq. (3)).

    ``y = p + σ · noise`` on the scenario's fixed draw (run 0): the ``measurements`` of
    :func:`track` with the same arguments, without a filter or its model.

    Parameters
    ----------
    scenario : Scenario
        Supplies the true path and the draw.
    sensors : sequence of str
        ``("vision",)`` or ``("vision", "proprioception")``.
    sigmas : array_like, shape (m,), optional
        Noise σ of each sensor (cm), > 0. Default: the scenario's σ_v and σ_p.

    Returns
    -------
    numpy.ndarray, shape (n, m)
        The readings (cm), one column per sensor.
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    sensors = model.sensor_names(sensors)
    sigmas = _sensor_sigmas("sigmas", _default_sigmas(scenario, sensors) if sigmas is None
                            else sigmas, sensors)
    if sigmas.ndim != 1:
        raise ValueError(f"sigmas must be one σ per sensor {sensors}, shape "
                         f"({len(sensors)},), got shape {sigmas.shape}: sweep σ with track")
    return _engine.readings(scenario.truth[:, 0], scenario.unit_noise(None, sensors), sigmas)


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
        p0_variance broadcast together. Its ``model`` is :func:`filter_model` of the
        assumed σ and P0.
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    sensors = model.sensor_names(sensors)
    if sigmas is None:
        sigmas = _default_sigmas(scenario, sensors)
    sigmas = _sensor_sigmas("sigmas", sigmas, sensors)
    assumed = sigmas if assumed_sigmas is None else _sensor_sigmas(
        "assumed_sigmas", assumed_sigmas, sensors)
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
    # Everything is checked above: the engine's core checks nothing again (R is not
    # factorised twice), so a slider's σ is checked once on its way to the filter.
    y = _engine.readings(scenario.truth[:, 0], noise, sigmas)
    filter_ = _assemble(scenario, sensors, assumed, p0)
    result = _engine.filter_run(y, filter_.A, filter_.C, filter_.Q, filter_.R, filter_.z0,
                                filter_.P0)
    return Tracking(scenario, sensors, y, result, filter_)


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
    A student's own run (:func:`lqe_helpers.own_runs.delayed`) holds positions only, (n, 1).
    """

    tracking: Tracking
    steps: int
    delayed_measurements: np.ndarray
    delayed_estimates: np.ndarray
    predictions: np.ndarray

    @property
    def delay(self) -> float:
        """The delay d = δ Δt (s)."""
        return self.steps * self.tracking.scenario.dt

    def figure(self, fast_window: tuple[float, float] = (3.75, 4.35), *,
               run: int | tuple[int, ...] | None = None) -> Figure:
        """Question (e)'s standard figure: truth, late readings, late and compensated estimate.

        Built by :func:`lqe_helpers.figures.delay_figure` (the whole trial, the start
        with nothing arrived yet shaded, and ``fast_window`` (s) of fast flight), so a
        notebook writes ``delayed.figure()`` instead of passing six arrays.

        ``fast_window``: (start, end) of the bottom-right zoom (s); ``run``: which run of a
        batch (an index into the leading axes), required when there are leading axes.
        Raises ValueError if ``run`` does not pick one run, or the delay is 0.
        """
        from . import figures

        scenario = self.tracking.scenario
        return figures.delay_figure(
            scenario.times, scenario.truth[:, 0],
            validation.one_run(self.delayed_measurements, run, trailing=2)[:, 0],
            validation.one_run(self.delayed_estimates, run, trailing=2)[:, 0],
            validation.one_run(self.predictions, run, trailing=2)[:, 0], self.delay, fast_window)

    def comparison_figure(self, title: str = "", *,
                          run: int | tuple[int, ...] | None = None) -> Figure:
        """The delayed and compensated estimates beside a perfect but late eye, errors below
        (:func:`lqe_helpers.figures.late_eye_figure`); ``run`` as in :meth:`figure`."""
        from . import figures

        truth = self.tracking.scenario.truth[:, 0]
        return figures.late_eye_figure(
            self.tracking.scenario.times, truth,
            validation.one_run(self.delayed_estimates, run, trailing=2)[:, 0],
            validation.one_run(self.predictions, run, trailing=2)[:, 0],
            simulation.delay_signal(truth, self.steps, axis=-1), title)

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
