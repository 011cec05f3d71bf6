"""Figures of notebook 04 (noisier proprioception): how much a worse sense still helps.

Also the painter of notebook 04's explorer (:func:`noisier_panels`): the trial by
:func:`~lqe_helpers.figures.common.trial_panels` beside the steady-state theory, built once
with no data and refilled by :mod:`lqe_helpers.explorers.noisier_proprioception`.
"""

from __future__ import annotations

from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import NullLocator

from ..plotting import COLORS, style
from .common import (
    TRUE_POSITION_LABEL,
    VISION_ONLY_LABEL,
    TrialLine,
    TrialPanels,
    interval_arrays,
    label_axes,
    legend_handles,
    mark_values,
    mean_band,
    plain_log_ticks,
    trial_panels,
)


def proprioception_sweep_figure(sigma_p: np.ndarray, fused, margin, dense_sigma_p: np.ndarray,
                                theory_fused: np.ndarray, theory_margin: np.ndarray,
                                vision, theory_vision: float, sigma_v: float,
                                marks: dict[str, float], ticks=None) -> Figure:
    """Fused MSE (left) and what proprioception wins (right) against σ_p, log axis.

    Parameters
    ----------
    sigma_p : array_like, shape (s,)
        The σ_p simulated (cm), increasing.
    fused : sequence of metrics.Interval, length s
        Monte Carlo MSE of the fused position (cm²) at each σ_p.
    margin : sequence of metrics.Interval, length s
        MSE lowered by proprioception in % of the vision-only MSE, paired per run.
    dense_sigma_p, theory_fused, theory_margin : array_like, shape (t,)
        σ_p (cm) of the theory curves, the steady-state fused variance (cm²) and the
        improvement in % it predicts.
    vision : metrics.Interval
        Monte Carlo MSE of vision alone (cm²), a horizontal line with its band.
    theory_vision : float
        Steady-state variance of vision alone (cm²).
    sigma_v : float
        σ_v of the runs (cm), for the title.
    marks : dict
        Label (e.g. "(c)") → a σ_p (cm) to mark with a dashed line.
    ticks : sequence of float, optional
        Ticks of the σ_p axis, labelled as plain numbers.

    Returns
    -------
    Figure
        Two panels; in each the simulation is the first line, the theory the second.
    """
    sigma_p = np.asarray(sigma_p, dtype=float)
    fig, (ax_mse, ax_margin) = plt.subplots(1, 2, figsize=(11, 4.4),
                                            gridspec_kw={"wspace": 0.28})
    _, _, fused_high = interval_arrays(fused)
    mean_band(ax_mse, sigma_p, fused, "estimate", "fused, simulation (95 % CI band)",
               marker="o", markersize=3.5)
    ax_mse.plot(dense_sigma_p, theory_fused,
                **style("reference", linewidth=2, label="fused, theory (steady state)"))
    ax_mse.axhspan(vision.low, vision.high, color=COLORS["alternative"], alpha=0.2, linewidth=0)
    ax_mse.axhline(vision.mean, **style("alternative", label="vision only, simulation"))
    ax_mse.axhline(theory_vision, **style("reference", color=COLORS["alternative"],
                                          linestyle=(0, (7, 3)), label="vision only, theory"))
    ax_mse.set_ylim(0, 1.15 * max(vision.high, theory_vision, fused_high.max()))
    label_axes(ax_mse, ylabel="position MSE (cm²)",
               title=f"Fused MSE against σ_p (σ_v = {sigma_v} cm)",
               legend={"loc": "lower right", "fontsize": 8.5, "handlelength": 3.5})

    mean_band(ax_margin, sigma_p, margin, "estimate", "simulation, paired (95 % CI band)",
               marker="o", markersize=3.5)
    ax_margin.plot(dense_sigma_p, theory_margin,
                   **style("reference", linewidth=2, label="theory (steady state)"))
    ax_margin.axhline(0, color=COLORS["truth"], linewidth=0.8)
    label_axes(ax_margin, ylabel="MSE lowered by proprioception (%)",
               title="The benefit of the extra sense",
               legend={"loc": "center right", "fontsize": 8.5})
    for ax in (ax_mse, ax_margin):
        label_axes(ax, "σ_p (cm), log scale", xscale="log", xlim=(sigma_p[0], sigma_p[-1]))
        plain_log_ticks(ax, "x", ticks)
        mark_values(ax, marks, "grey", linewidth=0.8, linestyle="--")
    return fig


def assumed_noise_figure(assumed_sigma_p: np.ndarray, fused, excess, vision_mse: float,
                         vision_excess: float, sigma_p: float, sigma_v: float, runs: int,
                         ticks=None, mse_ticks=None) -> Figure:
    """MSE of a filter that assumes σ̃_p (left) and its cost over the right model (right, zoom).

    Parameters
    ----------
    assumed_sigma_p : array_like, shape (s,)
        The σ̃_p the filter assumes (cm), increasing.
    fused : sequence of metrics.Interval, length s
        Monte Carlo MSE of the fused position (cm²) at each σ̃_p.
    excess : sequence of metrics.Interval, length s
        Extra MSE over the filter that assumes the true σ_p (cm²), paired per run.
    vision_mse : float
        Monte Carlo MSE of vision alone (cm²).
    vision_excess : float
        Extra MSE of vision alone over the correctly informed fused filter (cm²); the
        zoom on the right reaches 1.8 times it.
    sigma_p, sigma_v : float
        The true noise levels (cm), σ_p marked with a dashed line.
    runs : int
        Number of Monte Carlo runs, for the title.
    ticks, mse_ticks : sequence of float, optional
        Ticks of the σ̃_p axis and of the left panel's MSE axis, as plain numbers.

    Returns
    -------
    Figure
        Two panels; the means are the first line of each.
    """
    assumed_sigma_p = np.asarray(assumed_sigma_p, dtype=float)
    fig, (ax, ax_cost) = plt.subplots(1, 2, figsize=(11, 4.4), gridspec_kw={"wspace": 0.28})
    mean_band(ax, assumed_sigma_p, fused, "estimate", "fused, filter assumes σ̃_p",
               marker="o", markersize=4)
    ax.axhline(vision_mse, **style("alternative", label=VISION_ONLY_LABEL))
    label_axes(ax, ylabel="position MSE (cm²), log scale",
               title="MSE when the filter assumes σ̃_p", yscale="log")
    plain_log_ticks(ax, "y", mse_ticks)
    ax.text(0.04, 0.25, "← overtrust", fontsize=10, color="grey", transform=ax.transAxes)
    ax.text(0.96, 0.25, "undertrust →", fontsize=10, color="grey", ha="right",
            transform=ax.transAxes)

    mean_band(ax_cost, assumed_sigma_p, excess, "estimate",
               "fused, filter assumes σ̃_p (paired, 95 % CI band)", marker="o", markersize=4)
    ax_cost.axhline(vision_excess, **style("alternative", label=VISION_ONLY_LABEL))
    ax_cost.axhline(0, color=COLORS["truth"], linewidth=0.8)
    top = 1.8 * vision_excess
    label_axes(ax_cost, ylabel="extra MSE over the correct model (cm²)",
               title="Zoom: the cost of misjudging σ_p", ylim=(-top / 12, top))
    for axis in (ax, ax_cost):
        axis.axvline(sigma_p, **style("truth", linewidth=1, linestyle="--",
                                      label=f"true σ_p = {sigma_p} cm"))
        label_axes(axis, "σ̃_p assumed by the filter (cm), log scale", xscale="log")
        plain_log_ticks(axis, "x", ticks)
        axis.legend(loc="upper right", fontsize=8.5)
    fig.suptitle(f"Misjudging proprioception: true σ_v = {sigma_v} cm, σ_p = {sigma_p} cm "
                 f"({runs} runs)", y=1.0)
    return fig


#: Title of the explorer's right panel; it never changes (cached background).
THEORY_TITLE = "steady state"
#: The explorer's lines of the left column by gid
#: (see :data:`~lqe_helpers.figures.common.TrialLine`).
NOISIER_LINES: dict[str, TrialLine] = {
    "truth": (0, "truth", TRUE_POSITION_LABEL),
    "vision-only": (0, "alternative", "vision-only estimate"),
    "fused": (0, "estimate", "fused estimate (vision + proprioception)"),
    "vision-only error": (1, "alternative", None),
    "fused error": (1, "estimate", None),
}


class NoisierPanels(NamedTuple):
    """The artists :func:`noisier_panels` draws; the explorer refills them."""

    trial: TrialPanels
    marker: Line2D


def noisier_panels(figure: Figure, times: np.ndarray, duration: float, amplitude: float,
                   curve_sigma: np.ndarray, level: float, curve: np.ndarray) -> NoisierPanels:
    """Notebook 04's explorer on the empty ``figure``: a trial and the theory, no data yet.

    Left: the lines of :data:`NOISIER_LINES` over ``times`` (s), 0 to ``duration`` s,
    signals ±1.4 ``amplitude`` (cm). Right: the steady-state position variance (cm²) of
    vision alone (``level``) and fused (``curve`` against ``curve_sigma``, σ_p in cm, log
    axis), with an empty marker for the slider's σ_p.
    """
    trial = trial_panels(figure, duration, times, NOISIER_LINES, width_ratios=(2.4, 1.0),
                         height_ratios=(1.5, 1.0), top=0.9, wspace=0.3,
                         signal_limit=1.4 * amplitude, error_limit=2.5)
    figure.legend(handles=legend_handles(trial, NOISIER_LINES), loc="upper left",
                  bbox_to_anchor=(0.07, 0.99), ncol=3, fontsize=8)

    theory = trial.side
    theory.set_title(THEORY_TITLE, fontsize=10)
    theory.axhline(level, **style("alternative", gid="theory vision-only",
                                  label=VISION_ONLY_LABEL))
    theory.plot(curve_sigma, curve, **style("estimate", gid="theory fused", label="fused"))
    (marker,) = theory.plot([], [], gid="theory now", linestyle="none", marker="o",
                            markersize=7, color=COLORS["estimate"], label="slider's σ_p")
    theory.set_xscale("log")
    theory.set_xlim(curve_sigma[0], curve_sigma[-1])
    # Plain labels, as in the notebook's Figure 3 (mathtext powers of ten render slowly).
    ticks = [0.3, 1.0, 3.0, 10.0, 30.0, 100.0]
    theory.set_xticks(ticks, [f"{tick:g}" for tick in ticks])
    theory.xaxis.set_minor_locator(NullLocator())
    theory.set_ylim(0.0, 1.15 * level)
    theory.set_xlabel("σ_p (cm), log scale")
    theory.set_ylabel("steady-state position variance (cm²)")
    theory.legend(loc="lower right", fontsize=8)
    return NoisierPanels(trial, marker)
