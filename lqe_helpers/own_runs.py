"""A student's own arrays as the pack's results, so a notebook's figure is ``run.figure()``.

The notebooks' one-trial tasks make readings and estimates with the student's own
``my_filter`` and ``compensate``; the figures after them show exactly those arrays. These
functions check them once and wrap them in the results the pack's engine makes
(:class:`~lqe_helpers.experiments.Tracking`,
:class:`~lqe_helpers.experiments.DelayedTracking`,
:class:`~lqe_helpers.systematic_error.NoiseFreeOutputs`), which draw themselves: a notebook
passes one object, not six arrays. Nothing here estimates anything: the estimates are the
student's; the gains and covariances a result carries are the engine's for the same
readings and model (they do not depend on the readings), for a band or a gain only.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

import numpy as np

from . import experiments, model, validation
from .experiments import DelayedTracking
from .scenario import DEFAULT, Scenario
from .systematic_error import NoiseFreeOutputs, is_sigma_key, positions_by_sigma


def _columns(name: str, values: object, n: int, what: str) -> np.ndarray:
    """``values`` (n,) or (n, c) of real numbers (NaN allowed) as an (n, c) float array."""
    try:
        array = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an array of {what}, shape (n,) or (n, c) with "
                         f"n = {n}, got {type(values).__name__}") from None
    if array.ndim == 1:
        array = array[:, None]
    if array.ndim != 2 or array.shape[0] != n or array.shape[1] == 0:
        raise ValueError(f"{name} must be {what} of shape (n,) or (n, c) with n = {n}, got "
                         f"shape {np.shape(values)}")
    return array


def tracking(readings: np.ndarray, estimates: np.ndarray, *, scenario: Scenario = DEFAULT,
             sensors: Sequence[str] = ("vision",),
             sigmas: Sequence[float] | None = None) -> experiments.Tracking:
    """One trial of the student's filter as a :class:`~lqe_helpers.experiments.Tracking`.

    Parameters
    ----------
    readings : array_like, shape (n,) or (n, m)
        The trial's readings (cm), one column per sensor (``(n,)`` for one sensor).
    estimates : array_like, shape (n,) or (n, k)
        The student's estimates: positions (cm), or whole states whose column 0 is the
        position; finite.
    scenario : Scenario
        The trial's constants (times, true path, Δt).
    sensors : sequence of str
        The sensors of ``readings``' columns, e.g. ``("vision", "proprioception")``.
    sigmas : sequence of float, optional
        The σ (cm) of each sensor the filter assumed; default the scenario's.

    Returns
    -------
    Tracking
        ``positions`` and ``figure()`` are the student's; its model is
        :func:`~lqe_helpers.experiments.filter_model` of ``sigmas``.

    Raises
    ------
    ValueError
        If ``scenario`` is not a Scenario, a sensor is unknown, ``readings`` does not have
        one column per sensor and a row per time step, or ``estimates`` is not finite of
        shape (n,) or (n, k).
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    sensors = model.sensor_names(sensors)
    n = scenario.n_steps
    readings = _columns("readings", readings, n, "readings (cm)")
    if readings.shape[1] != len(sensors):
        raise ValueError(f"readings must have one column per sensor {sensors}, got shape "
                         f"{readings.shape}")
    estimates = _columns("estimates", estimates, n, "estimates (cm)")
    if not np.all(np.isfinite(estimates)):
        bad = estimates.size - np.count_nonzero(np.isfinite(estimates))
        raise ValueError(f"estimates must be finite numbers (cm), got {bad} NaN or infinite "
                         "values")
    built = experiments.filter_model(scenario, sensors, sigmas)
    result = dataclasses.replace(built.filter(readings), estimates=estimates)
    return experiments.Tracking(scenario, sensors, readings, result, built)


def delayed(run: experiments.Tracking, delay: float, late_readings: np.ndarray,
            delayed_positions: np.ndarray, compensated: np.ndarray) -> DelayedTracking:
    """The student's delayed and compensated trial as a :class:`DelayedTracking`.

    Parameters
    ----------
    run : Tracking
        The trial before the delay, e.g. :func:`tracking` of the student's readings and
        estimates.
    delay : float
        The delay d (s), a whole number of time steps δ = d / Δt.
    late_readings, delayed_positions, compensated : array_like, shape (n,)
        Positions (cm) on the wall-clock axis, NaN where nothing has arrived: the readings
        ``y_{j−δ}``, the delayed estimate ``ẑ_{j−δ}`` and the compensated estimate
        ``z*_j`` (Tutorial eqs. (7)–(8)).

    Returns
    -------
    DelayedTracking
        Holding positions only (arrays of shape (n, 1)); ``figure()`` and
        ``comparison_figure()`` draw them.

    Raises
    ------
    ValueError
        If ``run`` is not one trial's Tracking, ``delay`` is not a whole number of steps
        shorter than the trial, or a position array is not of shape (n,).
    """
    validation.instance("run", run, experiments.Tracking, "e.g. own_runs.tracking(...)")
    n = run.scenario.n_steps
    if run.positions.shape != (n,):
        raise ValueError(f"run must be one trial, positions of shape ({n},), got "
                         f"{run.positions.shape}")
    steps = run.scenario.delay_steps(delay)
    shifted = {}
    for name, values in (("late_readings", late_readings),
                         ("delayed_positions", delayed_positions),
                         ("compensated", compensated)):
        array = _columns(name, values, n, "positions (cm)")
        if array.shape != (n, 1):
            raise ValueError(f"{name} must be positions of shape ({n},), got shape "
                             f"{np.shape(values)}")
        shifted[name] = array
    return DelayedTracking(run, steps, shifted["late_readings"], shifted["delayed_positions"],
                           shifted["compensated"])


def noise_free(filtered: Mapping[float, np.ndarray], smoothed: Mapping[float, np.ndarray],
               alphas: Mapping[float, float], *,
               scenario: Scenario = DEFAULT) -> NoiseFreeOutputs:
    """The student's filter and smoother fed noise-free readings, as :class:`NoiseFreeOutputs`.

    Notebook 01's Figure 4: ``.figure(window)`` draws both beside the true path.

    Parameters
    ----------
    filtered : mapping
        σ_v (cm) → the positions (cm), shape (n,), of ``my_filter`` fed the true positions
        with R = [[σ_v²]].
    smoothed : mapping
        The same σ_v → the exponential smoother's output (cm), shape (n,), on the true
        positions with that σ_v's weight.
    alphas : mapping
        The same σ_v → the smoother's weight α, in (0, 1].
    scenario : Scenario
        The trial's constants (times, true path).

    Returns
    -------
    NoiseFreeOutputs
        By σ_v: "LQE (your my_filter)" (the estimate's role), then "exponential smoother,
        α = …" (the alternative's).

    Raises
    ------
    ValueError
        If ``scenario`` is not a Scenario, ``filtered`` does not map σ_v > 0 to finite
        positions of shape (n,), ``smoothed`` does not do so for the same σ_v, or
        ``alphas`` does not map them to numbers in (0, 1].
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    n = scenario.n_steps
    filtered = positions_by_sigma("filtered", filtered, n)
    smoothed = positions_by_sigma("smoothed", smoothed, n, list(filtered))
    weights = {float(sigma): alpha for sigma, alpha in alphas.items()
               if is_sigma_key(sigma)} if isinstance(alphas, Mapping) else {}
    if not weights or len(weights) != len(alphas) or sorted(weights) != sorted(filtered):
        raise ValueError("alphas must map each σ_v of filtered ("
                         + ", ".join(f"{sigma:g}" for sigma in filtered)
                         + f" cm) to a weight in (0, 1], got {alphas!r}")
    outputs = {}
    for (sigma, lqe), smooth in zip(filtered.items(), smoothed.values(), strict=True):
        alpha = validation.finite_number(f"alphas[{sigma:g}]", weights[sigma])
        if not 0 < alpha <= 1:
            raise ValueError(f"alphas[{sigma:g}] must be in (0, 1], got {alpha:g}")
        outputs[sigma] = {"LQE (your my_filter)": (lqe, "estimate"),
                          f"exponential smoother, α = {alpha:.2f}": (smooth, "alternative")}
    return NoiseFreeOutputs(scenario, outputs)
