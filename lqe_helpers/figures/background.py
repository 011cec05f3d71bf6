"""Figures of notebook 00 (the background model): eyes closed, the choice of σ_j, Q's sweep.

Also the painter of notebook 00's explorer (:func:`background_panels`): built once with no
data, its lines refilled by :mod:`lqe_helpers.explorers.background` on every slider move.
"""

from __future__ import annotations

from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import (
    FixedLocator,
    FuncFormatter,
    MultipleLocator,
    NullFormatter,
    NullLocator,
)

from ..plotting import COLORS, label_time_position, style
from .common import (
    ESTIMATE_LABEL,
    VISION_LABEL,
    errorbar_intervals,
    interval_arrays,
    label_axes,
    plain_log_ticks,
    plot_series,
)
from .common import TRUE_PATH_LABEL as TRUTH_LABEL  # the explorer's truth line


def open_loop_figure(times: np.ndarray, truth: np.ndarray, readings: np.ndarray,
                     estimate: np.ndarray, close: float, prediction_times: np.ndarray,
                     prediction: np.ndarray, prediction_std: np.ndarray,
                     start: float = 0.5, limit: float = 30.0) -> Figure:
    """Tracking with vision until ``close``, then prediction with no measurements.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    truth, readings, estimate : array_like, shape (n,)
        True position, visual readings and filtered position (cm); drawn up to
        ``close`` (the truth up to the end of the prediction).
    close : float
        Time (s) at which the eyes close, marked by a dotted vertical line.
    prediction_times : array_like, shape (h,)
        Times (s) of the prediction, from ``close`` on.
    prediction, prediction_std : array_like, shape (h,)
        Predicted position and its standard deviation (cm), drawn with a ±2σ band.
    start : float
        First time shown (s).
    limit : float
        The position axis runs from −limit to +limit (cm), > 0.

    Returns
    -------
    Figure
        One panel; lines in the order readings, truth, estimate, prediction.
    """
    times = np.asarray(times, dtype=float)
    prediction_times = np.asarray(prediction_times, dtype=float)
    prediction = np.asarray(prediction, dtype=float)
    prediction_std = np.asarray(prediction_std, dtype=float)
    if limit <= 0:
        raise ValueError(f"limit must be > 0 cm, got {limit}")
    end = float(prediction_times[-1])
    seen = times <= close
    shown = times <= end
    fig, ax = plt.subplots(figsize=(10, 4.5))
    plot_series(ax, times, [(readings, "vision", VISION_LABEL)], seen)
    plot_series(ax, times, [(truth, "truth", TRUTH_LABEL)], shown)
    plot_series(ax, times, [(estimate, "estimate", ESTIMATE_LABEL)], seen)
    ax.plot(prediction_times, prediction,
            **style("prediction", label="prediction with eyes closed"))
    ax.fill_between(prediction_times, prediction - 2 * prediction_std,
                    prediction + 2 * prediction_std, color=COLORS["prediction"], alpha=0.15,
                    linewidth=0, label="±2σ of the prediction")
    ax.axvline(close, color=COLORS["truth"], linewidth=0.8, linestyle=":")
    label_axes(ax, "time (s)", "position (cm)",
               f"Eyes closed at t = {close:g} s: the prediction and its ±2σ band",
               xlim=(start, end), ylim=(-limit, limit),
               legend={"loc": "lower left", "ncols": 3, "markerscale": 3, "fontsize": 9})
    fig.tight_layout()
    return fig


def mse_intervals_figure(labels: list[str], intervals, xlabel: str = "MSE (cm²)",
                         title: str = "", reference: float | None = None,
                         reference_label: str = "") -> Figure:
    """Monte Carlo means with their 95 % intervals, one row per condition.

    Parameters
    ----------
    labels : list of str
        Name of each condition, top to bottom.
    intervals : sequence of metrics.Interval
        Mean and 95 % interval of each condition (e.g. MSE in cm²).
    xlabel : str
        Quantity and unit of the values.
    title : str
        Title (say what was compared).
    reference : float, optional
        A value drawn as a dashed vertical line (e.g. raw vision's MSE σ_v²).
    reference_label : str
        Legend label of the reference line.

    Returns
    -------
    Figure
        One panel; its first line holds the means (x) against the rows (y = 0, 1, …
        from the top).
    """
    mean, low, high = interval_arrays(intervals)
    if len(labels) != mean.size:
        raise ValueError(f"labels must name each of the {mean.size} intervals, got "
                         f"{len(labels)} labels")
    rows = np.arange(mean.size)
    fig, ax = plt.subplots(figsize=(8, 1.2 + 0.6 * mean.size))
    ax.errorbar(mean, rows, xerr=[mean - low, high - mean], capsize=4, marker="o",
                **style("estimate", linestyle="none", label="Monte Carlo mean, 95 % CI"))
    if reference is not None:
        ax.axvline(reference, **style("reference", linestyle="--", label=reference_label))
    ax.set_yticks(rows, labels)
    # The legend goes below the axis label (0.55 inch below the axes, whose height is about
    # 0.6 inch per row), where no row's interval can sit under it.
    label_axes(ax, xlabel, title=title, ylim=(mean.size - 0.5, -0.5),
               legend={"loc": "upper center", "ncols": 2, "fontsize": 8, "frameon": False,
                       "bbox_to_anchor": (0.5, -0.55 / (0.6 * mean.size + 0.2))})
    fig.tight_layout()
    return fig


def uncertainty_growth_figure(elapsed: np.ndarray,
                              curves: dict[str, tuple[np.ndarray, str, float]],
                              amplitude: float | None = None) -> Figure:
    """Twice the predicted position's σ against time with no measurements, log–log.

    Parameters
    ----------
    elapsed : array_like, shape (n,)
        Time since the last measurement (s), > 0.
    curves : dict
        Label → (2σ of the predicted position (cm), shape (n,); line style such as
        ``"-"`` or ``":"``; line width). All are predictions, drawn in the prediction
        colour and told apart by line style.
    amplitude : float, optional
        The flight's amplitude (cm), drawn as a horizontal line.

    Returns
    -------
    Figure
        One panel with log axes; the curves are its first lines, in the order given.
    """
    elapsed = np.asarray(elapsed, dtype=float)
    if np.any(elapsed <= 0):
        raise ValueError("elapsed must be > 0 s everywhere (log axis), got a value <= 0")
    fig, ax = plt.subplots(figsize=(8, 4.8))
    for label, (curve, linestyle, width) in curves.items():
        ax.plot(elapsed, np.asarray(curve, dtype=float),
                **style("prediction", linestyle=linestyle, linewidth=width, label=label))
    if amplitude is not None:
        ax.axhline(amplitude, **style("reference", linestyle="-", linewidth=0.9,
                                      label="flight amplitude"))
    label_axes(ax, "time without measurements (s)", "2σ of predicted position (cm)",
               "Position uncertainty with no measurements", xscale="log", yscale="log",
               legend={"loc": "upper left", "fontsize": 8})
    fig.tight_layout()
    return fig


def jerk_sweep_figure(jerk_stds: np.ndarray, intervals, systematic: np.ndarray,
                      noise: np.ndarray, expected: np.ndarray, raw_mse: float,
                      derived: float) -> Figure:
    """Tracking error against the jerk noise σ_j behind Q, split into its two parts.

    Parameters
    ----------
    jerk_stds : array_like, shape (s,)
        The σ_j tried (cm/s³), > 0.
    intervals : sequence of metrics.Interval, length s
        Monte Carlo MSE of the filtered position at each σ_j (cm²).
    systematic, noise : array_like, shape (s,)
        The MSE's systematic part (noise-free run) and noise part (cm²).
    expected : array_like, shape (s,)
        The filter's own steady-state position variance (cm²).
    raw_mse : float
        MSE of the raw readings, σ_v² (cm²).
    derived : float
        The σ_j the pack derives from the motion (cm/s³), marked by a vertical line.

    Returns
    -------
    Figure
        One log–log panel; lines in the order MSE, systematic, noise, expected.
    """
    jerk_stds = np.asarray(jerk_stds, dtype=float)
    fig, ax = plt.subplots(figsize=(10, 5))
    errorbar_intervals(ax, jerk_stds, intervals, "estimate", marker="o",
                       **style("estimate", label="MSE of the filtered position (95 % CI)"))
    ax.plot(jerk_stds, np.asarray(systematic, dtype=float),
            **style("estimate", linestyle="--", linewidth=1.2,
                    label="systematic part (noise-free run)"))
    ax.plot(jerk_stds, np.asarray(noise, dtype=float),
            **style("estimate", linestyle=":", linewidth=1.6, label="noise part"))
    ax.plot(jerk_stds, np.asarray(expected, dtype=float),
            **style("reference", linestyle="-", linewidth=1.4, marker="s", markersize=4,
                    markerfacecolor="none", label="the filter's own expected variance"))
    ax.axhline(raw_mse, color=COLORS["vision"], linestyle="-.", linewidth=1.4,
               label="raw vision, σ_v²")
    ax.axvline(derived, color=COLORS["truth"], linewidth=0.8, linestyle="-",
               label=f"derived σ_j = {derived:,.0f} cm/s³")
    label_axes(ax, "jerk noise σ_j behind Q (cm/s³)", "position error (cm²)",
               "Tracking error against the process noise", xscale="log", yscale="log",
               legend={"loc": "lower left", "fontsize": 8, "ncols": 2})
    fig.tight_layout()
    return fig


def tracking_panels_figure(times: np.ndarray, truth: np.ndarray, readings: np.ndarray,
                           panels: dict[str, np.ndarray],
                           window: tuple[float, float]) -> Figure:
    """The same readings filtered several ways, one panel per filter, over a window.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    truth, readings : array_like, shape (n,)
        True position and visual readings (cm), the same in every panel.
    panels : dict
        Panel title → filtered position (cm), shape (n,).
    window : tuple of float
        (start, end) of the time shown (s).

    Returns
    -------
    Figure
        One panel per entry, sharing the position axis; in each the lines are readings,
        truth, estimate.
    """
    times = np.asarray(times, dtype=float)
    if not panels:
        raise ValueError("panels must hold at least one filter, got none")
    start, end = window
    if not end > start:
        raise ValueError(f"window must be (start, end) with end > start, got {window}")
    shown = (times >= start) & (times <= end)
    fig, axes = plt.subplots(1, len(panels), figsize=(4 * len(panels), 4), sharey=True,
                             squeeze=False)
    for ax, (title, estimate) in zip(axes[0], panels.items(), strict=True):
        plot_series(ax, times, [(readings, "vision", VISION_LABEL), (truth, "truth", TRUTH_LABEL),
                                (estimate, "estimate", ESTIMATE_LABEL)], shown)
        ax.set_title(title, fontsize=9)
        label_axes(ax, "time (s)", xlim=(start, end))
    label_axes(axes[0, 0], ylabel="position (cm)",
               legend={"loc": "lower left", "fontsize": 8, "markerscale": 3})
    fig.tight_layout()
    return fig


#: Line role and style of each way to choose σ_j in :func:`jerk_choice_figure` (told
#: apart by line style as well as by colour).
CHOICE_ROLES = {"likelihood": ("estimate", "-"), "NIS": ("prediction", "--"),
                "MSE": ("truth", ":")}


def jerk_choice_figure(jerk_stds: np.ndarray, log_likelihood: np.ndarray,
                       nis_mean: np.ndarray, mse: np.ndarray, chosen: dict[str, float],
                       expected_nis: float = 1.0) -> Figure:
    """Three ways to choose σ_j on one grid: the innovations' likelihood, the NIS, the MSE.

    Parameters
    ----------
    jerk_stds : array_like, shape (g,)
        The grid of σ_j (cm/s³), > 0, increasing.
    log_likelihood : array_like, shape (g,)
        Mean log-likelihood of the innovations per run (nats); drawn relative to its
        largest value.
    nis_mean : array_like, shape (g,)
        Mean NIS; drawn beside ``expected_nis``.
    mse : array_like, shape (g,)
        Mean position MSE (cm²), which needs the true path.
    chosen : dict of str to float
        The σ_j (cm/s³) each criterion picks, keyed by "likelihood", "NIS" and "MSE"
        (:data:`CHOICE_ROLES`); each is a vertical line in every panel.
    expected_nis : float
        The mean NIS a correct model predicts (the number of sensors).

    Returns
    -------
    Figure
        Three panels sharing the log σ_j axis: likelihood, NIS, MSE.
    """
    jerk_stds = np.asarray(jerk_stds, dtype=float)
    curves = [np.asarray(values, dtype=float) for values in (log_likelihood, nis_mean, mse)]
    if any(curve.shape != jerk_stds.shape for curve in curves):
        raise ValueError(f"log_likelihood, nis_mean and mse must have the grid's shape "
                         f"{jerk_stds.shape}, got {[curve.shape for curve in curves]}")
    unknown = set(chosen) - set(CHOICE_ROLES)
    if unknown:
        raise ValueError(f"chosen must be keyed by {tuple(CHOICE_ROLES)}, got {sorted(unknown)}")
    likelihood, nis, mse = curves
    fig, axes = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)
    panels = [
        (likelihood - likelihood.max(), "estimate", "log-likelihood − its largest (nats)",
         "Readings alone: the innovations' log-likelihood (mean per run)"),
        (nis, "prediction", "mean NIS", "Readings alone: the mean NIS"),
        (mse, "truth", "MSE (cm²)", "With the true path: the MSE after 1 s"),
    ]
    for ax, (values, role, ylabel, title) in zip(axes, panels, strict=True):
        ax.plot(jerk_stds, values, **style(role, marker="o", markersize=3))
        for key, value in chosen.items():
            role, linestyle = CHOICE_ROLES[key]
            ax.axvline(value, **style(role, linestyle=linestyle, linewidth=1.2,
                                      label=f"chosen by {key}: {value:,.0f} cm/s³"))
        label_axes(ax, ylabel=ylabel, title=title, xscale="log")
        ax.title.set_fontsize(10)
    axes[1].axhline(expected_nis, color=COLORS["reference"], linewidth=1.2,
                    label=f"expected mean NIS ({expected_nis:g})")
    label_axes(axes[-1], "jerk noise σ_j behind Q (cm/s³)")
    low, high = jerk_stds.min(), jerk_stds.max()
    plain_log_ticks(axes[-1], "x", [tick for tick in (500, 700, 1000, 1400, 2000, 2800, 4000)
                                    if low <= tick <= high] or None)
    axes[-1].xaxis.set_minor_formatter(NullFormatter())
    axes[1].legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return fig


#: Titles of the explorer's two panels; they never change (the numbers go beside the figure).
GROWTH_TITLE = "Uncertainty once the measurements stop"
TRACKING_TITLE = "Tracking"
#: Gap (points) between a panel and its title: wide enough that the title is not
#: painted again with the top spine, which every move repaints over the curves.
TITLE_PAD = 10.0
#: Labels of the explorer's artists, so tests and readers can find them.
GROWTH_LABEL = "2σ at this σ_j"
REFERENCE_LABEL = "2σ at the scenario's σ_j"
AMPLITUDE_LABEL = "flight amplitude"


class BackgroundPanels(NamedTuple):
    """The artists :func:`background_panels` draws; the explorer refills the last three."""

    axes: tuple[Axes, Axes]
    growth: Line2D
    vision: Line2D
    estimate: Line2D


def background_panels(figure: Figure, reference_times: np.ndarray,
                      reference_two_sigma: np.ndarray, times: np.ndarray, truth: np.ndarray,
                      *, amplitude: float, growth_duration: float,
                      window: tuple[float, float]) -> BackgroundPanels:
    """Notebook 00's explorer on the empty ``figure``: fixed artists drawn, the rest empty.

    Left: 2σ (cm) of the predicted position against the time since the last measurement
    (0 to ``growth_duration`` s, log scale), the reference curve ``reference_two_sigma``
    (cm, shape (r,) at ``reference_times``) and an empty curve for the slider's σ_j.
    Right: the true path ``truth`` (cm, shape (n,) at ``times`` in s) over ``window`` (s)
    with empty vision and estimate lines. ``amplitude`` (cm) marks the left panel and
    scales the right one.
    """
    growth_ax, track_ax = figure.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.35]})
    growth_ax.plot(reference_times, reference_two_sigma,
                   **style("reference", label=REFERENCE_LABEL))
    growth, = growth_ax.plot(reference_times, np.ones_like(reference_times),
                             **style("prediction", label=GROWTH_LABEL))
    growth_ax.axhline(amplitude, color=COLORS["truth"], linewidth=0.8, label=AMPLITUDE_LABEL)
    growth_ax.set_yscale("log")
    growth_ax.set_ylim(1e-2, 1e3)
    # Decades only, as plain numbers: minor ticks and mathtext labels would double
    # the time a slider move takes to render.
    growth_ax.yaxis.set_major_locator(FixedLocator(np.logspace(-2, 3, 6)))
    growth_ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    growth_ax.yaxis.set_minor_locator(NullLocator())
    growth_ax.set_xlim(0, growth_duration)
    growth_ax.set_xlabel("time since the last measurement (s)")
    growth_ax.set_ylabel("2σ of predicted position (cm)")
    growth_ax.set_title(GROWTH_TITLE, fontsize=10, pad=TITLE_PAD)
    # Legends below the panels, never over a moving curve: a legend a curve passes
    # under has to be painted again on every slider move.
    growth_ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize=8, ncols=2)

    shown = (times >= window[0]) & (times <= window[1])
    empty = np.zeros(int(shown.sum()))
    vision, = track_ax.plot(times[shown], empty, **style("vision", label=VISION_LABEL))
    track_ax.plot(times[shown], truth[shown], **style("truth", label=TRUTH_LABEL))
    estimate, = track_ax.plot(times[shown], empty, **style("estimate", label=ESTIMATE_LABEL))
    track_ax.set_ylim(-1.7 * amplitude, 1.7 * amplitude)
    track_ax.set_xlim(*window)
    track_ax.xaxis.set_major_locator(MultipleLocator(1.0))  # fewer labels: faster redraws
    label_time_position(track_ax)
    track_ax.set_title(TRACKING_TITLE, fontsize=10, pad=TITLE_PAD)
    track_ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize=8, ncols=3)
    figure.subplots_adjust(left=0.07, right=0.98, top=0.92, bottom=0.25, wspace=0.22)
    return BackgroundPanels((growth_ax, track_ax), growth, vision, estimate)
