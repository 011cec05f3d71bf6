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


def _mean_band(ax, x: np.ndarray, intervals, role: str, label: str, **line) -> np.ndarray:
    """Plot the means of ``intervals`` against ``x`` over their shaded 95 % band."""
    mean, low, high = _interval_arrays(intervals)
    ax.fill_between(x, low, high, color=COLORS[role], alpha=0.25, linewidth=0)
    ax.plot(x, mean, **style(role, label=label, **line))
    return mean


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
    delayed_mean = _mean_band(ax_mse, delays, delayed, "estimate",
                              "delayed estimate (simulation)")
    compensated_mean = _mean_band(ax_mse, delays, compensated, "prediction",
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
    share_mean = _mean_band(ax_share, delays, share, "prediction",
                            "1 − MSE compensated / MSE delayed", linestyle="-", marker=".",
                            markersize=4)
    for ax in (ax_mse, ax_share):
        ax.axvline(delay, color=COLORS["vision"], linewidth=1)
        ax.set_xlim(0, delays[-1])
        ax.set_xlabel("delay d (s)")
    ax_mse.text(delay + 0.01 * delays[-1], 0.97, f"d = {delay} s", fontsize=9, color="0.35",
                va="top", transform=ax_mse.get_xaxis_transform())
    ax_mse.set_ylabel("position MSE (cm²)")
    ax_mse.set_title("MSE against the delay")
    ax_mse.legend(loc="lower right", fontsize=8.5)

    _, share_low, share_high = _interval_arrays(share)
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
    ax_share.set_ylabel("share of the delayed MSE removed")
    ax_share.set_title("What compensation wins (paired, per run)")
    ax_share.legend(loc="lower left", fontsize=8.5)
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
    simulated, _, _ = _interval_arrays(compensated)
    ax.plot(delays[1:], simulated[1:],
            **style("prediction", linestyle="none", marker="o", markersize=3.5,
                    label="compensated, simulation"))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(1e-4 * theory.min(), 10.0 * theory.max())
    ax.set_xlabel("delay d (s)")
    ax.set_ylabel("prediction MSE (cm²)")
    ax.set_title("Where the prediction error comes from (theory)")
    ax.axvspan(delays[1], delays[-1], color=COLORS["vision"], alpha=0.12, linewidth=0,
               label="delays simulated in Figure 4")
    ax.axvline(takeover, color=COLORS["truth"], linewidth=0.8)
    ax.text(takeover * 0.93, 0.04, f"jerks take over\nfrom d = {takeover:.2f} s", fontsize=9,
            ha="right", transform=ax.get_xaxis_transform())
    ax.legend(loc="upper left", fontsize=9)
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
    times = np.asarray(times, dtype=float)
    if until <= 0:
        raise ValueError(f"until must be > 0 s, got {until}")
    window = times <= until
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
    ax.set_yscale("log")
    ax.set_ylim(*ylim)
    ax.set_xlim(0, until)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("squared position error (cm²)")
    ax.set_title("The error over time: what each filter achieves, and what it believes")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=3, fontsize=9)
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
    times = np.asarray(times, dtype=float)
    steady_gain = np.asarray(steady_gain, dtype=float).reshape(-1)
    if until <= 0:
        raise ValueError(f"until must be > 0 s, got {until}")
    early = times <= until
    units = ("position gain", "velocity gain (1/s)", "acceleration gain (1/s²)")
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.8))
    for state, (ax, unit) in enumerate(zip(axes, units, strict=True)):
        for name, (gain, role) in gains.items():
            ax.plot(times[early], np.asarray(gain, dtype=float)[early, state],
                    **style(role, label=name))
        ax.axhline(steady_gain[state], **style("reference", label="steady state K∞"))
        ax.set_yscale("log")
        ax.set_xlim(0, until)
        ax.set_xlabel("time (s)")
        ax.set_ylabel(unit)
    for ax, title in zip(axes, ("position", "velocity", "acceleration"), strict=True):
        ax.set_title(title)
    fig.suptitle("Gains over time: P0 sets the start, not the end")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=3)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    return fig


def _errorbar_intervals(ax, x: np.ndarray, intervals, role: str, **line) -> None:
    """Means of ``intervals`` against ``x`` with their 95 % intervals as error bars."""
    mean, low, high = _interval_arrays(intervals)
    ax.errorbar(x, mean, yerr=[mean - low, high - mean], color=COLORS[role], markersize=4,
                capsize=2, **line)


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
    _errorbar_intervals(ax_t, p0_grid, convergence, "estimate", marker="o",
                        label="convergence time")
    ax_t.set_ylabel("convergence time (s)")
    _errorbar_intervals(ax_m, p0_grid, start_up, "estimate", marker="o",
                        label=f"MSE over the first {burn_in:g} s")
    _errorbar_intervals(ax_m, p0_grid, settled, "alternative", marker="s", linestyle="-.",
                        label=f"MSE after {burn_in:g} s")
    ax_m.set_ylabel("position MSE (cm²)")
    ax_m.set_ylim(0, None)
    for ax in (ax_t, ax_m):
        ax.set_xscale("log")
        ax.set_xlabel("p0 in P0 = p0 · I (cm², cm²/s², cm²/s⁴)")
        for text, value in question_values.items():
            ax.axvline(value, color=COLORS["vision"], linewidth=1)
            ax.annotate(text, (value, 1.0), xycoords=("data", "axes fraction"), xytext=(3, -12),
                        textcoords="offset points", color=COLORS["vision"], fontsize=9)
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


def _plain_log_ticks(ax, axis: str, ticks) -> None:
    """Put ``ticks`` on a log ``axis`` ("x" or "y") labelled as plain numbers (0.3, not 3e-1)."""
    if ticks is None:
        return
    ticks = list(ticks)
    labels = [f"{tick:g}" for tick in ticks]
    if axis == "x":
        ax.set_xticks(ticks, labels)
    else:
        ax.set_yticks(ticks, labels)
        ax.yaxis.set_minor_locator(plt.NullLocator())


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
    _, _, fused_high = _interval_arrays(fused)
    _mean_band(ax_mse, sigma_p, fused, "estimate", "fused, simulation (95 % CI band)",
               marker="o", markersize=3.5)
    ax_mse.plot(dense_sigma_p, theory_fused,
                **style("reference", linewidth=2, label="fused, theory (steady state)"))
    ax_mse.axhspan(vision.low, vision.high, color=COLORS["alternative"], alpha=0.2, linewidth=0)
    ax_mse.axhline(vision.mean, **style("alternative", label="vision only, simulation"))
    ax_mse.axhline(theory_vision, **style("reference", color=COLORS["alternative"],
                                          linestyle=(0, (7, 3)), label="vision only, theory"))
    ax_mse.set_ylim(0, 1.15 * max(vision.high, theory_vision, fused_high.max()))
    ax_mse.set_ylabel("position MSE (cm²)")
    ax_mse.set_title(f"Fused MSE against σ_p (σ_v = {sigma_v} cm)")
    ax_mse.legend(loc="lower right", fontsize=8.5, handlelength=3.5)

    _mean_band(ax_margin, sigma_p, margin, "estimate", "simulation, paired (95 % CI band)",
               marker="o", markersize=3.5)
    ax_margin.plot(dense_sigma_p, theory_margin,
                   **style("reference", linewidth=2, label="theory (steady state)"))
    ax_margin.axhline(0, color=COLORS["truth"], linewidth=0.8)
    ax_margin.set_ylabel("MSE lowered by proprioception (%)")
    ax_margin.set_title("The benefit of the extra sense")
    ax_margin.legend(loc="center right", fontsize=8.5)
    for ax in (ax_mse, ax_margin):
        ax.set_xscale("log")
        ax.set_xlim(sigma_p[0], sigma_p[-1])
        ax.set_xlabel("σ_p (cm), log scale")
        _plain_log_ticks(ax, "x", ticks)
        for question, value in marks.items():
            ax.axvline(value, color="grey", linewidth=0.8, linestyle="--")
            ax.annotate(question, (value, 1.0), xycoords=("data", "axes fraction"),
                        xytext=(3, -12), textcoords="offset points", fontsize=9, color="grey")
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
    _mean_band(ax, assumed_sigma_p, fused, "estimate", "fused, filter assumes σ̃_p",
               marker="o", markersize=4)
    ax.axhline(vision_mse, **style("alternative", label="vision only"))
    ax.set_yscale("log")
    _plain_log_ticks(ax, "y", mse_ticks)
    ax.set_ylabel("position MSE (cm²), log scale")
    ax.set_title("MSE when the filter assumes σ̃_p")
    ax.text(0.04, 0.25, "← overtrust", fontsize=10, color="grey", transform=ax.transAxes)
    ax.text(0.96, 0.25, "undertrust →", fontsize=10, color="grey", ha="right",
            transform=ax.transAxes)

    _mean_band(ax_cost, assumed_sigma_p, excess, "estimate",
               "fused, filter assumes σ̃_p (paired, 95 % CI band)", marker="o", markersize=4)
    ax_cost.axhline(vision_excess, **style("alternative", label="vision only"))
    ax_cost.axhline(0, color=COLORS["truth"], linewidth=0.8)
    top = 1.8 * vision_excess
    ax_cost.set_ylim(-top / 12, top)
    ax_cost.set_ylabel("extra MSE over the correct model (cm²)")
    ax_cost.set_title("Zoom: the cost of misjudging σ_p")
    for axis in (ax, ax_cost):
        axis.axvline(sigma_p, **style("truth", linewidth=1, linestyle="--",
                                      label=f"true σ_p = {sigma_p} cm"))
        axis.set_xscale("log")
        _plain_log_ticks(axis, "x", ticks)
        axis.set_xlabel("σ̃_p assumed by the filter (cm), log scale")
        axis.legend(loc="upper right", fontsize=8.5)
    fig.suptitle(f"Misjudging proprioception: true σ_v = {sigma_v} cm, σ_p = {sigma_p} cm "
                 f"({runs} runs)", y=1.0)
    return fig
