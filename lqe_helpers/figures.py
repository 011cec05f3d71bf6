"""Figures the question notebooks draw, one function per kind of figure.

Each function takes arrays (positions in cm, times in s, MSEs in cm²) and returns a
matplotlib Figure in the pack's Okabe–Ito roles (:func:`lqe_helpers.plotting.style`);
a notebook shows it with :func:`lqe_helpers.plotting.show_figure`. Nothing runs on import.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from .plotting import COLORS, style


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
        Two panels sharing the time axis; lines in the order readings, truth, estimates.
    """
    times = np.asarray(times, dtype=float)
    truth = np.asarray(truth, dtype=float)
    fig, (ax_top, ax_err) = plt.subplots(2, 1, figsize=(10, 6.2), sharex=True,
                                         gridspec_kw={"height_ratios": [1.5, 1]})
    for label, (values, role) in (readings or {}).items():
        ax_top.plot(times, values, **style(role, label=label))
    ax_top.plot(times, truth, **style("truth", label="true position"))
    ax_err.axhline(0.0, color=COLORS["truth"], linewidth=0.8)
    for label, (values, role) in estimates.items():
        values = np.asarray(values, dtype=float)
        ax_top.plot(times, values, **style(role, label=label))
        ax_err.plot(times, values - truth, **style(role, linewidth=1.1, label=label))
    ax_top.set_ylabel("position (cm)")
    ax_top.set_title(title)
    ax_top.legend(loc="upper right", fontsize=9, ncol=2, markerscale=2.5)
    ax_err.set_ylabel("error (cm)")
    ax_err.set_xlabel("time (s)")
    ax_err.set_xlim(times[0], times[-1])
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
    ax.set_xlim(0.0, top)
    ax.set_ylim(0.0, top)
    ax.set_aspect("equal")
    ax.set_xlabel(f"MSE, {label_first} (cm²)")
    ax.set_ylabel(f"MSE, {label_second} (cm²)")
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize=9)
    return fig


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
        Two panels sharing the time axis.
    """
    times = np.asarray(times, dtype=float)
    truth = np.asarray(truth, dtype=float)
    if until <= 0:
        raise ValueError(f"until must be > 0 s, got {until}")
    shown = times <= until
    fig, (ax_p, ax_v) = plt.subplots(2, 1, figsize=(10, 6.6), sharex=True)
    if readings is not None:
        ax_p.plot(times[shown], np.asarray(readings, dtype=float)[shown],
                  **style("vision", label="vision readings"))
    for column, ax in enumerate((ax_p, ax_v)):
        ax.plot(times[shown], truth[shown, column], **style("truth", label="truth"))
        for label, (states, role) in estimates.items():
            ax.plot(times[shown], np.asarray(states, dtype=float)[shown, column],
                    **style(role, label=label))
    ax_p.set_ylabel("position (cm)")
    ax_p.set_title("Position")
    ax_v.set_ylabel("velocity (cm/s)")
    ax_v.set_title("Velocity")
    ax_v.set_xlabel("time (s)")
    ax_v.set_xlim(0.0, until)
    ax_p.legend(loc="upper right", fontsize=9, ncol=2, markerscale=2.5)
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
    times = np.asarray(times, dtype=float)
    if until <= 0:
        raise ValueError(f"until must be > 0 s, got {until}")
    shown = times <= until
    fig, ax = plt.subplots(figsize=(10, 4.6))
    for label, (curve, role) in curves.items():
        ax.plot(times[shown], np.asarray(curve, dtype=float)[shown], **style(role, label=label))
    if threshold is not None:
        ax.axhline(threshold, color=COLORS["vision"], linestyle="--", linewidth=1.2,
                   label="threshold")
    for label, (time, role) in (marks or {}).items():
        ax.axvline(time, color=COLORS[role], linestyle="--", linewidth=1, label=label)
    ax.set_yscale("log")
    ax.set_xlim(0.0, until)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("squared position error (cm²)")
    ax.legend(loc="upper right", fontsize=9)
    fig.tight_layout()
    return fig


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
        ax.set_ylabel("estimate − truth (cm)")
        ax.set_title(title, loc="left")
        ax.legend(loc="upper right", ncol=4, fontsize=8)
    axes[-1, 0].set_xlim(times[0], times[-1])
    axes[-1, 0].set_xlabel("time (s)")
    fig.tight_layout()
    return fig


def delay_figure(times: np.ndarray, truth: np.ndarray, delayed_readings: np.ndarray,
                 delayed_estimate: np.ndarray, compensated: np.ndarray, delay: float,
                 fast_window: tuple[float, float] = (3.75, 4.35)) -> Figure:
    """Question (e): truth, late readings, late estimate and compensated estimate.

    Top: the whole trial. Bottom left: the start, with the first ``delay`` seconds
    (nothing has arrived yet) shaded. Bottom right: a window of fast flight, where the
    late estimate trails most visibly.

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
        (np.asarray(delayed_readings, dtype=float), "vision", r"vision, delayed $y_{j-\delta}$"),
        (np.asarray(truth, dtype=float), "truth", "true position"),
        (np.asarray(delayed_estimate, dtype=float), "estimate",
         r"delayed estimate $\hat z_{j-\delta}$"),
        (np.asarray(compensated, dtype=float), "prediction",
         r"compensated $z^*_j = A^\delta \hat z_{j-\delta}$"),
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
        for values, role, label in series:
            ax.plot(times[shown], values[shown], **style(role, label=label))
        ax.set_xlim(start, end)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("position (cm)")
    ax_all.set_title(f"Vision delayed by d = {delay:g} s: the whole trial")
    ax_all.legend(loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=4, markerscale=3)
    ax_start.axvspan(times[0], times[0] + delay, color=COLORS["vision"], alpha=0.25,
                     linewidth=0)
    ax_start.set_title(f"Start: nothing before t = d = {delay:g} s (shaded)")
    ax_fast.set_title("Fast flight: where the delay shows most")
    return fig


# --- notebooks 00 (background) and 06 (bonus): appended by the 00/06 notebook engineer ---

def _interval_arrays(intervals) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Means, lower and upper ends of a sequence of ``metrics.Interval`` (or alike)."""
    intervals = list(intervals)
    if not intervals:
        raise ValueError("intervals must hold at least one interval, got none")
    return (np.array([float(iv.mean) for iv in intervals]),
            np.array([float(iv.low) for iv in intervals]),
            np.array([float(iv.high) for iv in intervals]))


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
    ax.plot(times[seen], np.asarray(readings, dtype=float)[seen], **style("vision", label="vision"))
    ax.plot(times[shown], np.asarray(truth, dtype=float)[shown],
            **style("truth", label="true path"))
    ax.plot(times[seen], np.asarray(estimate, dtype=float)[seen],
            **style("estimate", label="filtered estimate"))
    ax.plot(prediction_times, prediction,
            **style("prediction", label="prediction with eyes closed"))
    ax.fill_between(prediction_times, prediction - 2 * prediction_std,
                    prediction + 2 * prediction_std, color=COLORS["prediction"], alpha=0.15,
                    linewidth=0, label="±2σ of the prediction")
    ax.axvline(close, color=COLORS["truth"], linewidth=0.8, linestyle=":")
    ax.set_xlim(start, end)
    ax.set_ylim(-limit, limit)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("position (cm)")
    ax.set_title(f"Eyes closed at t = {close:g} s: the model extrapolates, its uncertainty "
                 "fans out")
    ax.legend(loc="lower left", ncols=3, markerscale=3, fontsize=9)
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
    mean, low, high = _interval_arrays(intervals)
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
    ax.set_ylim(mean.size - 0.5, -0.5)
    ax.set_xlabel(xlabel)
    ax.set_title(title)
    ax.legend(loc="lower right", fontsize=8)
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
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time without measurements (s)")
    ax.set_ylabel("2σ of predicted position (cm)")
    ax.set_title("Position uncertainty with no measurements")
    ax.legend(loc="upper left", fontsize=8)
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
    mean, low, high = _interval_arrays(intervals)
    fig, ax = plt.subplots(figsize=(10, 5))
    ax.errorbar(jerk_stds, mean, yerr=[mean - low, high - mean], marker="o", markersize=4,
                capsize=2, **style("estimate", label="MSE of the filtered position (95 % CI)"))
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
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("jerk noise σ_j behind Q (cm/s³)")
    ax.set_ylabel("position error (cm²)")
    ax.set_title("Tracking error against the process noise")
    ax.legend(loc="lower left", fontsize=8, ncols=2)
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
        ax.plot(times[shown], np.asarray(readings, dtype=float)[shown],
                **style("vision", label="vision"))
        ax.plot(times[shown], np.asarray(truth, dtype=float)[shown],
                **style("truth", label="true path"))
        ax.plot(times[shown], np.asarray(estimate, dtype=float)[shown],
                **style("estimate", label="filtered estimate"))
        ax.set_title(title, fontsize=9)
        ax.set_xlim(start, end)
        ax.set_xlabel("time (s)")
    axes[0, 0].set_ylabel("position (cm)")
    axes[0, 0].legend(loc="lower left", fontsize=8, markerscale=3)
    fig.tight_layout()
    return fig


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
    times = np.asarray(times, dtype=float)
    if until <= 0:
        raise ValueError(f"until must be > 0 s, got {until}")
    estimate = np.asarray(estimate, dtype=float)
    std = np.asarray(std, dtype=float)
    early = times <= until
    fig, (ax_run, ax_mc) = plt.subplots(1, 2, figsize=(12, 4.2))
    ax_run.fill_between(times[early], estimate[early] - 2 * std[early],
                        estimate[early] + 2 * std[early], color=COLORS["estimate"],
                        alpha=0.15, linewidth=0, label="±2σ of the filter's own variance")
    ax_run.plot(times[early], np.full(early.sum(), float(bias)), **style("truth",
                label="true bias"))
    ax_run.plot(times[early], estimate[early], **style("estimate", label="bias estimate"))
    ax_run.set_xlim(0, until)
    ax_run.set_ylim(float(bias) - 80, float(bias) + 80)
    ax_run.set_xlabel("time (s)")
    ax_run.set_ylabel("bias (cm/s²)")
    ax_run.set_title("One run: the bias estimate and its band")
    ax_run.legend(loc="upper right", fontsize=8)
    ax_mc.plot(times, np.asarray(rms_error, dtype=float),
               **style("estimate", label="RMS error over the runs"))
    ax_mc.plot(times, np.asarray(filter_std, dtype=float),
               **style("reference", linewidth=2.0, label="the filter's own σ of the bias"))
    ax_mc.set_yscale("log")
    ax_mc.set_xlim(times[0], times[-1])
    ax_mc.set_xlabel("time (s)")
    ax_mc.set_ylabel("bias error (cm/s²)")
    ax_mc.set_title("Monte Carlo: real error beside the filter's own σ")
    ax_mc.legend(loc="upper right", fontsize=8)
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
    times = np.asarray(times, dtype=float)
    if until <= 0:
        raise ValueError(f"until must be > 0 s, got {until}")
    shown = times <= until
    accelerations = np.asarray(accelerations, dtype=float)
    fig, ax = plt.subplots(figsize=(10, 3.8))
    ax.plot(times[shown], np.asarray(readings, dtype=float)[shown],
            **style("proprioception", label="signal a_r = a + b + noise"))
    ax.plot(times[shown], accelerations[shown], **style("truth", label="true acceleration a"))
    ax.plot(times[shown], accelerations[shown] + bias,
            **style("truth", linestyle="--", linewidth=1.0, label="a + b"))
    ax.set_xlim(0, until)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("acceleration (cm/s²)")
    ax.set_title(f"The acceleration signal: noisy, and shifted by its bias b = {bias:g} cm/s²")
    ax.legend(loc="upper left", fontsize=8, markerscale=2, ncols=3)
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
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(elapsed[0], elapsed[-1])
    ax.set_xlabel("time since the known start (s)")
    ax.set_ylabel("RMS position error (cm)")
    ax.set_title("Integrating the signal without vision")
    ax.legend(loc="upper left", fontsize=8)
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
    mean, low, high = _interval_arrays(intervals)
    fig, (ax_mse, ax_bias) = plt.subplots(1, 2, figsize=(12, 4.4))
    ax_mse.errorbar(values, mean, yerr=[mean - low, high - mean], marker="o", markersize=4,
                    capsize=2, **style("estimate", label="with the signal (95 % CI)"))
    ax_mse.axhspan(float(baseline.low), float(baseline.high), color=COLORS["alternative"],
                   alpha=0.3, linewidth=0)
    ax_mse.axhline(float(baseline.mean), **style("alternative", label="vision only"))
    ax_bias.plot(values, np.asarray(bias_rms, dtype=float), marker="o", markersize=4,
                 **style("estimate", label="RMS error of b̂ at the end"))
    ax_bias.plot(values, np.asarray(bias_std, dtype=float),
                 **style("reference", linewidth=2.0, label="the filter's own σ of b̂"))
    for ax, ylabel in ((ax_mse, "position MSE after the burn-in (cm²)"),
                       (ax_bias, "bias error (cm/s²)")):
        ax.axvline(marked, color=COLORS["truth"], linewidth=0.8, linestyle="--")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.legend(loc="upper left", fontsize=8)
    ax_mse.set_title("Position MSE: with the signal and vision only")
    ax_bias.set_title("How well the bias is learned")
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
    times = np.asarray(times, dtype=float)
    if until <= 0:
        raise ValueError(f"until must be > 0 s, got {until}")
    early = times <= until
    dashes = (":", "-.", "-", "--", (0, (5, 1)), (0, (1, 3)))
    fig, (ax_b, ax_v) = plt.subplots(1, 2, figsize=(12, 4.4))
    for (label, curve), linestyle in zip(mean_errors.items(), dashes, strict=False):
        ax_b.plot(times[early], np.asarray(curve, dtype=float)[early],
                  **style("estimate", linestyle=linestyle, label=label))
    ax_b.axhline(0, color=COLORS["truth"], linewidth=0.8)
    ax_b.set_xlim(0, until)
    ax_b.set_xlabel("time (s)")
    ax_b.set_ylabel("mean error of b̂ over runs (cm/s²)")
    ax_b.set_title("Start-up of the bias estimate, by true bias")
    ax_b.legend(loc="lower right", fontsize=8)
    for (label, curve), linestyle in zip(filter_stds.items(), dashes, strict=False):
        ax_v.plot(times, np.asarray(curve, dtype=float),
                  **style("reference", linestyle=linestyle, linewidth=2.0, label=label))
    ax_v.set_yscale("log")
    ax_v.set_xlim(times[0], times[-1])
    ax_v.set_xlabel("time (s)")
    ax_v.set_ylabel("the filter's σ of b̂ (cm/s²)")
    ax_v.set_title("The filter's σ of the bias, by vision noise")
    ax_v.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return fig
