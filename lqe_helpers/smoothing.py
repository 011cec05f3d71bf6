"""Smoothers that ignore the signal's statistics: the tutorial's foil for the LQE.

The tutorial's Background contrasts the LQE with an exponentially weighted moving
average, which "will simply weight the most recent observations more heavily than those
before but will not consider the statistics of the noisy signal". This module holds that
smoother, the causal moving average, and a tuner that picks each one's best setting on
the same draws the LQE is judged on, so that a paired Monte Carlo interval follows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import metrics, validation


def _readings(y: object) -> np.ndarray:
    """``y`` as a finite float array with a time axis last, (..., n)."""
    return validation.finite_array("y", y, min_ndim=1)


def exponential_smoother(y: np.ndarray, alpha: float | np.ndarray) -> np.ndarray:
    """Exponentially weighted moving average ``s_j = s_{j−1} + α (y_j − s_{j−1})``.

    Starts from the first reading, ``s_0 = y_0``, so every output is a weighted mean of
    readings up to and including ``y_j`` (causal): ``s_j = Σ_i w_i y_{j−i}`` with weights
    ``α (1 − α)^i``, the last one ``(1 − α)^j`` on ``y_0``. α = 1 returns the readings.

    Parameters
    ----------
    y : array_like, shape (..., n)
        Readings (cm) with time on the last axis; leading axes are runs or sensors.
    alpha : float or array_like, shape (...)
        Weight of the newest reading, 0 < α <= 1 (no unit). Its shape broadcasts against
        ``y.shape[:-1]``: give ``y[..., None, :]`` and a grid ``alpha`` of shape (g,) to
        smooth every run with every weight in one call.

    Returns
    -------
    ndarray, shape (broadcast of y.shape[:-1] and alpha.shape) + (n,)
        The smoothed readings (cm).
    """
    y = _readings(y)
    alpha = validation.finite_array("alpha", alpha)
    if np.any(alpha <= 0) or np.any(alpha > 1):
        raise ValueError(
            f"alpha must be in (0, 1], got {np.ravel(alpha)[:6].tolist()}"
            + ("" if alpha.size <= 6 else f" … ({alpha.size} values)"))
    batch = validation.broadcast_batches(y=y.shape[:-1], alpha=alpha.shape)
    n_steps = y.shape[-1]
    validation.check_memory(
        f"y of shape {y.shape} and alpha of shape {alpha.shape}",
        2 * validation.elements((*batch, n_steps)), what="for the smoothed readings")
    readings = np.moveaxis(np.broadcast_to(y, (*batch, n_steps)), -1, 0)  # (n, ...)
    out = np.empty((n_steps, *batch))
    keep = 1.0 - alpha  # (1 − α) s + α y: exactly y when α = 1
    level = readings[0]
    out[0] = level
    for j in range(1, n_steps):
        level = keep * level + alpha * readings[j]
        out[j] = level
    return np.moveaxis(out, 0, -1)


def moving_average(y: np.ndarray, window: int | np.ndarray) -> np.ndarray:
    """Causal moving average: the mean of the last ``N`` readings up to and including ``y_j``.

    Before N readings exist (j < N − 1) the mean is over the j + 1 readings there are.
    N = 1 returns the readings.

    Parameters
    ----------
    y : array_like, shape (..., n)
        Readings (cm) with time on the last axis.
    window : int or array_like of int, shape (...)
        Window length N in samples, 1 <= N. Its shape broadcasts against
        ``y.shape[:-1]``, like ``alpha`` in :func:`exponential_smoother`.

    Returns
    -------
    ndarray, shape (broadcast of y.shape[:-1] and window.shape) + (n,)
        The averaged readings (cm), from running sums: accurate to a few units of
        rounding of the running sum's magnitude (about 1e-15 × n × the readings' size);
        N = 1 returns the readings exactly.
    """
    y = _readings(y)
    windows = _windows(window)
    batch = validation.broadcast_batches(y=y.shape[:-1], window=windows.shape)
    n_steps = y.shape[-1]
    validation.check_memory(
        f"y of shape {y.shape} and window of shape {windows.shape}",
        4 * validation.elements((*batch, n_steps)), what="for the averaged readings")
    sums = np.concatenate([np.zeros((*y.shape[:-1], 1)), np.cumsum(y, axis=-1)], axis=-1)
    ends = np.arange(1, n_steps + 1)                           # j + 1
    starts = np.maximum(ends - windows[..., None], 0)          # (..., n) of window's shape
    sums = np.broadcast_to(sums, (*batch, n_steps + 1))
    starts = np.broadcast_to(starts, (*batch, n_steps))
    total = sums[..., 1:] - np.take_along_axis(sums, starts, axis=-1)
    # A window of one sample is the reading itself, exactly (not a difference of sums).
    return np.where(windows[..., None] == 1, y, total / (ends - starts))


def _windows(window: object) -> np.ndarray:
    """``window`` as an int array of lengths >= 1, else a ``ValueError`` naming it."""
    reason = validation.not_real(window)
    array = np.asarray(window) if reason is None else None
    if array is None or array.dtype.kind not in "iuf" or array.size == 0 or np.any(
            ~np.isfinite(array)) or np.any(array != np.round(array)) or np.any(array < 1):
        raise ValueError(
            f"window must be a whole number of samples >= 1 (or an array of them), got "
            f"{window!r}" + (f": {reason}" if reason else ""))
    return array.astype(np.int64)


@dataclass(frozen=True)
class TunedSmoother:
    """The best setting of a smoother on a grid, judged by Monte Carlo mean MSE.

    Attributes
    ----------
    settings : ndarray, shape (g,)
        The grid tried (α, or the window N in samples).
    mean_mse : ndarray, shape (g,)
        Monte Carlo mean MSE (cm²) of each setting after the burn-in.
    best : float
        The setting with the smallest mean MSE.
    mse : ndarray, shape (runs,)
        Per-run MSEs (cm²) of the best setting, on the draws given: subtract the LQE's
        per-run MSEs on the same draws and pass the difference to
        :func:`~lqe_helpers.metrics.mean_ci95` for a paired interval.
    smoothed : ndarray, shape (runs, n)
        The best setting's output (cm), e.g. for a figure of its lag.
    """

    settings: np.ndarray
    mean_mse: np.ndarray
    best: float
    mse: np.ndarray
    smoothed: np.ndarray


def tune_smoother(kind: str, y: np.ndarray, truth: np.ndarray, settings: np.ndarray,
                  burn_in_steps: int = 0) -> TunedSmoother:
    """Try every setting of a smoother on the same readings; keep the best by mean MSE.

    The best setting is chosen on the very draws it is then judged on, which flatters
    the smoother by the luck of one parameter's choice; with hundreds of runs that
    bias is far below the Monte Carlo interval (``tests/test_smoothing.py`` measures
    it on a fresh draw).

    Parameters
    ----------
    kind : {"exponential", "moving_average"}
        :func:`exponential_smoother` (settings are α) or :func:`moving_average`
        (settings are windows N in samples).
    y : array_like, shape (runs, n)
        One sensor's readings (cm), one row per Monte Carlo run, runs >= 2.
    truth : array_like, shape (n,)
        True positions (cm).
    settings : array_like, shape (g,)
        The grid of α in (0, 1] or of windows N >= 1.
    burn_in_steps : int
        Samples left out of every MSE, as in :func:`~lqe_helpers.metrics.mse`.

    Returns
    -------
    TunedSmoother
    """
    smoothers = {"exponential": exponential_smoother, "moving_average": moving_average}
    if not isinstance(kind, str) or kind not in smoothers:
        raise ValueError(f"kind must be one of {tuple(smoothers)}, got {kind!r}")
    y = _readings(y)
    if y.ndim != 2 or y.shape[0] < 2:
        raise ValueError(f"y must have shape (runs, n) with runs >= 2, got shape {y.shape}")
    settings = validation.finite_array("settings", settings, min_ndim=1)
    if settings.ndim != 1:
        raise ValueError(f"settings must have shape (g,), got shape {settings.shape}")
    smoothed = smoothers[kind](y[:, None, :], settings)         # (runs, g, n)
    mses = metrics.mse(smoothed, truth, burn_in_steps)          # (runs, g)
    mean_mse = mses.mean(axis=0)
    best = int(np.argmin(mean_mse))
    return TunedSmoother(settings, mean_mse, float(settings[best]), mses[:, best],
                         smoothed[:, best])
