"""Figures of notebook 01 (vision only): where the filtered estimate's error comes from.

:func:`estimate_error_figure` (errors with the filter's own band and the systematic error)
and :func:`lag_figure` (noise-free outputs of the filter and a smoother beside the truth:
who lags, who leads).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from ..plotting import COLORS, style
from .common import label_axes, plot_series


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
                        label="±2σ of the filter's own variance")
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
        series = [(truth, "truth", "true position")]
        series += [(values, role, label) for label, (values, role) in curves.items()]
        plot_series(ax, times, series, shown)
        label_axes(ax, "time (s)", title=title, xlim=(start, end),
                   legend={"loc": "lower left", "fontsize": 8})
    label_axes(axes[0, 0], ylabel="position (cm)")
    fig.tight_layout()
    return fig
