"""Figures of notebook 02 (initial covariance): the start-up, the gains, the sweep over P0.

Also the painter of notebook 02's explorer (:func:`start_up_panels`): built once with no
data, refilled by :mod:`lqe_helpers.explorers.initial_covariance` on every slider move.
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

from ..plotting import COLORS, DATA_UNDER_LINES, style
from .common import (
    BAND_LABEL,
    ESTIMATE_LABEL,
    VISION_READINGS_LABEL,
    errorbar_intervals,
    first_seconds,
    label_axes,
    legend_above,
    mark_values,
    plot_series,
)
from .common import NOISY_VISION_LABEL as VISION_LABEL  # the explorer's readings


def start_up_figure(times: np.ndarray, truth: np.ndarray,
                    estimates: dict[str, tuple[np.ndarray, str]],
                    readings: np.ndarray | None = None, until: float = 2.0) -> Figure:
    """The first seconds of a trial: position (top) and velocity (bottom).

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    truth : array_like, shape (n, >=2)
        True states; columns 0 and 1 are position (cm) and velocity (cm/s).
    estimates : dict
        Label → (estimated states, shape (n, >=2); style role).
    readings : array_like, shape (n,), optional
        Visual readings (cm), drawn in the position panel.
    until : float
        Last time shown (s), > 0.

    Returns
    -------
    Figure
        Two panels sharing the time axis; the legend above the position panel.
    """
    times, shown = first_seconds(times, until)
    truth = np.asarray(truth, dtype=float)
    fig, (ax_p, ax_v) = plt.subplots(2, 1, figsize=(10, 6.6), sharex=True)
    if readings is not None:
        plot_series(ax_p, times, [(readings, "vision", VISION_READINGS_LABEL)], shown)
    for column, ax in enumerate((ax_p, ax_v)):
        plot_series(ax, times, [(truth[:, column], "truth", "truth")]
                    + [(np.asarray(states, dtype=float)[:, column], role, label)
                       for label, (states, role) in estimates.items()], shown)
    label_axes(ax_p, ylabel="position (cm)")
    legend_above(ax_p, "Position")
    label_axes(ax_v, "time (s)", "velocity (cm/s)", "Velocity", xlim=(0.0, until))
    fig.tight_layout()
    return fig


def squared_error_figure(times: np.ndarray, curves: dict[str, tuple[np.ndarray, str]],
                         threshold: float | None = None,
                         marks: dict[str, tuple[float, str]] | None = None,
                         until: float = 2.0) -> Figure:
    """Monte Carlo mean squared error over time on a logarithmic axis.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    curves : dict
        Label → (squared error curve (cm²), shape (n,), > 0; style role).
    threshold : float, optional
        A level to draw as a dashed horizontal line (cm²), e.g. 2 × the steady level.
    marks : dict, optional
        Label → (time (s); role) drawn as vertical lines, e.g. convergence times.
    until : float
        Last time shown (s), > 0.

    Returns
    -------
    Figure
        One panel; the curves are its first lines, in the order given.
    """
    times, shown = first_seconds(times, until)
    fig, ax = plt.subplots(figsize=(10, 4.6))
    plot_series(ax, times, [(curve, role, label) for label, (curve, role) in curves.items()],
                shown)
    if threshold is not None:
        ax.axhline(threshold, color=COLORS["vision"], linestyle="--", linewidth=1.2,
                   label="threshold")
    for label, (time, role) in (marks or {}).items():
        ax.axvline(time, color=COLORS[role], linestyle="--", linewidth=1, label=label)
    label_axes(ax, "time (s)", "squared position error (cm²)", yscale="log", xlim=(0.0, until),
               legend={"loc": "upper right", "fontsize": 9})
    fig.tight_layout()
    return fig


def belief_and_error_figure(times: np.ndarray,
                            filters: dict[str, tuple[np.ndarray, np.ndarray, float, str]],
                            steady_variance: float, threshold: float, runs: int,
                            until: float = 2.0,
                            ylim: tuple[float, float] = (0.05, 15.0)) -> Figure:
    """Each filter's actual squared error beside what it believes it to be, over time.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    filters : dict
        Name (e.g. "P0 = diag(1)") → (Monte Carlo mean squared position error (cm²),
        shape (n,); the filter's own position variance (cm²), shape (n,); its convergence
        time (s); style role).
    steady_variance : float
        The steady-state position variance [P̂∞]pp (cm²).
    threshold : float
        The convergence threshold (cm²), e.g. 2 × the steady level.
    runs : int
        Number of Monte Carlo runs behind the mean, for the legend.
    until : float
        Last time shown (s), > 0.
    ylim : (float, float)
        Range of the logarithmic axis (cm²); a very uncertain start lies above it.

    Returns
    -------
    Figure
        One panel; for each filter in turn, its error line and then its variance line.
    """
    times, window = first_seconds(times, until)
    fig, ax = plt.subplots(figsize=(10, 4.8))
    for name, (squared_error, own_variance, converged, role) in filters.items():
        ax.plot(times[window], np.asarray(squared_error, dtype=float)[window],
                **style(role, label=f"{name}: mean squared error ({runs} runs)"))
        ax.plot(times[window], np.asarray(own_variance, dtype=float)[window],
                **style(role, linestyle=":", linewidth=2.2, label=f"{name}: filter's own variance"))
        ax.axvline(converged, color=COLORS[role], linewidth=1, alpha=0.7)
        ax.text(converged, 0.97, f" converged\n {converged:.2f} s", color=COLORS[role],
                fontsize=9, va="top", transform=ax.get_xaxis_transform())
    ax.axhline(steady_variance, **style("reference", label="steady-state variance (theory)"))
    ax.axhline(threshold, color=COLORS["vision"], linestyle="--", linewidth=1.2,
               label="convergence threshold: 2 × steady level")
    label_axes(ax, "time (s)", "squared position error (cm²)",
               "The error over time: what each filter achieves, and what it believes",
               yscale="log", xlim=(0, until), ylim=ylim,
               legend={"loc": "upper center", "bbox_to_anchor": (0.5, -0.14), "ncol": 3,
                       "fontsize": 9})
    return fig


def gains_figure(times: np.ndarray, gains: dict[str, tuple[np.ndarray, str]],
                 steady_gain: np.ndarray, until: float = 1.5) -> Figure:
    """The gains of position, velocity and acceleration over time, one panel each (log scale).

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    gains : dict
        Name (e.g. "P0 = diag(1)") → (the gains K_j of a one-sensor filter, shape (n, 3):
        position (no unit), velocity (1/s), acceleration (1/s²); style role).
    steady_gain : array_like, shape (3,)
        The steady-state gain K∞, drawn in every panel.
    until : float
        Last time shown (s), > 0.

    Returns
    -------
    Figure
        Three panels (position, velocity, acceleration); in each, one line per entry of
        ``gains`` in order, then K∞.
    """
    times, early = first_seconds(times, until)
    steady_gain = np.asarray(steady_gain, dtype=float).reshape(-1)
    units = ("position gain", "velocity gain (1/s)", "acceleration gain (1/s²)")
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.8))
    titles = ("position", "velocity", "acceleration")
    for state, (ax, unit, title) in enumerate(zip(axes, units, titles, strict=True)):
        plot_series(ax, times, [(np.asarray(gain, dtype=float)[:, state], role, name)
                                for name, (gain, role) in gains.items()], early)
        ax.axhline(steady_gain[state], **style("reference", label="steady state K∞"))
        label_axes(ax, "time (s)", unit, title, yscale="log", xlim=(0, until))
    fig.suptitle("Gains over time: P0 sets the start, not the end")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=3)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    return fig


def p0_sweep_figure(p0_grid: np.ndarray, convergence, start_up, settled, burn_in: float,
                    question_values: dict[str, float], scales: dict[str, float],
                    plateau: tuple[float, float], plateau_margin: float) -> Figure:
    """Convergence time (left) and MSEs (right) against p0 in P0 = p0 · I, log axis.

    Parameters
    ----------
    p0_grid : array_like, shape (s,)
        The p0 swept (cm², cm²/s², cm²/s⁴), > 0.
    convergence : sequence of metrics.Interval, length s
        Convergence time (s) with its 95 % interval.
    start_up, settled : sequence of metrics.Interval, length s
        Position MSE (cm²) over the first ``burn_in`` seconds and after them.
    burn_in : float
        Length of the start-up window (s), for the legend.
    question_values : dict
        Label (e.g. "diag(1)") → p0 of the question, marked grey.
    scales : dict
        Label (e.g. "A²") → a squared scale of the flight, marked pink dotted.
    plateau : (float, float)
        The range of p0 whose start-up MSE is within ``plateau_margin`` of the best, shaded.
    plateau_margin : float
        That margin as a fraction (0.1 = 10 %), for the legend.

    Returns
    -------
    Figure
        Two panels sharing the p0 axis.
    """
    p0_grid = np.asarray(p0_grid, dtype=float)
    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(11, 4.2))
    errorbar_intervals(ax_t, p0_grid, convergence, "estimate", marker="o",
                        label="convergence time")
    ax_t.set_ylabel("convergence time (s)")
    errorbar_intervals(ax_m, p0_grid, start_up, "estimate", marker="o",
                        label=f"MSE over the first {burn_in:g} s")
    errorbar_intervals(ax_m, p0_grid, settled, "alternative", marker="s", linestyle="-.",
                        label=f"MSE after {burn_in:g} s")
    ax_m.set_ylabel("position MSE (cm²)")
    ax_m.set_ylim(0, None)
    for ax in (ax_t, ax_m):
        ax.set_xscale("log")
        ax.set_xlabel("p0 in P0 = p0 · I (cm², cm²/s², cm²/s⁴)")
        mark_values(ax, question_values, COLORS["vision"], linewidth=1)
        ax.axvspan(plateau[0], plateau[-1], color=COLORS["estimate"], alpha=0.12, linewidth=0,
                   label=f"plateau: start-up MSE within {100 * plateau_margin:.0f} % of best")
        for k, (name, value) in enumerate(scales.items()):
            ax.axvline(value, **style("reference", label="squared scales of the flight"
                                      if k == 0 else None))
            ax.annotate(name, (value, 0.88), xycoords=("data", "axes fraction"), xytext=(2, 0),
                        textcoords="offset points", color=COLORS["reference"], fontsize=9)
        ax.legend(loc="center right", fontsize=9)
    ax_t.set_title("How long the start-up lasts")
    ax_m.set_title("How much it costs, and what stays the same")
    fig.tight_layout()
    return fig


#: Labels of the explorer's artists, so tests and readers can find them. Both panels use
#: the same labels: axes 0 is position, axes 1 velocity.
TRUTH_LABEL = "truth"


class StartUpPanels(NamedTuple):
    """The artists :func:`start_up_panels` draws; the explorer refills all but the truth."""

    axes: tuple[Axes, Axes]
    vision: Line2D
    bands: tuple[FillBetweenPolyCollection, FillBetweenPolyCollection]
    estimates: tuple[Line2D, Line2D]


def start_up_panels(figure: Figure, times: np.ndarray, truth: np.ndarray,
                    peak_speed: float) -> StartUpPanels:
    """Notebook 02's explorer on the empty ``figure``: position and velocity, no data yet.

    ``times`` (s), shape (n,); ``truth`` (n, 2 or more): true position (cm) and velocity
    (cm/s) in columns 0 and 1; ``peak_speed`` (cm/s) sets the velocity axis to ±2×.
    """
    position_ax, velocity_ax = figure.subplots(1, 2)
    empty = np.zeros_like(times)
    vision, = position_ax.plot(times, empty, label=VISION_LABEL, **style("vision"))
    bands, estimates = [], []
    for column, ax in enumerate((position_ax, velocity_ax)):
        bands.append(ax.fill_between(times, empty, empty, color=COLORS["estimate"],
                                     alpha=0.15, linewidth=0, label=BAND_LABEL,
                                     zorder=DATA_UNDER_LINES))
        ax.plot(times, truth[:, column], label=TRUTH_LABEL, **style("truth"))
        estimates.append(ax.plot(times, empty, label=ESTIMATE_LABEL, **style("estimate"))[0])
        ax.set_xlim(times[0], times[-1])
        ax.xaxis.set_major_locator(MultipleLocator(0.5))  # fewer labels: faster redraws
        ax.set_xlabel("time (s)")
    position_ax.set_ylabel("position (cm)")
    velocity_ax.set_ylabel("velocity (cm/s)")
    velocity_ax.set_ylim(-2.0 * peak_speed, 2.0 * peak_speed)
    figure.legend(*position_ax.get_legend_handles_labels(), loc="lower center", ncol=4,
                  fontsize=9, markerscale=3)
    figure.subplots_adjust(left=0.07, right=0.98, top=0.97, bottom=0.25, wspace=0.22)
    return StartUpPanels((position_ax, velocity_ax), vision, tuple(bands), tuple(estimates))
