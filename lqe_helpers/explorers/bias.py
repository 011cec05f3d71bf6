"""Explorer of notebook 06: a biased acceleration signal corrected by vision.

Three sliders: the signal's true bias b, its noise σ_a and vision's noise σ_v.
Left panel: the filter's bias estimate converging to the true bias, with the ±2σ
band of its own covariance. Right panel: the hand's path, vision, the filtered
position and dead reckoning (the signal integrated without vision), which drifts
away quadratically.
"""

from __future__ import annotations

from functools import partial

import numpy as np
from matplotlib.figure import Figure

from .. import bias_model
from ..explorer import Explorer, float_slider, log_slider
from ..plotting import label_time_position, plot_band, style
from ..scenario import DEFAULT, Scenario

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
#: Fixed y range of the bias panel (cm/s²): every slider value fits, the axes stay put.
BIAS_AXIS = (-80.0, 80.0)

#: Seconds shown (s): the bias settles and dead reckoning leaves the plot well before.
WINDOW = 4.0

#: Labels of the plotted artists, so tests and readers can find them.
TRUE_BIAS_LABEL = "true bias"
BIAS_ESTIMATE_LABEL = "estimated bias"
BIAS_BAND_LABEL = "±2σ"
TRUTH_LABEL = "true path"
VISION_LABEL = "vision"
ESTIMATE_LABEL = "filtered estimate"
DEAD_RECKONING_LABEL = "dead reckoning"


def draw_bias(figure: Figure, *, bias: float, sigma_a: float, sigma_v: float,
              scenario: Scenario = DEFAULT, noise: np.ndarray | None = None) -> None:
    """Draw one run of the biased-input filter and of dead reckoning.

    Clears ``figure``. Left: the bias estimate b̂ with ±2 standard deviations of the
    filter's own bias variance, and the true bias. Right: the true path, vision's
    samples, the filtered position and the dead-reckoned position, whose distance
    from the path at the end of the trial is given in the title with this run's
    filtered MSE after the burn-in.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        Cleared and redrawn.
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

    Raises
    ------
    ValueError
        If a value is out of range, or ``noise`` has the wrong shape.
    """
    tracking = bias_model.track_with_input(scenario, bias=bias, sigma_a=sigma_a,
                                           sigma_v=sigma_v, noise=noise)
    shown = scenario.times <= WINDOW
    times = scenario.times[shown]
    end_error = float(tracking.dead_reckoning[-1, 0] - tracking.truth[-1, 0])

    figure.clear()
    bias_ax, path_ax = figure.subplots(1, 2)
    estimate, std = tracking.bias_estimates[shown], tracking.bias_stds[shown]
    plot_band(bias_ax, times, estimate, std, label=BIAS_BAND_LABEL)
    bias_ax.plot(times, tracking.truth[shown, 2], **style("truth", label=TRUE_BIAS_LABEL))
    bias_ax.plot(times, estimate, **style("estimate", label=BIAS_ESTIMATE_LABEL))
    bias_ax.set_ylim(*BIAS_AXIS)
    bias_ax.set_xlim(0, WINDOW)
    bias_ax.set_xlabel("time (s)")
    bias_ax.set_ylabel("bias (cm/s²)")
    bias_ax.set_title(f"b = {tracking.bias:g} cm/s²; estimate at {scenario.duration:g} s: "
                      f"{tracking.bias_estimates[-1]:.1f} ± {2 * tracking.bias_stds[-1]:.1f}",
                      fontsize=10)
    bias_ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8, ncols=3)

    path_ax.plot(times, tracking.measurements[shown, 0], **style("vision", label=VISION_LABEL))
    path_ax.plot(times, tracking.truth[shown, 0], **style("truth", label=TRUTH_LABEL))
    path_ax.plot(times, tracking.positions[shown], **style("estimate", label=ESTIMATE_LABEL))
    path_ax.plot(times, tracking.dead_reckoning[shown, 0],
                 **style("alternative", label=DEAD_RECKONING_LABEL))
    limit = 2.0 * scenario.amplitude
    path_ax.set_ylim(-limit, limit)
    path_ax.set_xlim(0, WINDOW)
    label_time_position(path_ax)
    path_ax.set_title(f"MSE {float(tracking.mse()):.3g} cm²; dead reckoning "
                      f"{end_error:+.0f} cm off at {scenario.duration:g} s", fontsize=10)
    path_ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8, ncols=4,
                   markerscale=2, columnspacing=1.0, handlelength=1.8)
    figure.subplots_adjust(left=0.07, right=0.98, top=0.92, bottom=0.22, wspace=0.2)


def explore_bias(scenario: Scenario = DEFAULT) -> Explorer:
    """Sliders for b (cm/s²), σ_a (cm/s², log scale) and σ_v (cm) over :func:`draw_bias`.

    Both noise streams are drawn once from the scenario's seed and kept, so a slider
    rescales the same noise instead of drawing new noise.
    """
    noise = bias_model.unit_noise(scenario)
    sliders = {
        "bias": float_slider("b (cm/s²)", bias_model.DEFAULT_BIAS, *BIAS_RANGE, BIAS_STEP,
                             readout_format=".0f"),
        "sigma_a": log_slider("σ_a (cm/s²)", bias_model.DEFAULT_SIGMA_A, *SIGMA_A_RANGE,
                              steps_per_decade=8, readout_format=".3g"),
        "sigma_v": float_slider("σ_v (cm)", float(np.clip(scenario.sigma_v, *SIGMA_V_RANGE)),
                                *SIGMA_V_RANGE, SIGMA_V_STEP, readout_format=".1f"),
    }
    return Explorer(
        "A biased acceleration signal corrected by vision",
        sliders,
        partial(draw_bias, scenario=scenario, noise=noise),
        figsize=(10.0, 4.6),
    )
