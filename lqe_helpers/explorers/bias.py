"""Explorer of notebook 06: a biased acceleration signal corrected by vision.

Three sliders: the signal's true bias b, its noise σ_a and vision's noise σ_v.
Left panel: the filter's bias estimate converging to the true bias, with the ±2σ
band of its own covariance. Right panel: the hand's path, vision, the filtered
position and dead reckoning (the signal integrated without vision). The numbers of the
view (whose filter runs: the pack's; b, the bias estimate at the end of the trial, the
filtered MSE beside the vision-only filter's on the same camera noise, and how far dead
reckoning ends off the path) are not drawn in the figure: the drawing function returns
them as one line of text, which the explorer shows between the sliders and the picture.

Speed: building the axes, ticks and legends costs more than the filter run, so
:func:`draw_bias` builds the panels once per figure and afterwards only replaces the
data of the same artists. A move recomputes only what its slider changes: the
filter run depends on σ_a and σ_v alone, since the filter is linear in its input and
a move of b only shifts the estimates by b times the filter's response to a unit
input (:func:`~lqe_helpers.bias_model.unbiased_run`, the same path notebook 06's
:func:`~lqe_helpers.bias_model.track_with_input` takes). The explorer keeps the run
of the last (σ_a, σ_v) only (:class:`~lqe_helpers.explorers.cache.LastResults`), and the
vision-only filter's MSE of the last σ_v: going back to a σ pays for its filter run again.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial

import numpy as np
from matplotlib.figure import Figure

from .. import bias_model, experiments
from ..figures.bias import (  # noqa: F401  (the labels and axes, found here too)
    BIAS_AXIS,
    BIAS_BAND_LABEL,
    BIAS_ESTIMATE_LABEL,
    BIAS_TICK,
    BIAS_TITLE,
    DEAD_RECKONING_LABEL,
    ESTIMATE_LABEL,
    PATH_TITLE,
    TRUE_BIAS_LABEL,
    TRUTH_LABEL,
    VISION_LABEL,
    BiasPanels,
    bias_panels,
)
from ..scenario import DEFAULT, Scenario
from .base import Explorer, with_explorer_seed
from .cache import LastResults
from .panels import reuse_panels
from .sliders import float_slider, log_slider, starting_value

#: Slider range of the true bias b (cm/s²): up to 60 % of the path's peak acceleration.
BIAS_RANGE = (-60.0, 60.0)
#: Slider step of b (cm/s²).
BIAS_STEP = 5.0
#: Slider range of σ_a (cm/s²), log scale: from a near-perfect signal to one ten times
#: noisier than the path's peak acceleration (≈ 99 cm/s²).
SIGMA_A_RANGE = (1.0, 1000.0)
#: Slider range and step of σ_v (cm), covering the tutorial's 1.5 and 4.5 cm.
SIGMA_V_RANGE = (0.5, 6.0)
SIGMA_V_STEP = 0.5
#: Seconds shown (s): the bias settles and dead reckoning leaves the plot well before.
WINDOW = 4.0

def _build(figure: Figure, scenario: Scenario) -> BiasPanels:
    """The explorer's panels on the empty ``figure``, by notebook 06's painter of them."""
    shown = _shown(scenario)
    return bias_panels(figure, scenario.times[shown], scenario.truth[shown, 0],
                       amplitude=scenario.amplitude, window=WINDOW)


def _shown(scenario: Scenario) -> np.ndarray:
    """Samples drawn: the first :data:`WINDOW` seconds."""
    return scenario.times <= WINDOW


def draw_bias(figure: Figure, *, bias: float, sigma_a: float, sigma_v: float,
              scenario: Scenario = DEFAULT, noise: np.ndarray | None = None) -> str:
    """Draw one run of the biased-input filter and of dead reckoning.

    Left: the bias estimate b̂ with ±2 standard deviations of the filter's own bias
    variance, and the true bias. Right: the true path, vision's samples, the
    filtered position and the dead-reckoned position. Only the first :data:`WINDOW`
    seconds are drawn. Returns the numbers of this view as one line of text (the
    explorer shows it beside the figure): b, the estimate b̂ ± 2σ at the end of the
    trial, this run's filtered MSE after the burn-in beside the vision-only filter's on
    the same camera noise, and how far dead reckoning is from the path at the end of the
    trial (:func:`_bias_numbers`).

    A figure not drawn by this function is cleared first; on one it drew before,
    for the same scenario, the same artists receive the new data (rebuilding the
    axes would take longer than the filter run).

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to draw on.
    bias : float
        True bias b of the acceleration signal in cm/s².
    sigma_a : float
        Noise σ_a of the acceleration signal in cm/s², > 0 (the filter assumes it too).
    sigma_v : float
        Vision noise σ_v in cm, > 0.
    scenario : Scenario
        The hand's path, Δt, seed and burn-in.
    noise : array_like, shape (n, 2), optional
        Unit noise ``[vision, acceleration]``; default
        :func:`~lqe_helpers.bias_model.unit_noise`.

    Returns
    -------
    str
        Whose filter runs (the pack's), b (cm/s²), b̂ ± 2σ (cm/s²) at the end of the
        trial, the filtered MSE (cm²) after the burn-in with the vision-only filter's,
        and dead reckoning's position error (cm) at the end.

    Raises
    ------
    ValueError
        If a value is out of range, or ``noise`` has the wrong shape.
    """
    run = bias_model.unbiased_run(scenario, sigma_a, sigma_v, noise=noise)
    return _draw_tracking(figure, run.at_bias(bias),
                          _vision_only_mse(scenario, run.sigma_v, noise=noise))


def _vision_only_mse(scenario: Scenario, sigma_v: float, noise: np.ndarray | None = None
                    ) -> float:
    """MSE (cm²) after the burn-in of the vision-only filter of notebook 01 at ``sigma_v``.

    Run by the pack's engine (:func:`lqe_helpers.experiments.track`) on the camera noise of
    ``noise`` (its first column, shape (n, 2)), the noise the filter with the signal sees:
    the comparison of notebook 06's Task 2, for one run. Default noise:
    :func:`~lqe_helpers.bias_model.unit_noise`.
    """
    if noise is None:
        noise = bias_model.unit_noise(scenario)
    tracking = experiments.track(scenario, sigmas=[sigma_v], noise=np.asarray(noise)[..., :1])
    return float(tracking.mse())


def _draw(figure: Figure, *, bias: float, sigma_a: float, sigma_v: float,
          unbiased_runs: Callable[[float, float], bias_model.UnbiasedRun],
          vision_mses: Callable[[float], float]) -> str:
    """:func:`draw_bias` for the explorer: ``unbiased_runs(σ_a, σ_v)`` makes or keeps the filter
    run at b = 0, which a move of b only shifts (``UnbiasedRun.at_bias``);
    ``vision_mses(σ_v)`` makes or keeps the vision-only filter's MSE."""
    return _draw_tracking(figure, unbiased_runs(sigma_a, sigma_v).at_bias(bias),
                          vision_mses(sigma_v))


def _draw_tracking(figure: Figure, tracking: bias_model.InputTracking,
                   vision_mse: float) -> str:
    """:func:`draw_bias` for a run already made; returns the numbers of the view."""
    scenario = tracking.scenario
    shown = _shown(scenario)
    times = scenario.times[shown]
    estimate, std = tracking.bias_estimates[shown], tracking.bias_stds[shown]

    panels = reuse_panels(figure, _build, scenario)
    panels.band.set_data(times, estimate - 2 * std, estimate + 2 * std)
    panels.true_bias.set_ydata(tracking.truth[shown, 2])
    panels.bias_estimate.set_ydata(estimate)
    panels.vision.set_ydata(tracking.measurements[shown, 0])
    panels.estimate.set_ydata(tracking.positions[shown])
    panels.dead_reckoning.set_ydata(tracking.dead_reckoning[shown, 0])
    return _bias_numbers(tracking, vision_mse)


def _plus_minus(value: float, spread: float) -> str:
    """``value ± spread`` with the spread to 2 significant figures and the value to as many
    decimals ("19.93 ± 0.31", "20.012 ± 0.031", "21 ± 13"), so neither prints as 0.0."""
    decimals = max(0, 1 - math.floor(math.log10(spread))) if spread > 0 else 2
    return f"{value:.{decimals}f} ± {spread:.{decimals}f}"


def _bias_numbers(tracking: bias_model.InputTracking, vision_mse: float) -> str:
    """The numbers of :func:`draw_bias`'s view of ``tracking`` as one line of text.

    ``vision_mse`` is the vision-only filter's MSE (cm²) on the same camera noise
    (:func:`_vision_only_mse`). MSEs to 3 significant figures, b̂ ± 2σ by :func:`_plus_minus`.
    """
    scenario = tracking.scenario
    end_error = float(tracking.dead_reckoning[-1, 0] - tracking.truth[-1, 0])
    estimate = _plus_minus(float(tracking.bias_estimates[-1]), 2 * float(tracking.bias_stds[-1]))
    return (f"The pack's filter with the signal as input (bias_model). True bias "
            f"b = {tracking.bias:g} cm/s²; its estimate at {scenario.duration:g} s (± 2σ): "
            f"{estimate} cm/s². MSE of the filtered position after {scenario.burn_in:g} s: "
            f"{float(tracking.mse()):.3g} cm² (vision-only filter on the same camera noise: "
            f"{vision_mse:.3g} cm²); dead reckoning ends {end_error:+.0f} cm off the path at "
            f"{scenario.duration:g} s.")


def describe_bias(*, bias: float, sigma_a: float, sigma_v: float) -> str:
    """What :func:`draw_bias` shows at these slider values (its alt text)."""
    return (f"First {WINDOW:g} s of one run with an acceleration signal biased by "
            f"b = {bias:g} cm/s² and noise σ_a = {sigma_a:.3g} cm/s², vision at "
            f"σ_v = {sigma_v:.1f} cm. Left: the bias estimate with its ±2σ band and the true "
            f"bias; right: true path, vision, filtered estimate and dead reckoning.")


def explore_bias(scenario: Scenario = DEFAULT) -> Explorer:
    """Sliders for b (cm/s²), σ_a (cm/s², log scale) and σ_v (cm) over :func:`draw_bias`.

    Both noise streams are drawn once from the scenario's explorer seed (another draw
    than the tasks', :func:`~lqe_helpers.explorers.base.with_explorer_seed`) and kept,
    so a slider rescales the same noise instead of drawing new noise. The filter run
    at b = 0 is kept for the last (σ_a, σ_v) (:class:`~lqe_helpers.explorers.cache.LastResults`):
    a move of b only shifts it, as notebook 06's own runs are made
    (:func:`~lqe_helpers.bias_model.track_with_input`). b and σ_a start at
    :data:`~lqe_helpers.bias_model.DEFAULT_BIAS` and
    :data:`~lqe_helpers.bias_model.DEFAULT_SIGMA_A`, σ_v at the scenario's.

    Raises
    ------
    ValueError
        If ``scenario.sigma_v`` lies outside the slider's range :data:`SIGMA_V_RANGE`.
    """
    start_sigma_v = starting_value("sigma_v", scenario.sigma_v, *SIGMA_V_RANGE, "cm")
    noise = bias_model.unit_noise(with_explorer_seed(scenario))
    sliders = {
        "bias": float_slider("b (cm/s²)", bias_model.DEFAULT_BIAS, *BIAS_RANGE, BIAS_STEP,
                             readout_format=".0f"),
        "sigma_a": log_slider("σ_a (cm/s²)", bias_model.DEFAULT_SIGMA_A, *SIGMA_A_RANGE,
                              steps_per_decade=8, readout_format=".3g"),
        "sigma_v": float_slider("σ_v (cm)", start_sigma_v, *SIGMA_V_RANGE, SIGMA_V_STEP,
                                readout_format=".1f"),
    }
    return Explorer(
        "A biased acceleration signal corrected by vision",
        sliders,
        partial(_draw, unbiased_runs=LastResults(partial(bias_model.unbiased_run, scenario,
                                                         noise=noise)),
                vision_mses=LastResults(partial(_vision_only_mse, scenario, noise=noise))),
        figsize=(10.0, 4.6),
        describe=describe_bias,
    )
