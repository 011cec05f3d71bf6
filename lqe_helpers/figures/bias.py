"""Figures of notebook 06 (bias and input): the bias learned, the signal, dead reckoning.

Also the painter of notebook 06's explorer (:func:`bias_panels`): built once with no data,
refilled by :mod:`lqe_helpers.explorers.bias` on every slider move.
"""

from __future__ import annotations

from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import FillBetweenPolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MultipleLocator

from ..plotting import COLORS, DATA_UNDER_LINES, label_time_position, style
from .common import (
    BAND_LABEL,
    ESTIMATE_LABEL,
    VISION_LABEL,
    VISION_ONLY_LABEL,
    errorbar_intervals,
    first_seconds,
    label_axes,
    plot_series,
)
from .common import TRUE_PATH_LABEL as TRUTH_LABEL  # the explorer's truth line

_LEGEND_UPPER_RIGHT = {"loc": "upper right", "fontsize": 8}
#: Both axes logarithmic, legend at the upper left: the sweeps over a noise level.
_LOG_LOG_UPPER_LEFT = {"xscale": "log", "yscale": "log",
                       "legend": {"loc": "upper left", "fontsize": 8}}


def _whole_trial_log(times: np.ndarray) -> dict:
    """label_axes arguments of a panel over the whole trial on a log y axis."""
    return {"yscale": "log", "xlim": (times[0], times[-1]), "legend": _LEGEND_UPPER_RIGHT}


def bias_learning_figure(times: np.ndarray, estimate: np.ndarray, std: np.ndarray,
                         bias: float, rms_error: np.ndarray, filter_std: np.ndarray,
                         until: float = 3.0) -> Figure:
    """Notebook 06: a bias estimate with its ±2σ band, and its Monte Carlo error.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    estimate, std : array_like, shape (n,)
        One run's bias estimate and the filter's own σ of it (cm/s²).
    bias : float
        The true bias (cm/s²).
    rms_error : array_like, shape (n,)
        Root-mean-square error of the bias estimate over Monte Carlo runs (cm/s²), > 0.
    filter_std : array_like, shape (n,)
        The filter's own σ of the bias estimate (cm/s²), > 0.
    until : float
        Last time shown in the left panel (s), > 0.

    Returns
    -------
    Figure
        Left: the run (lines: truth, estimate). Right, log scale: RMS error, filter σ.
    """
    times, early = first_seconds(times, until)
    estimate = np.asarray(estimate, dtype=float)
    std = np.asarray(std, dtype=float)
    fig, (ax_run, ax_mc) = plt.subplots(1, 2, figsize=(12, 4.2))
    ax_run.fill_between(times[early], estimate[early] - 2 * std[early],
                        estimate[early] + 2 * std[early], color=COLORS["estimate"],
                        alpha=0.15, linewidth=0, label=BAND_LABEL)
    plot_series(ax_run, times, [(np.full(times.size, float(bias)), "truth", "true bias"),
                                (estimate, "estimate", "bias estimate")], early)
    label_axes(ax_run, "time (s)", "bias (cm/s²)", "One run: the bias estimate and its band",
               xlim=(0, until), ylim=(float(bias) - 80, float(bias) + 80),
               legend=_LEGEND_UPPER_RIGHT)
    ax_mc.plot(times, np.asarray(rms_error, dtype=float),
               **style("estimate", label="RMS error over the runs"))
    ax_mc.plot(times, np.asarray(filter_std, dtype=float),
               **style("reference", linewidth=2.0, label="the filter's own σ of the bias"))
    label_axes(ax_mc, "time (s)", "bias error (cm/s²)",
               "Monte Carlo: real error beside the filter's own σ", **_whole_trial_log(times))
    fig.tight_layout()
    return fig


def acceleration_signal_figure(times: np.ndarray, readings: np.ndarray,
                               accelerations: np.ndarray, bias: float,
                               until: float = 2.0) -> Figure:
    """Notebook 06: the acceleration signal's readings beside the true acceleration.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    readings : array_like, shape (n,)
        The signal a_r = a + b + noise (cm/s²).
    accelerations : array_like, shape (n,)
        True acceleration a (cm/s²).
    bias : float
        The bias b (cm/s²); a + b is drawn dashed.
    until : float
        Last time shown (s), > 0.

    Returns
    -------
    Figure
        One panel; lines in the order readings, a, a + b.
    """
    times, shown = first_seconds(times, until)
    accelerations = np.asarray(accelerations, dtype=float)
    fig, ax = plt.subplots(figsize=(10, 3.8))
    plot_series(ax, times, [(readings, "proprioception", "signal a_r = a + b + noise"),
                            (accelerations, "truth", "true acceleration a")], shown)
    plot_series(ax, times, [(accelerations + bias, "truth", "a + b")], shown, linestyle="--",
                linewidth=1.0)
    label_axes(ax, "time (s)", "acceleration (cm/s²)",
               f"The acceleration signal: noisy, and shifted by its bias b = {bias:g} cm/s²",
               xlim=(0, until),
               legend={"loc": "upper left", "fontsize": 8, "markerscale": 2, "ncols": 3})
    fig.tight_layout()
    return fig


def drift_figure(elapsed: np.ndarray, errors: dict[str, tuple[np.ndarray, str, str]],
                 theory: dict[str, tuple[np.ndarray, str]],
                 amplitude: float | None = None) -> Figure:
    """Notebook 06: RMS position error against time, log–log, beside theory curves.

    Parameters
    ----------
    elapsed : array_like, shape (n,)
        Time since the known start (s), > 0.
    errors : dict
        Label → (RMS position error (cm), shape (n,); style role; line style).
    theory : dict
        Label → (theoretical curve (cm), shape (n,); line style), drawn broad and pale
        behind the errors.
    amplitude : float, optional
        The movement's amplitude (cm), a horizontal line.

    Returns
    -------
    Figure
        One log–log panel; the theory curves are its first lines, then the errors.
    """
    elapsed = np.asarray(elapsed, dtype=float)
    if np.any(elapsed <= 0):
        raise ValueError("elapsed must be > 0 s everywhere (log axis), got a value <= 0")
    fig, ax = plt.subplots(figsize=(10, 5))
    for label, (curve, linestyle) in theory.items():
        ax.plot(elapsed, np.asarray(curve, dtype=float),
                **style("reference", linestyle=linestyle, linewidth=6, alpha=0.35, label=label))
    for label, (curve, role, linestyle) in errors.items():
        ax.plot(elapsed, np.asarray(curve, dtype=float),
                **style(role, linestyle=linestyle, label=label))
    if amplitude is not None:
        ax.axhline(amplitude, color=COLORS["truth"], linewidth=0.8, alpha=0.7,
                   label="amplitude of the movement")
    label_axes(ax, "time since the known start (s)", "RMS position error (cm)",
               "Integrating the signal without vision", xscale="log", yscale="log",
               xlim=(elapsed[0], elapsed[-1]), legend={"loc": "upper left", "fontsize": 8})
    fig.tight_layout()
    return fig


def noise_sweep_figure(values: np.ndarray, intervals, baseline, bias_rms: np.ndarray,
                       bias_std: np.ndarray, marked: float, xlabel: str) -> Figure:
    """Notebook 06: position MSE and bias error against a swept noise level.

    Parameters
    ----------
    values : array_like, shape (s,)
        The swept values (e.g. σ_a in cm/s²), > 0.
    intervals : sequence of metrics.Interval, length s
        Position MSE with its 95 % interval at each value (cm²).
    baseline : metrics.Interval
        The MSE to beat (e.g. vision only), drawn as a line with a band (cm²).
    bias_rms, bias_std : array_like, shape (s,)
        RMS error of the bias estimate and the filter's own σ of it at the end of the
        trial (cm/s²).
    marked : float
        The default value, a dashed vertical line in both panels.
    xlabel : str
        Quantity and unit of ``values``.

    Returns
    -------
    Figure
        Left: MSE (first line the means). Right: bias errors (lines RMS, σ).
    """
    values = np.asarray(values, dtype=float)
    fig, (ax_mse, ax_bias) = plt.subplots(1, 2, figsize=(12, 4.4))
    errorbar_intervals(ax_mse, values, intervals, "estimate", marker="o",
                       **style("estimate", label="with the signal (95 % CI)"))
    ax_mse.axhspan(float(baseline.low), float(baseline.high), color=COLORS["alternative"],
                   alpha=0.3, linewidth=0)
    ax_mse.axhline(float(baseline.mean), **style("alternative", label=VISION_ONLY_LABEL))
    ax_bias.plot(values, np.asarray(bias_rms, dtype=float), marker="o", markersize=4,
                 **style("estimate", label="RMS error of b̂ at the end"))
    ax_bias.plot(values, np.asarray(bias_std, dtype=float),
                 **style("reference", linewidth=2.0, label="the filter's own σ of b̂"))
    for ax in (ax_mse, ax_bias):
        ax.axvline(marked, color=COLORS["truth"], linewidth=0.8, linestyle="--")
    label_axes(ax_mse, xlabel, "position MSE after the burn-in (cm²)",
               "Position MSE: with the signal and vision only", **_LOG_LOG_UPPER_LEFT)
    label_axes(ax_bias, xlabel, "bias error (cm/s²)", "How well the bias is learned",
               **_LOG_LOG_UPPER_LEFT)
    fig.tight_layout()
    return fig


def bias_settling_figure(times: np.ndarray, mean_errors: dict[str, np.ndarray],
                         filter_stds: dict[str, np.ndarray], until: float = 2.0) -> Figure:
    """Notebook 06: mean bias error for several true biases; filter σ for several σ_v.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    mean_errors : dict
        Label (e.g. "b = 20 cm/s²") → mean error of b̂ over runs (cm/s²), shape (n,);
        drawn up to ``until``.
    filter_stds : dict
        Label (e.g. "σ_v = 1.5 cm") → the filter's σ of b̂ (cm/s²), shape (n,), > 0.
    until : float
        Last time shown in the left panel (s), > 0.

    Returns
    -------
    Figure
        Left: the mean errors, in order. Right (log scale): the σ's, in order.
    """
    times, early = first_seconds(times, until)
    dashes = (":", "-.", "-", "--", (0, (5, 1)), (0, (1, 3)))
    fig, (ax_b, ax_v) = plt.subplots(1, 2, figsize=(12, 4.4))
    for (label, curve), linestyle in zip(mean_errors.items(), dashes, strict=False):
        plot_series(ax_b, times, [(curve, "estimate", label)], early, linestyle=linestyle)
    ax_b.axhline(0, color=COLORS["truth"], linewidth=0.8)
    label_axes(ax_b, "time (s)", "mean error of b̂ over runs (cm/s²)",
               "Start-up of the bias estimate, by true bias", xlim=(0, until),
               legend={"loc": "lower right", "fontsize": 8})
    for (label, curve), linestyle in zip(filter_stds.items(), dashes, strict=False):
        ax_v.plot(times, np.asarray(curve, dtype=float),
                  **style("reference", linestyle=linestyle, linewidth=2.0, label=label))
    label_axes(ax_v, "time (s)", "the filter's σ of b̂ (cm/s²)",
               "The filter's σ of the bias, by vision noise", **_whole_trial_log(times))
    fig.tight_layout()
    return fig


#: Fixed y range of the explorer's bias panel (cm/s²): every slider value fits.
BIAS_AXIS = (-80.0, 80.0)
#: Spacing of the bias panel's y ticks (cm/s²).
BIAS_TICK = 40.0
#: Labels of the explorer's artists, so tests and readers can find them.
TRUE_BIAS_LABEL = "true bias"
BIAS_ESTIMATE_LABEL = "estimated bias"
BIAS_BAND_LABEL = "±2σ"
DEAD_RECKONING_LABEL = "dead reckoning"
#: Titles of the explorer's two panels; they never change (cached background).
BIAS_TITLE = "bias of the acceleration signal"
PATH_TITLE = "position of the hand"


class BiasPanels(NamedTuple):
    """The artists :func:`bias_panels` draws; the explorer refills all of them."""

    axes: tuple[Axes, Axes]
    band: FillBetweenPolyCollection
    true_bias: Line2D
    bias_estimate: Line2D
    vision: Line2D
    estimate: Line2D
    dead_reckoning: Line2D


def bias_panels(figure: Figure, times: np.ndarray, truth: np.ndarray, *, amplitude: float,
                window: float) -> BiasPanels:
    """Notebook 06's explorer on the empty ``figure``: the bias (left) and the path (right).

    ``times`` (s) and ``truth`` (true position, cm), shape (n,) each, the samples shown;
    ``window`` (s) the time axis' end; ``amplitude`` (cm) scales the path's axis.
    """
    bias_ax, path_ax = figure.subplots(1, 2)
    empty = np.zeros_like(times)
    band = bias_ax.fill_between(times, empty, empty, color=COLORS["estimate"], alpha=0.15,
                                linewidth=0, label=BIAS_BAND_LABEL, zorder=DATA_UNDER_LINES)
    true_bias, = bias_ax.plot(times, empty, **style("truth", label=TRUE_BIAS_LABEL))
    bias_estimate, = bias_ax.plot(times, empty, **style("estimate", label=BIAS_ESTIMATE_LABEL))
    bias_ax.set_ylim(*BIAS_AXIS)
    bias_ax.set_xlim(0, window)
    # Fewer tick labels than matplotlib's default: text is most of a redraw's cost.
    bias_ax.yaxis.set_major_locator(MultipleLocator(BIAS_TICK))
    bias_ax.set_xlabel("time (s)")
    bias_ax.set_ylabel("bias (cm/s²)")
    bias_ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8, ncols=3)
    # Lifted clear of the axes area, which the band (clipped to it) repaints on every
    # move: at the default pad the title would be repainted with it.
    bias_ax.set_title(BIAS_TITLE, fontsize=10, pad=10)

    vision, = path_ax.plot(times, empty, **style("vision", label=VISION_LABEL))
    path_ax.plot(times, truth, **style("truth", label=TRUTH_LABEL))
    estimate, = path_ax.plot(times, empty, **style("estimate", label=ESTIMATE_LABEL))
    dead_reckoning, = path_ax.plot(times, empty,
                                   **style("alternative", label=DEAD_RECKONING_LABEL))
    limit = 2.0 * amplitude
    path_ax.set_ylim(-limit, limit)
    path_ax.set_xlim(0, window)
    path_ax.yaxis.set_major_locator(MultipleLocator(amplitude))
    for ax in (bias_ax, path_ax):
        ax.xaxis.set_major_locator(MultipleLocator(1.0))
    label_time_position(path_ax)
    path_ax.set_title(PATH_TITLE, fontsize=10, pad=10)
    path_ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8, ncols=4,
                   markerscale=2, columnspacing=1.0, handlelength=1.8)
    figure.subplots_adjust(left=0.07, right=0.98, top=0.92, bottom=0.22, wspace=0.2)
    return BiasPanels((bias_ax, path_ax), band, true_bias, bias_estimate, vision,
                      estimate, dead_reckoning)
