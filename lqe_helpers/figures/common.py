"""What several notebooks' figures share: two figures, and the pieces every figure is made of.

The figures: :func:`tracking_comparison_figure` (estimates beside the truth, their errors
below; notebooks 01, 03, 04, 05; its painter :func:`trial_column` draws the explorers'
trials of 01, 03, 04 and 05 too) and :func:`paired_mse_figure` (one point per Monte
Carlo run; 01, 03, 04, 05, 06). The pieces: series drawn in their roles
(:func:`plot_series`), axes labelled in one call (:func:`label_axes`), Monte Carlo
means with their 95 % intervals as error bars or a band (:func:`errorbar_intervals`,
:func:`mean_band`), values marked by a labelled vertical line (:func:`mark_values`), a
legend above a full panel (:func:`legend_above`), plain tick labels on a log axis
(:func:`plain_log_ticks`), the first seconds of a trial (:func:`first_seconds`) and the
explorers' trial of 03 and 04 beside a side panel (:func:`trial_panels`).
Nothing runs on import.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..plotting import COLORS, style

#: A series to draw: (values, shape (n,); style role; legend label or None).
Series = tuple[np.ndarray, str, "str | None"]
#: A line of a trial column (:func:`trial_column`): (panel, style role, legend label or
#: None). Panel 0 holds the signals, panel 1 the errors (estimate − true position).
TrialLine = tuple[int, str, "str | None"]

#: Legend labels several pictures share, written once: the figures draw them and the
#: explorers (and their tests) find their artists by them.
TRUE_POSITION_LABEL = "true position"
TRUE_PATH_LABEL = "true path"
VISION_LABEL = "vision"
NOISY_VISION_LABEL = "noisy vision"
VISION_READINGS_LABEL = "vision readings"
VISION_ONLY_LABEL = "vision only"
ESTIMATE_LABEL = "filtered estimate"
BAND_LABEL = "±2σ of the filter's own variance"


def interval_arrays(intervals: Iterable) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Means, lower and upper ends of a sequence of ``metrics.Interval`` (or alike), (s,) each.

    Raises
    ------
    ValueError
        If ``intervals`` is empty.
    """
    intervals = list(intervals)
    if not intervals:
        raise ValueError("intervals must hold at least one interval, got none")
    return (np.array([float(iv.mean) for iv in intervals]),
            np.array([float(iv.low) for iv in intervals]),
            np.array([float(iv.high) for iv in intervals]))


def first_seconds(times: np.ndarray, until: float) -> tuple[np.ndarray, np.ndarray]:
    """``times`` (s) as floats and the mask of the samples up to ``until`` (s, > 0).

    Raises
    ------
    ValueError
        If ``until`` is not > 0.
    """
    times = np.asarray(times, dtype=float)
    if until <= 0:
        raise ValueError(f"until must be > 0 s, got {until}")
    return times, times <= until


def plot_series(ax: Axes, times: np.ndarray, series: Iterable[Series],
                shown: np.ndarray | None = None, **line: object) -> None:
    """Draw each (values, role, label) of ``series`` against ``times``, in its role's style.

    ``shown`` (a mask or index of the samples) restricts every series to those samples;
    ``line`` overrides the roles' styles for every series (e.g. ``linewidth=1.1``).
    """
    times = np.asarray(times, dtype=float)
    selected = slice(None) if shown is None else shown
    for values, role, label in series:
        ax.plot(times[selected], np.asarray(values, dtype=float)[selected],
                **style(role, label=label, **line))


def label_axes(ax: Axes, xlabel: str | None = None, ylabel: str | None = None,
               title: str | None = None, *, xscale: str | None = None,
               yscale: str | None = None, xlim: tuple | None = None,
               ylim: tuple | None = None,
               legend: Mapping[str, object] | None = None) -> None:
    """Decorate ``ax`` in one call: scales, then limits, labels, title and legend.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes.
    xlabel, ylabel : str, optional
        Quantity and unit of each axis, e.g. ``"time (s)"``.
    title : str, optional
        What the panel shows.
    xscale, yscale : str, optional
        ``"log"`` for a logarithmic axis.
    xlim, ylim : tuple, optional
        Axis limits, (low, high).
    legend : mapping, optional
        Keyword arguments of :meth:`~matplotlib.axes.Axes.legend` (e.g. ``{"loc":
        "upper right", "fontsize": 8}``); None draws no legend.
    """
    if xscale is not None:
        ax.set_xscale(xscale)
    if yscale is not None:
        ax.set_yscale(yscale)
    if xlim is not None:
        ax.set_xlim(*xlim)
    if ylim is not None:
        ax.set_ylim(*ylim)
    if xlabel is not None:
        ax.set_xlabel(xlabel)
    if ylabel is not None:
        ax.set_ylabel(ylabel)
    if title is not None:
        ax.set_title(title)
    if legend is not None:
        ax.legend(**legend)


def errorbar_intervals(ax: Axes, x: np.ndarray, intervals: Iterable, role: str,
                       **line: object) -> None:
    """Means of ``intervals`` against ``x`` with their 95 % intervals as error bars.

    Drawn in the role's colour with markers of size 4 and caps of 2 points; ``line``
    adds or overrides keyword arguments of :meth:`~matplotlib.axes.Axes.errorbar`.
    """
    mean, low, high = interval_arrays(intervals)
    ax.errorbar(x, mean, yerr=[mean - low, high - mean],
                **{"color": COLORS[role], "markersize": 4, "capsize": 2, **line})


def mean_band(ax: Axes, x: np.ndarray, intervals: Iterable, role: str, label: str,
              **line: object) -> np.ndarray:
    """Plot the means of ``intervals`` against ``x`` over their shaded 95 % band; the means."""
    mean, low, high = interval_arrays(intervals)
    ax.fill_between(x, low, high, color=COLORS[role], alpha=0.25, linewidth=0)
    ax.plot(x, mean, **style(role, label=label, **line))
    return mean


def mark_values(ax: Axes, marks: Mapping[str, float], color: str, **line: object) -> None:
    """A vertical line at each value of ``marks``, labelled with its key at the top left.

    ``line`` styles the lines (e.g. ``linewidth=1``); the labels share their colour.
    """
    for text, value in marks.items():
        ax.axvline(value, color=color, **line)
        ax.annotate(text, (value, 1.0), xycoords=("data", "axes fraction"), xytext=(3, -12),
                    textcoords="offset points", color=color, fontsize=9)


def plain_log_ticks(ax: Axes, axis: str, ticks: Sequence[float] | None) -> None:
    """Put ``ticks`` on a log ``axis`` ("x" or "y") labelled as plain numbers (0.3, not 3e-1).

    None leaves the axis as it is.
    """
    if ticks is None:
        return
    ticks = list(ticks)
    labels = [f"{tick:g}" for tick in ticks]
    if axis == "x":
        ax.set_xticks(ticks, labels)
    else:
        ax.set_yticks(ticks, labels)
        ax.yaxis.set_minor_locator(plt.NullLocator())


def legend_above(ax: Axes, title: str = "") -> None:
    """Put ``ax``'s legend in one row above the panel, between it and its ``title``.

    For panels whose data fill them from edge to edge (readings and estimates over a
    whole trial), where a legend inside would cover some of them.
    """
    labels = ax.get_legend_handles_labels()[1]
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=max(len(labels), 1),
              frameon=False, fontsize=9, markerscale=2.5, handlelength=1.8,
              columnspacing=1.2, borderaxespad=0.2)
    ax.set_title(title, pad=22)


def trial_column(signals: Axes, errors: Axes | None, times: np.ndarray,
                 lines: Mapping[str, TrialLine],
                 values: Mapping[str, np.ndarray] | None = None, *,
                 error_linewidth: float, zero_line_first: bool) -> dict[str, Line2D]:
    """Draw one trial's signals over its errors: the one painter of that picture.

    Used by :func:`tracking_comparison_figure` (notebooks 01, 03, 04, 05 through
    :meth:`lqe_helpers.experiments.Tracking.figure` and
    :meth:`lqe_helpers.experiments.DelayedTracking.comparison_figure`) and by the painters of
    the explorers of 01, 03, 04 and 05 (:func:`lqe_helpers.figures.vision.vision_panel`,
    signals only; :func:`trial_panels`; :func:`lqe_helpers.figures.delay.delay_panels`),
    which draw with no data; the explorers refill these lines on every slider move.

    Parameters
    ----------
    signals, errors : matplotlib.axes.Axes
        The top (position, cm) and bottom (estimate − true position, cm) panels;
        ``errors`` None for a trial's signals alone (every line on panel 0).
    times : array_like, shape (n,)
        Sample times (s).
    lines : mapping of str to (panel, role, label)
        By gid, in drawing order: each becomes one line in its role's style (on the
        errors panel with ``error_linewidth``).
    values : mapping of str to array_like, shape (n,), optional
        The y data (cm) of each line, by gid; None draws every line as zeros, waiting
        for data.
    error_linewidth : float
        Line width (pt) of the lines on the errors panel.
    zero_line_first : bool
        Whether the errors panel's zero line (black, 0.8 pt) is drawn before its lines
        (under them, as the notebooks' figures do) or after them.

    Returns
    -------
    dict of str to Line2D
        The drawn lines by gid.

    Raises
    ------
    ValueError
        If ``errors`` is None and a line is on panel 1.
    """
    times = np.asarray(times, dtype=float)
    panels = (signals, errors)
    if errors is None and any(panel != 0 for panel, _, _ in lines.values()):
        raise ValueError(f"lines must all be on panel 0 when errors is None, got "
                         f"{[gid for gid, (panel, _, _) in lines.items() if panel != 0]}")
    if zero_line_first and errors is not None:
        errors.axhline(0.0, **style("truth", linewidth=0.8))
    drawn = {}
    for gid, (panel, role, label) in lines.items():
        extra = {"linewidth": error_linewidth} if panel == 1 else {}
        y = np.zeros_like(times) if values is None else np.asarray(values[gid], dtype=float)
        (drawn[gid],) = panels[panel].plot(times, y, **style(role, gid=gid, label=label,
                                                             **extra))
    if not zero_line_first and errors is not None:
        errors.axhline(0.0, **style("truth", linewidth=0.8))
    return drawn


class TrialPanels(NamedTuple):
    """A trial's signals (top left) and errors (bottom left), a side panel, the lines."""

    signals: Axes
    errors: Axes
    side: Axes
    lines: dict[str, Line2D]


def trial_panels(figure: Figure, duration: float, times: np.ndarray,
                 lines: Mapping[str, TrialLine], *, width_ratios: tuple[float, float],
                 height_ratios: tuple[float, float], top: float, wspace: float,
                 signal_limit: float, error_limit: float) -> TrialPanels:
    """One trial over ``times`` (s) beside a side panel, on an empty figure (03, 04 explorers).

    The left column holds the signals (position, ±``signal_limit`` cm) above the
    errors (estimate − true position, ±``error_limit`` cm, with a zero line) over 0 to
    ``duration`` s; each entry of ``lines`` becomes a line of zeros, its key as gid,
    waiting for data, drawn by :func:`trial_column`. The caller adds the legend and
    fills the side panel.
    """
    grid = figure.add_gridspec(2, 2, width_ratios=width_ratios, height_ratios=height_ratios,
                               left=0.07, right=0.98, bottom=0.1, top=top,
                               hspace=0.1, wspace=wspace)
    signals = figure.add_subplot(grid[0, 0])
    errors = figure.add_subplot(grid[1, 0], sharex=signals)
    side = figure.add_subplot(grid[:, 1])
    drawn = trial_column(signals, errors, times, lines, error_linewidth=1.0,
                         zero_line_first=False)
    signals.set_ylim(-signal_limit, signal_limit)
    signals.set_ylabel("position (cm)")
    signals.tick_params(labelbottom=False)
    errors.set_ylim(-error_limit, error_limit)
    errors.set_xlim(0.0, duration)
    errors.set_xlabel("time (s)")
    errors.set_ylabel("error (cm)")
    figure.align_ylabels((signals, errors))
    return TrialPanels(signals, errors, side, drawn)


def legend_handles(panels: TrialPanels, lines: Mapping[str, TrialLine]) -> list[Line2D]:
    """The lines of ``panels`` that ``lines`` gives a legend label, in its order."""
    return [panels.lines[gid] for gid, (_, _, label) in lines.items() if label is not None]


def tracking_comparison_figure(times: np.ndarray, truth: np.ndarray,
                               estimates: dict[str, tuple[np.ndarray, str]],
                               readings: dict[str, tuple[np.ndarray, str]] | None = None,
                               title: str = "") -> Figure:
    """Estimates beside the truth (top) and their errors (bottom), for one trial.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    truth : array_like, shape (n,)
        True position (cm).
    estimates : dict
        Label → (estimated positions (cm), shape (n,); style role such as ``"estimate"``
        or ``"alternative"``). Each is drawn on top and its error (estimate − truth) below.
    readings : dict, optional
        Label → (sensor readings (cm), shape (n,); role ``"vision"`` or
        ``"proprioception"``), drawn on top only.
    title : str
        Title of the top panel (say what changed, e.g. "σ_v = σ_p = 1.5 cm").

    Returns
    -------
    Figure
        Two panels sharing the time axis, drawn by :func:`trial_column`; lines in the
        order readings, truth, estimates; the legend in one row above the top panel,
        under its title, clear of the data.
    """
    times = np.asarray(times, dtype=float)
    truth = np.asarray(truth, dtype=float)
    fig, (ax_top, ax_err) = plt.subplots(2, 1, figsize=(10, 6.2), sharex=True,
                                         gridspec_kw={"height_ratios": [1.5, 1]})
    lines: dict[str, TrialLine] = {}
    values: dict[str, np.ndarray] = {}
    for label, (series, role) in (readings or {}).items():
        lines[f"reading: {label}"], values[f"reading: {label}"] = (0, role, label), series
    lines["truth"], values["truth"] = (0, "truth", TRUE_POSITION_LABEL), truth
    for label, (series, role) in estimates.items():
        series = np.asarray(series, dtype=float)
        lines[f"estimate: {label}"], values[f"estimate: {label}"] = (0, role, label), series
        lines[f"error: {label}"], values[f"error: {label}"] = (1, role, label), series - truth
    trial_column(ax_top, ax_err, times, lines, values, error_linewidth=1.1,
                 zero_line_first=True)
    label_axes(ax_top, ylabel="position (cm)")
    legend_above(ax_top, title)
    label_axes(ax_err, "time (s)", "error (cm)", xlim=(times[0], times[-1]))
    fig.tight_layout()
    return fig


def paired_mse_figure(mse_first: np.ndarray, mse_second: np.ndarray, label_first: str,
                      label_second: str, title: str = "") -> Figure:
    """One point per Monte Carlo run: its MSE in one condition against the other.

    Points below the diagonal are runs in which the second condition had the smaller
    error. Run r of both conditions must come from the same noise (paired runs).

    Parameters
    ----------
    mse_first, mse_second : array_like, shape (runs,)
        Per-run MSEs (cm²) of the two conditions.
    label_first, label_second : str
        Names of the conditions (x and y axis).
    title : str
        Title (say what was compared).

    Returns
    -------
    Figure
        The first line holds the runs, the second the diagonal "no change".
    """
    first = np.asarray(mse_first, dtype=float)
    second = np.asarray(mse_second, dtype=float)
    if first.shape != second.shape or first.ndim != 1:
        raise ValueError(f"mse_first and mse_second must be paired vectors (runs,), got "
                         f"shapes {first.shape} and {second.shape}")
    fig, ax = plt.subplots(figsize=(5.6, 5.2))
    ax.plot(first, second, linestyle="none", marker="o", markersize=3.5, alpha=0.5,
            color=COLORS["estimate"], label=f"one Monte Carlo run ({first.size} in all)")
    top = 1.1 * float(max(first.max(), second.max()))
    ax.plot([0.0, top], [0.0, top], **style("truth", linewidth=1, label="no change (diagonal)"))
    ax.plot([first.mean()], [second.mean()], linestyle="none", marker="D", markersize=8,
            markeredgecolor="black", color=COLORS["prediction"], label="Monte Carlo mean")
    ax.set_aspect("equal")
    label_axes(ax, f"MSE, {label_first} (cm²)", f"MSE, {label_second} (cm²)", title,
               xlim=(0.0, top), ylim=(0.0, top), legend={"loc": "upper left", "fontsize": 9})
    return fig
