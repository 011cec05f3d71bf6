"""The filter with the biased signal as input, and its runs (notebook 06 and its explorer).

The model the filter assumes (Lesson 0.5 eqs. (4)–(9)) is assembled inside this module,
for its runs (:attr:`UnbiasedRun.model`); the butterfly's model has its one builder,
:func:`lqe_helpers.experiments.filter_model`. A run is made in one place,
:func:`unbiased_run`, for notebook 06 (through :func:`track_with_input`) and for the
explorer alike. The filter is linear in its input, so the run at a true bias b is the
run at b = 0 plus b times the response to a unit input (:meth:`UnbiasedRun.at_bias`):
both come out of one filter call (one Riccati recursion, two estimate sequences), and
a slider that moves b only adds them again.

Each public function checks its inputs once, at its entry.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .. import _engine, _matrices, metrics, validation
from ..experiments import FilterModel
from ..filter import FilterResult
from ..scenario import Scenario
from .equations import (
    DEFAULT_BIAS,
    DEFAULT_SIGMA_A,
    NOISE_COLUMNS,
    acceleration_readings,
    dead_reckoning,
    initial_state,
    input_matrix,
    step_accelerations,
    transition_matrix,
    true_states,
    unit_noise,
)

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: The filter's prior standard deviation of the bias (cm/s²): the observer allows
#: offsets up to about half the peak acceleration before it has seen anything.
DEFAULT_BIAS_PRIOR_STD = 50.0
#: Most batches per panel of :meth:`InputTracking.settling_figure` (its painter's line styles).
MAX_SETTLING_CURVES = 6


def _assemble(scenario: Scenario, sigma_a: float, sigma_v: float,
              bias_prior_std: float) -> FilterModel:
    """The model the filter of :func:`track_with_input` assumes, from checked inputs.

    ``A = F`` and ``B = G`` (Lesson 0.5 eq. (5)), ``Q = G σ_a² Gᵀ`` (eq. (9)),
    ``C = [1, 0, 0]``, ``R = σ_v²``, ``z0 = [0, 0, 0]`` and
    ``P0 = diag(A², (A·2πf)², bias_prior_std²)``: one amplitude A for position, the
    path's peak speed for velocity. σ_a (cm/s²), σ_v (cm) and ``bias_prior_std``
    (cm/s²) already checked (:func:`_checked`).
    """
    dt = scenario.dt
    g = input_matrix(dt)
    return FilterModel(
        A=transition_matrix(dt), C=_matrices.observation(1),
        Q=_matrices.input_noise_covariance(g, sigma_a),
        R=_matrices.noise_covariance(np.array([sigma_v])), z0=np.zeros(3),
        P0=np.diag([scenario.amplitude**2, scenario.peak_speed**2, bias_prior_std**2]), B=g,
    )


def _checked(scenario: Scenario, sigma_a: float, sigma_v: float | None,
             bias_prior_std: float) -> tuple[float, float, float]:
    """σ_a (cm/s²), σ_v (cm; None: the scenario's) and the prior σ (cm/s²), checked."""
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    return (validation.positive("sigma_a", sigma_a, "cm/s²"),
            validation.positive("sigma_v", scenario.sigma_v if sigma_v is None else sigma_v,
                                "cm"),
            validation.positive("bias_prior_std", bias_prior_std, "cm/s²"))


@dataclass(frozen=True)
class InputTracking:
    """The hand tracked from vision plus a biased acceleration input.

    Attributes
    ----------
    scenario : Scenario
    bias, sigma_a, sigma_v : float
        True bias (cm/s²), the signal's noise σ_a (cm/s²) and vision's σ_v (cm).
    truth : ndarray, shape (n, 3)
        True ``[p, v, b]``.
    readings : ndarray, shape (..., n)
        The acceleration signal u (cm/s²).
    measurements : ndarray, shape (..., n, 1)
        Vision's position readings (cm).
    result : FilterResult
        The filter's estimates ``[p̂, v̂, b̂]``, gains and covariances.
    dead_reckoning : ndarray, shape (..., n, 3)
        The signal integrated from the true start with no vision and b̂ = 0.
    """

    scenario: Scenario
    bias: float
    sigma_a: float
    sigma_v: float
    truth: np.ndarray
    readings: np.ndarray
    measurements: np.ndarray
    result: FilterResult
    dead_reckoning: np.ndarray

    @property
    def positions(self) -> np.ndarray:
        """Filtered positions p̂ (cm), shape (..., n)."""
        return self.result.estimates[..., 0]

    @property
    def bias_estimates(self) -> np.ndarray:
        """Bias estimates b̂ (cm/s²), shape (..., n)."""
        return self.result.estimates[..., 2]

    @property
    def bias_stds(self) -> np.ndarray:
        """The filter's own standard deviation of b̂ (cm/s²), shape (..., n)."""
        return np.sqrt(self.result.estimate_covariances[..., 2, 2])

    @property
    def position_stds(self) -> np.ndarray:
        """The filter's own standard deviation of p̂ (cm), shape (..., n)."""
        return np.sqrt(self.result.estimate_covariances[..., 0, 0])

    def mse(self) -> np.ndarray:
        """Per-run MSE (cm²) of the filtered position after the burn-in, shape (...)."""
        return metrics.mse(self.positions, self.truth[:, 0], self.scenario.burn_in_steps)

    def bias_rms_error(self) -> np.ndarray:
        """Root-mean-square error of b̂ over the runs (axis 0) against time (cm/s²), (..., n)."""
        return np.sqrt(np.mean((self.bias_estimates - self.bias) ** 2, axis=0))

    def learning_figure(self, runs: InputTracking) -> Figure:
        """Notebook 06's Figure 1: this run's b̂ with its band, and the runs' error of b̂.

        Built by :func:`lqe_helpers.figures.bias_learning_figure`, so a notebook passes
        two results instead of six arrays.

        Parameters
        ----------
        runs : InputTracking
            Monte Carlo runs (one leading axis) of the same scenario, bias and σ's:
            their RMS error of b̂ (:meth:`bias_rms_error`) and the filter's own σ of it.

        Raises
        ------
        ValueError
            If this tracking is not a single run, or ``runs`` is not a batch of runs of
            the same experiment.
        """
        from .. import figures

        if self.bias_estimates.ndim != 1:
            raise ValueError(f"learning_figure draws a single run: this tracking has leading "
                             f"axes {self.bias_estimates.shape[:-1]}")
        if not (isinstance(runs, InputTracking) and runs.bias_estimates.ndim == 2
                and (runs.scenario, runs.bias, runs.sigma_a, runs.sigma_v)
                == (self.scenario, self.bias, self.sigma_a, self.sigma_v)):
            raise ValueError(
                "runs must be an InputTracking of Monte Carlo runs (one leading axis) of "
                "this run's scenario, bias, sigma_a and sigma_v, got "
                f"{type(runs).__name__}")
        return figures.bias_learning_figure(self.scenario.times, self.bias_estimates,
                                            self.bias_stds, self.bias, runs.bias_rms_error(),
                                            runs.bias_stds[0])

    def signal_figure(self) -> Figure:
        """Notebook 06's Figure 3: this run's acceleration signal beside a and a + b.

        Built by :func:`lqe_helpers.figures.acceleration_signal_figure` from this run's
        readings, the scenario's true mean acceleration per step
        (:func:`~lqe_helpers.bias_model.equations.step_accelerations`) and the true bias.

        Raises
        ------
        ValueError
            If this tracking is not a single run.
        """
        from .. import figures

        if self.readings.ndim != 1:
            raise ValueError(f"signal_figure draws a single run: this tracking has leading "
                             f"axes {self.readings.shape[:-1]}")
        return figures.acceleration_signal_figure(self.scenario.times, self.readings,
                                                  step_accelerations(self.scenario), self.bias)

    @staticmethod
    def settling_figure(by_bias: Mapping[float, InputTracking],
                        by_sigma_v: Mapping[float, InputTracking]) -> Figure:
        """Notebook 06's Figure 6: how b̂ settles, by true bias and by vision's noise.

        Built by :func:`lqe_helpers.figures.bias_settling_figure`: left, each batch of
        ``by_bias``: its runs' mean error of b̂ (labelled "b = 20 cm/s²", …); right, each
        batch of ``by_sigma_v``: the filter's own σ of b̂, the same in every run
        (labelled "σ_v = 1.5 cm", …).

        Parameters
        ----------
        by_bias : mapping of float to InputTracking
            True bias b (cm/s²) → Monte Carlo runs (one leading axis) at that bias, 1 to
            :data:`MAX_SETTLING_CURVES` of them, in the order drawn.
        by_sigma_v : mapping of float to InputTracking
            σ_v (cm) → Monte Carlo runs at that vision noise, likewise.

        Raises
        ------
        ValueError
            If a mapping holds no batch or too many, a key is not its batch's b or σ_v, a
            value is not Monte Carlo runs, or the batches are of different scenarios.
        """
        from .. import figures

        by_bias = _batches("by_bias", by_bias, "bias", "true bias b (cm/s²)")
        by_sigma_v = _batches("by_sigma_v", by_sigma_v, "sigma_v", "σ_v (cm)")
        scenario = by_bias[0].scenario
        if any(batch.scenario != scenario for batch in by_sigma_v):
            raise ValueError("by_sigma_v must hold runs of the scenario of by_bias's runs")
        return figures.bias_settling_figure(
            scenario.times,
            {f"b = {batch.bias:g} cm/s²": np.mean(batch.bias_estimates - batch.bias, axis=0)
             for batch in by_bias},
            {f"σ_v = {batch.sigma_v:g} cm": batch.bias_stds[0] for batch in by_sigma_v})

    def dead_reckoning_mse(self) -> np.ndarray:
        """Per-run MSE (cm²) of the dead-reckoned position after the burn-in, shape (...)."""
        return metrics.mse(self.dead_reckoning[..., 0], self.truth[:, 0],
                           self.scenario.burn_in_steps)


def _batches(name: str, batches: object, attribute: str, what: str) -> list[InputTracking]:
    """``batches``' values, checked: 1 to :data:`MAX_SETTLING_CURVES` Monte Carlo runs of
    one scenario, each under the key of its own ``attribute`` (to 1e-9)."""
    items = list(batches.items()) if isinstance(batches, Mapping) else []
    if not 1 <= len(items) <= MAX_SETTLING_CURVES or not all(
            isinstance(key, numbers.Real) and not isinstance(key, bool)
            and isinstance(batch, InputTracking) and batch.bias_estimates.ndim == 2
            and batch.scenario == items[0][1].scenario
            and abs(float(key) - getattr(batch, attribute)) <= 1e-9 for key, batch in items):
        got = ([f"{key!r}: {type(batch).__name__}" for key, batch in items]
               if isinstance(batches, Mapping) else type(batches).__name__)
        raise ValueError(
            f"{name} must map each {what} to Monte Carlo runs at that value (an "
            f"InputTracking with one leading axis, all of one scenario), 1 to "
            f"{MAX_SETTLING_CURVES} of them, got {got}")
    return [batch for _, batch in items]


@dataclass(frozen=True)
class UnbiasedRun:
    """The filter of :func:`track_with_input` on a signal with no bias, and its unit response.

    Everything a true bias b changes is a multiple of b: the signal is ``a_r + b``
    (Lesson 0.5 eq. (2)), and the filter is linear in its input and starts from
    ``z0 = 0``, so its estimates are those at b = 0 plus b times the estimates of a
    filter that sees no measurement and an input of 1 cm/s² at every step.
    :meth:`at_bias` makes the run at any b from these.

    Attributes
    ----------
    scenario : Scenario
    sigma_a, sigma_v, bias_prior_std : float
        The signal's noise (cm/s²), vision's noise (cm) and the filter's prior σ of the
        bias (cm/s²).
    measurements : ndarray, shape (..., n, 1)
        Vision's position readings (cm); they do not depend on b.
    readings : ndarray, shape (..., n)
        The acceleration signal at b = 0 (cm/s²).
    result : FilterResult
        The filter's run at b = 0.
    unit_response : ndarray, shape (n, 3)
        The estimates ``[p̂, v̂, b̂]`` for no measurement and a unit input (cm/s², per cm/s²
        of bias).
    model : FilterModel
        The model the filter assumed (A = F, B = G, Q = G σ_a² Gᵀ, C, R = σ_v², z0, P0).
    """

    scenario: Scenario
    sigma_a: float
    sigma_v: float
    bias_prior_std: float
    measurements: np.ndarray
    readings: np.ndarray
    result: FilterResult
    unit_response: np.ndarray
    model: FilterModel

    def at_bias(self, bias: float) -> InputTracking:
        """The run of :func:`track_with_input` at true bias ``bias`` (cm/s², any sign).

        Equal to the filter run on the biased signal to rounding (1e-9,
        ``tests/bias_model/test_bias_model.py``); dead reckoning integrates the biased signal.

        Raises
        ------
        ValueError
            If ``bias`` is not a finite number.
        """
        return self._at(validation.finite_number("bias", bias, "cm/s²"))

    def _at(self, bias: float) -> InputTracking:
        """:meth:`at_bias` of a bias already checked."""
        scenario = self.scenario
        readings = self.readings + bias
        result = FilterResult(
            estimates=self.result.estimates + bias * self.unit_response,
            gains=self.result.gains,
            covariances=self.result.covariances,
            estimate_covariances=self.result.estimate_covariances,
        )
        drift = dead_reckoning(readings, initial_state(scenario, bias), scenario.dt)
        return InputTracking(scenario, bias, self.sigma_a, self.sigma_v,
                             true_states(scenario, bias), readings, self.measurements, result,
                             drift)


def unbiased_run(scenario: Scenario, sigma_a: float = DEFAULT_SIGMA_A,
                 sigma_v: float | None = None,
                 bias_prior_std: float = DEFAULT_BIAS_PRIOR_STD, runs: int | None = None,
                 noise: np.ndarray | None = None) -> UnbiasedRun:
    """Simulate vision and the signal at b = 0, and filter both it and a unit input.

    One call of the filter of :func:`_assemble` on the runs and one more run (no
    measurement, an input of 1 cm/s² at every step): they share the gains.

    Parameters
    ----------
    scenario : Scenario
        The hand's path, Δt, seed and burn-in.
    sigma_a : float
        Noise σ_a of the signal in cm/s², > 0; the filter's Q uses the same value.
    sigma_v : float, optional
        Vision noise σ_v in cm, > 0. Default: the scenario's.
    bias_prior_std : float
        The filter's prior standard deviation of the bias in cm/s², > 0.
    runs : int, optional
        Monte Carlo runs; None for the single run shown in figures (run 0).
    noise : array_like, shape (n, 2) or (runs, n, 2), optional
        Unit noise ``[vision, acceleration]``; default :func:`unit_noise`. Explorers
        pass a draw they keep, so a slider never changes the noise pattern.

    Returns
    -------
    UnbiasedRun
        Leading axis: runs, if any.
    """
    sigma_a, sigma_v, bias_prior_std = _checked(scenario, sigma_a, sigma_v, bias_prior_std)
    if noise is None:
        noise = unit_noise(scenario, runs)
    expected = (scenario.n_steps, 2) if runs is None else (runs, scenario.n_steps, 2)
    noise = validation.shaped_array("noise", noise, expected, ", ".join(NOISE_COLUMNS))
    # Everything is checked above: the engine's core checks nothing again, so a
    # slider's σ_v is checked once on its way to the filter.
    measurements = _engine.readings(scenario.truth[:, 0], noise[..., :1], np.array([sigma_v]))
    readings = acceleration_readings(step_accelerations(scenario), 0.0, sigma_a,
                                     noise[..., 1])
    # The runs, then one more: no measurement and a unit input, filtered together.
    n, batch = scenario.n_steps, measurements.shape[:-2]
    y = np.concatenate([measurements.reshape(-1, n, 1), np.zeros((1, n, 1))])
    u = np.concatenate([readings.reshape(-1, n, 1), np.ones((1, n, 1))])
    model = _assemble(scenario, sigma_a, sigma_v, bias_prior_std)
    both = _engine.filter_run(y, model.A, model.C, model.Q, model.R, model.z0, model.P0,
                              B=model.B, u=u)

    def runs_only(array: np.ndarray) -> np.ndarray:
        return array[:-1].reshape(*batch, *array.shape[1:])

    result = FilterResult(*(runs_only(getattr(both, name)) for name in (
        "estimates", "gains", "covariances", "estimate_covariances")))
    return UnbiasedRun(scenario, sigma_a, sigma_v, bias_prior_std, measurements, readings,
                       result, both.estimates[-1], model)


def track_with_input(scenario: Scenario, bias: float = DEFAULT_BIAS,
                     sigma_a: float = DEFAULT_SIGMA_A, sigma_v: float | None = None,
                     bias_prior_std: float = DEFAULT_BIAS_PRIOR_STD,
                     runs: int | None = None, noise: np.ndarray | None = None
                     ) -> InputTracking:
    """Simulate vision and the biased signal, then filter with the signal as input.

    The filter is :func:`~lqe_helpers.filter.kalman_filter` with ``A = F``, ``B = G``
    (Lesson 0.5 eq. (5)), ``Q = G σ_a² Gᵀ`` (eq. (9)), ``C = [1, 0, 0]`` and
    ``R = σ_v²`` (:func:`_assemble`). It starts from ``z0 = [0, 0, 0]`` with prior
    standard deviations of one amplitude A for position, the path's peak speed A·2πf
    for velocity and ``bias_prior_std`` for the bias: the observer knows the range of
    the movement and roughly how large a bias can be, nothing more. Made as
    ``unbiased_run(...).at_bias(bias)``, the path the explorer takes too.

    Parameters
    ----------
    scenario : Scenario
        The hand's path, Δt, seed and burn-in.
    bias : float
        True constant bias b of the signal in cm/s² (any sign).
    sigma_a : float
        True noise σ_a of the signal in cm/s², > 0; the filter's Q uses the same value.
    sigma_v : float, optional
        Vision noise σ_v in cm, > 0. Default: the scenario's.
    bias_prior_std : float
        The filter's prior standard deviation of the bias in cm/s², > 0.
    runs : int, optional
        Monte Carlo runs; None for the single run shown in figures (run 0).
    noise : array_like, shape (n, 2) or (runs, n, 2), optional
        Unit noise ``[vision, acceleration]``; default :func:`unit_noise`.

    Returns
    -------
    InputTracking
        Leading axis: runs, if any.
    """
    bias = validation.finite_number("bias", bias, "cm/s²")
    return unbiased_run(scenario, sigma_a, sigma_v, bias_prior_std, runs, noise)._at(bias)
