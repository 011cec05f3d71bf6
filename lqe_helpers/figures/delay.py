"""Figures of notebook 05 (sensory delay): the late signal, compensation, and its limits.

Also the painter of notebook 05's explorer (:func:`delay_panels`): one trial's signals
over its errors by :func:`~lqe_helpers.figures.common.trial_column` (the painter of the
notebook's Figure 3), built once with no data and refilled by
:mod:`lqe_helpers.explorers.delay` on every slider move.
"""

from __future__ import annotations

from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

from ..plotting import COLORS, DATA_UNDER_LINES, style
from .common import (
    TRUE_POSITION_LABEL,
    TrialLine,
    interval_arrays,
    label_axes,
    mean_band,
    plot_series,
    tracking_comparison_figure,
    trial_column,
)


def delay_figure(times: np.ndarray, truth: np.ndarray, delayed_readings: np.ndarray,
                 delayed_estimate: np.ndarray, compensated: np.ndarray, delay: float,
                 fast_window: tuple[float, float] = (3.75, 4.35)) -> Figure:
    """Question (e): truth, late readings, late estimate and compensated estimate.

    Top: the whole trial. Bottom left: the start, with the first ``delay`` seconds
    (nothing has arrived yet) shaded. Bottom right: a window of fast flight, titled with
    its times only (what it shows is the student's to find).

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s), wall-clock.
    truth : array_like, shape (n,)
        True position (cm).
    delayed_readings : array_like, shape (n,)
        Readings as they arrive, y_(j−δ) (cm); NaN before the first one.
    delayed_estimate : array_like, shape (n,)
        Position of the newest estimate, ẑ_(j−δ) (cm); NaN before the first one.
    compensated : array_like, shape (n,)
        Position of the compensated estimate z*_j = A^δ ẑ_(j−δ) (cm); NaN before j = δ.
    delay : float
        The delay d (s), > 0.
    fast_window : tuple of float
        (start, end) of the bottom-right zoom (s).

    Returns
    -------
    Figure
        Three panels; in each the lines are, in order, readings, truth, delayed estimate,
        compensated estimate.
    """
    times = np.asarray(times, dtype=float)
    if delay <= 0:
        raise ValueError(f"delay must be > 0 s, got {delay}")
    series = [
        (delayed_readings, "vision", r"vision, delayed $y_{j-\delta}$"),
        (truth, "truth", TRUE_POSITION_LABEL),
        (delayed_estimate, "estimate", r"delayed estimate $\hat z_{j-\delta}$"),
        (compensated, "prediction", r"compensated $z^*_j = A^\delta \hat z_{j-\delta}$"),
    ]
    fig = plt.figure(figsize=(10, 7.5))
    grid = fig.add_gridspec(2, 2, height_ratios=[1.05, 1], hspace=0.45, wspace=0.22)
    ax_all = fig.add_subplot(grid[0, :])
    ax_start = fig.add_subplot(grid[1, 0])
    ax_fast = fig.add_subplot(grid[1, 1])
    windows = ((ax_all, (times[0], times[-1])), (ax_start, (times[0], times[0] + 5 * delay)),
               (ax_fast, fast_window))
    for ax, (start, end) in windows:
        shown = (times >= start) & (times <= end)
        plot_series(ax, times, series, shown)
        label_axes(ax, "time (s)", "position (cm)", xlim=(start, end))
    label_axes(ax_all, title=f"Vision delayed by d = {delay:g} s: the whole trial",
               legend={"loc": "upper center", "bbox_to_anchor": (0.5, -0.18), "ncol": 4,
                       "markerscale": 3})
    ax_start.axvspan(times[0], times[0] + delay, color=COLORS["vision"], alpha=0.25,
                     linewidth=0)
    ax_start.set_title(f"Start: nothing before t = d = {delay:g} s (shaded)")
    ax_fast.set_title(f"Fast flight, {fast_window[0]:g}–{fast_window[1]:g} s")
    return fig


def delay_sweep_figure(delays: np.ndarray, delayed, compensated, undelayed_mse: float,
                       theory_delays: np.ndarray, theory: np.ndarray,
                       late_eye_mse: np.ndarray, share, delay: float) -> Figure:
    """What compensation wins as the delay grows: MSEs (left) and the share removed (right).

    Parameters
    ----------
    delays : array_like, shape (s,)
        The delays simulated (s), increasing, starting at 0.
    delayed, compensated : sequence of metrics.Interval, length s
        Monte Carlo MSE (cm²) of the delayed and of the compensated position.
    undelayed_mse : float
        MSE of the filter with no delay (cm²), drawn as a horizontal line.
    theory_delays, theory : array_like, shape (t,)
        Delays (s) and the theoretical MSE of the compensated position (cm²); only the
        part within ``delays`` is drawn.
    late_eye_mse : array_like, shape (s,)
        MSE of the true position seen late (cm²); its first entry (no delay) is left out.
    share : sequence of metrics.Interval, length s
        Share of the delayed MSE that compensation removes, paired per run (1 = all).
    delay : float
        The question's delay (s), marked in both panels.

    Returns
    -------
    Figure
        Two panels: the MSEs against the delay (log scale; lines first the delayed, the
        compensated, the theory, the late eye) and the share removed (its means the first
        line), whose arrows point at the deepest loss before ``delay`` and the middle of the late
        delays where compensation hurts (when there are such delays).
    """
    delays = np.asarray(delays, dtype=float)
    theory_delays = np.asarray(theory_delays, dtype=float)
    theory = np.asarray(theory, dtype=float)
    late_eye_mse = np.asarray(late_eye_mse, dtype=float)
    fig, (ax_mse, ax_share) = plt.subplots(1, 2, figsize=(11, 4.6),
                                           gridspec_kw={"wspace": 0.28})
    delayed_mean = mean_band(ax_mse, delays, delayed, "estimate",
                              "delayed estimate (simulation)")
    compensated_mean = mean_band(ax_mse, delays, compensated, "prediction",
                                  "compensated (simulation)")
    shown = theory_delays <= delays[-1] + 1e-9
    ax_mse.plot(theory_delays[shown], theory[shown],
                **style("reference", linewidth=2.2,
                        label=r"compensated, theory $[P^*_\delta]_{pp}$"))
    ax_mse.plot(delays[1:], late_eye_mse[1:],
                **style("truth", linestyle=(0, (6, 2, 1, 2)), linewidth=1.1,
                        label="perfect but late eye"))
    ax_mse.axhline(undelayed_mse, **style("alternative", linewidth=1.1, label="undelayed filter"))
    # Scaled to the estimates' MSEs: the late eye, near 0 at the shortest delays, is cut.
    estimates = np.concatenate([delayed_mean, compensated_mean, theory[shown]])
    estimates = estimates[estimates > 0]
    ax_mse.set_yscale("log")
    ax_mse.set_ylim(0.5 * estimates.min(), 2.0 * estimates.max())
    share_mean = mean_band(ax_share, delays, share, "prediction",
                            "1 − MSE compensated / MSE delayed", linestyle="-", marker=".",
                            markersize=4)
    for ax in (ax_mse, ax_share):
        ax.axvline(delay, color=COLORS["vision"], linewidth=1)
        ax.set_xlim(0, delays[-1])
        ax.set_xlabel("delay d (s)")
    ax_mse.text(delay + 0.01 * delays[-1], 0.97, f"d = {delay} s", fontsize=9, color="0.35",
                va="top", transform=ax_mse.get_xaxis_transform())
    label_axes(ax_mse, ylabel="position MSE (cm²)", title="MSE against the delay",
               legend={"loc": "lower right", "fontsize": 8.5})

    _, share_low, share_high = interval_arrays(share)
    ax_share.axhline(0, color=COLORS["truth"], linewidth=0.9)
    middle = 0.45 * delays[-1]
    ax_share.text(middle, 0.03, "↑ compensation helps", fontsize=9, ha="center", va="bottom")
    ax_share.text(middle, -0.03, "↓ compensation hurts", fontsize=9, ha="center", va="top")
    blended = ax_share.get_xaxis_transform()          # x in data, y in axes fraction
    arrow = {"arrowstyle": "->", "linewidth": 0.8}
    early = (delays > 0) & (delays < delay) & (share_mean < 0)
    if early.any():
        i = int(np.flatnonzero(early)[np.argmin(share_mean[early])])
        ax_share.annotate("too short to be\nworth the jitter", xy=(delays[i], share_mean[i]),
                          xytext=(delays[i] + 0.14 * delays[-1], 0.2), textcoords=blended,
                          fontsize=9, ha="center", va="top", arrowprops=arrow)
    late = np.flatnonzero((delays > delay) & (share_mean < 0))
    if late.size:
        i = int(late[late.size // 2])
        ax_share.annotate("so long that the\nprediction overshoots",
                          xy=(delays[i], share_mean[i]),
                          xytext=(delays[i] - 0.22 * delays[-1], 0.2), textcoords=blended,
                          fontsize=9, ha="center", va="top", arrowprops=arrow)
    ax_share.set_ylim(min(-0.1, share_low.min()) - 0.1, max(0.1, share_high.max()) + 0.15)
    label_axes(ax_share, ylabel="share of the delayed MSE removed",
               title="What compensation wins (paired, per run)",
               legend={"loc": "lower left", "fontsize": 8.5})
    return fig


def prediction_error_sources_figure(theory_delays: np.ndarray, theory: np.ndarray,
                                    extrapolated: np.ndarray, jerks: np.ndarray,
                                    delays: np.ndarray, compensated,
                                    takeover: float) -> Figure:
    """The theoretical prediction MSE against the delay, split into its two sources (log–log).

    Parameters
    ----------
    theory_delays : array_like, shape (t,)
        Delays (s) of the theory, increasing; only those > 0 are drawn.
    theory, extrapolated, jerks : array_like, shape (t,)
        Theoretical MSE of the compensated position (cm²): the total, the old estimation
        error carried forward alone, and the jerks accumulated during the gap alone.
    delays : array_like, shape (s,)
        The delays simulated (s), starting at 0; shaded, and the simulated MSEs drawn.
    compensated : sequence of metrics.Interval, length s
        Monte Carlo MSE of the compensated position (cm²); its first entry is left out.
    takeover : float
        The delay (s) from which the jerks exceed the extrapolated error, marked.

    Returns
    -------
    Figure
        One log–log panel; lines in the order total, extrapolated, jerks, simulation.
    """
    theory_delays = np.asarray(theory_delays, dtype=float)
    delays = np.asarray(delays, dtype=float)
    positive = theory_delays > 0
    x = theory_delays[positive]
    theory = np.asarray(theory, dtype=float)[positive]
    fig, ax = plt.subplots(figsize=(8, 4.6))
    ax.plot(x, theory, **style("reference", linewidth=2.2, label="theory: total"))
    ax.plot(x, np.asarray(extrapolated, dtype=float)[positive],
            **style("estimate", linestyle="--", label="old estimation error, extrapolated"))
    ax.plot(x, np.asarray(jerks, dtype=float)[positive],
            **style("alternative", label="jerks accumulated during the gap"))
    simulated, _, _ = interval_arrays(compensated)
    ax.plot(delays[1:], simulated[1:],
            **style("prediction", linestyle="none", marker="o", markersize=3.5,
                    label="compensated, simulation"))
    ax.axvspan(delays[1], delays[-1], color=COLORS["vision"], alpha=0.12, linewidth=0,
               label="delays simulated in Figure 4")
    ax.axvline(takeover, color=COLORS["truth"], linewidth=0.8)
    ax.text(takeover * 0.93, 0.04, f"jerks take over\nfrom d = {takeover:.2f} s", fontsize=9,
            ha="right", transform=ax.get_xaxis_transform())
    label_axes(ax, "delay d (s)", "prediction MSE (cm²)",
               "Where the prediction error comes from (theory)", xscale="log", yscale="log",
               xlim=(x[0], x[-1]), ylim=(1e-4 * theory.min(), 10.0 * theory.max()),
               legend={"loc": "upper left", "fontsize": 9})
    return fig


def late_eye_figure(times: np.ndarray, truth: np.ndarray, delayed: np.ndarray,
                    compensated: np.ndarray, late_eye: np.ndarray, title: str = "") -> Figure:
    """Notebook 05's Figure 3: the delayed and compensated estimates and a perfect but late eye.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    truth, delayed, compensated, late_eye : array_like, shape (n,)
        True position, the delayed estimate ``p̂_{j−δ}``, the compensated ``p*_j`` and the
        true position seen δ samples late (cm); NaN where nothing has arrived.
    title : str
        Title of the top panel.

    Returns
    -------
    Figure
        :func:`~lqe_helpers.figures.common.tracking_comparison_figure` of the three: blue,
        vermillion and pink dotted on top, their errors below.
    """
    return tracking_comparison_figure(times, truth, {
        r"delayed estimate $\hat p_{j-\delta}$": (delayed, "estimate"),
        r"compensated $p^*_j$": (compensated, "prediction"),
        r"perfect but late eye $p_{j-\delta}$": (late_eye, "reference")}, title=title)


#: The explorer's lines: gid → (axes index, role, legend label). The gids let tests find
#: them.
DELAY_LINES: dict[str, TrialLine] = {
    "vision": (0, "vision", "vision, delayed  $y_{j-δ}$"),
    "truth": (0, "truth", TRUE_POSITION_LABEL),
    "delayed": (0, "estimate", "delayed estimate  $\\hat z_{j-δ}$"),
    "prediction": (0, "prediction", "compensated  $z^*_j = A^δ\\,\\hat z_{j-δ}$"),
    "delayed-error": (1, "estimate", "delayed estimate error"),
    "prediction-error": (1, "prediction", "compensated error"),
}
_SPAN = "nothing-yet"
_SPAN_STYLE = {"color": COLORS["vision"], "alpha": 0.2, "linewidth": 0, "gid": _SPAN,
               "zorder": DATA_UNDER_LINES}


class DelayPanels(NamedTuple):
    """The axes :func:`delay_panels` draws and the lines and spans the explorer refills."""

    axes: tuple[Axes, Axes]
    lines: dict[str, Line2D]
    spans: tuple[Rectangle, Rectangle]


def delay_panels(figure: Figure, window: float) -> DelayPanels:
    """Notebook 05's explorer on the empty ``figure``: signals over errors, no data yet.

    The lines of :data:`DELAY_LINES`, a legend above, and in each axes an empty span
    "nothing has arrived yet"; the time axis spans 0 to ``window`` (s).
    """
    axes = figure.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [2.2, 1]})
    figure.subplots_adjust(top=0.91, bottom=0.1, hspace=0.12)
    top, bottom = axes
    # The notebooks' painter of a trial's signals over its errors, with no data yet.
    lines = trial_column(top, bottom, np.empty(0), DELAY_LINES, error_linewidth=1.2,
                         zero_line_first=False)
    handles = [lines[gid] for gid, (index, _, _) in DELAY_LINES.items() if index == 0]
    handles.append(Patch(**{k: v for k, v in _SPAN_STYLE.items() if k != "gid"},
                         label="nothing has arrived yet"))
    figure.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 0.995), ncol=5,
                  fontsize=8, handlelength=2.2, columnspacing=1.2, markerscale=2.5)
    top.set_ylabel("position (cm)")
    # Under the band and the lines (above the grid's zorder 1.5): a fixed text painted
    # before what a move changes stays in the cached layer; above the band it would be
    # repainted with it on every move (the band's extent is its whole axes). The band
    # reaches this corner only when the delay spans most of the window shown (a short
    # trial); the text then shows through it.
    bottom.text(0.99, 0.95, "error = estimate − true position", transform=bottom.transAxes,
                ha="right", va="top", fontsize=8, zorder=(1.5 + DATA_UNDER_LINES) / 2)
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("error (cm)")
    bottom.set_xlim(0.0, window)
    figure.align_ylabels(axes)
    spans = tuple(ax.axvspan(0.0, 0.0, **_SPAN_STYLE) for ax in axes)
    for ax in axes:
        ax.set_xlim(0.0, window)  # axvspan would widen them
    return DelayPanels((top, bottom), lines, spans)
