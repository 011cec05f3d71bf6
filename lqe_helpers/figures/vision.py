"""Figures of notebook 01 (vision only): where the filtered estimate's error comes from.

:func:`estimate_error_figure` (errors with the filter's own band and the systematic error)
and :func:`lag_figure` (noise-free outputs of the filter and a smoother beside the truth:
who lags, who leads); :func:`vision_panel`, the painter of notebook 01's explorer: one trial's
signals drawn by :func:`~lqe_helpers.figures.common.trial_column` (the painter of the
notebook's Figures 1–2) with the filter's ±2σ band, built once and refilled by
:mod:`lqe_helpers.explorers.vision` on every slider move.
"""

from __future__ import annotations

from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import FillBetweenPolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..plotting import COLORS, DATA_UNDER_LINES, label_time_position, style
from .common import (
    BAND_LABEL,
    ESTIMATE_LABEL,
    TrialLine,
    label_axes,
    plot_series,
    trial_column,
)
from .common import NOISY_VISION_LABEL as VISION_LABEL  # the explorer's readings
from .common import TRUE_POSITION_LABEL as TRUTH_LABEL  # the explorer's truth line

#: The explorer's lines by gid (:data:`~lqe_helpers.figures.common.TrialLine`).
_VISION_LINES: dict[str, TrialLine] = {
    "vision": (0, "vision", VISION_LABEL),
    "truth": (0, "truth", TRUTH_LABEL),
    "estimate": (0, "estimate", ESTIMATE_LABEL),
}


class VisionPanel(NamedTuple):
    """The artists :func:`vision_panel` draws; the explorer refills all but the truth."""

    ax: Axes
    vision: Line2D
    band: FillBetweenPolyCollection
    estimate: Line2D


def vision_panel(figure: Figure, times: np.ndarray, truth: np.ndarray,
                 duration: float) -> VisionPanel:
    """Notebook 01's explorer on the empty ``figure``: one trial, no data but the truth.

    ``times`` (s) and ``truth`` (true position, cm), shape (n,) each. The vision, band
    (the filter's ±2σ) and estimate wait for data; the x axis spans 0 to ``duration`` (s).
    """
    ax = figure.add_subplot()
    times = np.asarray(times, dtype=float)
    empty = np.zeros_like(times)
    lines = trial_column(ax, None, times, _VISION_LINES,
                         {"vision": empty, "truth": truth, "estimate": empty},
                         error_linewidth=1.0, zero_line_first=False)
    band = ax.fill_between(times, times, times, color=COLORS["estimate"], alpha=0.15,
                           linewidth=0, label=BAND_LABEL, zorder=DATA_UNDER_LINES)
    ax.set_xlim(0.0, duration)
    label_time_position(ax)
    ax.legend(handles=[lines["vision"], band, lines["truth"], lines["estimate"]],
              loc="upper center", bbox_to_anchor=(0.5, -0.17), ncol=4, fontsize=9,
              markerscale=3)
    figure.subplots_adjust(left=0.08, right=0.98, top=0.97, bottom=0.27)
    return VisionPanel(ax, lines["vision"], band, lines["estimate"])


def estimate_error_figure(times: np.ndarray,
                          panels: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray, str]],
                          skipped: float = 0.0) -> Figure:
    """Errors of filtered estimates with the filter's own ±2σ band, one panel per case.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    panels : dict
        Panel title (e.g. "σ_v = 1.5 cm") → (error of the estimate, estimate − truth (cm),
        shape (n,); the filter's own standard deviation of its position (cm), shape (n,),
        drawn as a ±2σ band around zero; the systematic error, the error of the same
        filter fed noise-free readings (cm), shape (n,); style role of the error line).
    skipped : float
        Length (s) of a start-up shaded grey and labelled as left out of the MSEs; 0 for
        none.

    Returns
    -------
    Figure
        One panel per entry, sharing both axes; in each, the first line is the error and
        the second the systematic error.
    """
    times = np.asarray(times, dtype=float)
    if not panels:
        raise ValueError("panels must hold at least one case, got none")
    if skipped < 0:
        raise ValueError(f"skipped must be >= 0 s, got {skipped}")
    fig, axes = plt.subplots(len(panels), 1, figsize=(10, 3 * len(panels)), sharex=True,
                             sharey=True, squeeze=False)
    for ax, (title, (error, std, systematic, role)) in zip(axes[:, 0], panels.items(),
                                                           strict=True):
        band = 2 * np.asarray(std, dtype=float)
        ax.fill_between(times, -band, band, color=COLORS[role], alpha=0.15, linewidth=0,
                        label=BAND_LABEL)
        ax.plot(times, np.asarray(error, dtype=float),
                **style(role, linewidth=1.0, linestyle="-", label="error"))
        ax.plot(times, np.asarray(systematic, dtype=float),
                **style("reference", linewidth=2.2,
                        label="systematic error (noise-free readings)"))
        if skipped > 0:
            ax.axvspan(times[0], skipped, color=COLORS["vision"], alpha=0.15, linewidth=0,
                       label="start-up, left out of the MSEs")
        ax.set_title(title, loc="left")
        label_axes(ax, ylabel="estimate − truth (cm)",
                   legend={"loc": "upper right", "ncol": 4, "fontsize": 8})
    label_axes(axes[-1, 0], "time (s)", xlim=(times[0], times[-1]))
    fig.tight_layout()
    return fig


def lag_figure(times: np.ndarray, truth: np.ndarray,
               panels: dict[str, dict[str, tuple[np.ndarray, str]]],
               window: tuple[float, float]) -> Figure:
    """Estimates beside the true path over a short window, one panel per case, side by side.

    Made for noise-free outputs (a filter or a smoother fed the true positions): what is
    left is their systematic error, so a lag shows as a curve shifted to the right of the
    true path, a lead as one shifted to the left.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    truth : array_like, shape (n,)
        True position (cm), drawn black in every panel.
    panels : dict
        Panel title (e.g. "σ_v = 1.5 cm") → {legend label → (positions (cm), shape (n,);
        style role such as ``"estimate"`` or ``"alternative"``)}.
    window : (float, float)
        Start and end (s) of the time shown, inside ``times``.

    Returns
    -------
    Figure
        One panel per entry, sharing the position axis; in each, the truth first, then
        the curves in the order given.
    """
    times = np.asarray(times, dtype=float)
    truth = np.asarray(truth, dtype=float)
    if not panels:
        raise ValueError("panels must hold at least one case, got none")
    start, end = (float(value) for value in window)
    if not times[0] <= start < end <= times[-1]:
        raise ValueError(f"window must be (start, end) with {times[0]:g} <= start < end <= "
                         f"{times[-1]:g} s, got {window}")
    shown = (times >= start) & (times <= end)
    fig, axes = plt.subplots(1, len(panels), figsize=(5 * len(panels), 4), sharey=True,
                             squeeze=False)
    for ax, (title, curves) in zip(axes[0], panels.items(), strict=True):
        series = [(truth, "truth", TRUTH_LABEL)]
        series += [(values, role, label) for label, (values, role) in curves.items()]
        plot_series(ax, times, series, shown)
        label_axes(ax, "time (s)", title=title, xlim=(start, end),
                   legend={"loc": "lower left", "fontsize": 8})
    label_axes(axes[0, 0], ylabel="position (cm)")
    fig.tight_layout()
    return fig
