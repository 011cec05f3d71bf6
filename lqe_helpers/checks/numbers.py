"""Number checks shared by several notebooks until each has its own: an MSE, a paired difference.

These judge a student's number against the student's own arrays (``check_mse`` recomputes
the MSE of the positions it is given), so they catch wrong arithmetic, not wrong science.
The notebooks' own modules replace them, task by task, with checks that recompute the
value from the task's inputs (see :mod:`lqe_helpers.checks.vision` for the pattern).
"""

from __future__ import annotations

import numpy as np

from .. import metrics
from .judging import interval_mistakes, judge, judge_interval, mse_mistakes
from .machinery import (
    INTERVAL_RTOL,
    MSE_RTOL,
    CheckFailed,
    argument_array,
    passed,
    tolerance_text,
)

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback


def _burn_in(value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise CheckFailed(f"burn_in_steps must be a whole number of samples >= 0, got "
                          f"{value!r}")
    return int(value)


def check_mse(value: float | np.ndarray, estimate: np.ndarray, truth: np.ndarray,
              burn_in_steps: int = 0) -> None:
    """Check a mean squared error against :func:`metrics.mse` (relative tolerance 1e-6).

    Tolerance :data:`MSE_RTOL`, relative to the MSE.

    Parameters
    ----------
    value : float or array_like, shape (...)
        The student's MSE (cm²): one number for one run, one per run for a batch (or
        the mean over the runs as one number).
    estimate : array_like, shape (..., n)
        Estimated positions (cm).
    truth : array_like, shape (n,)
        True positions (cm).
    burn_in_steps : int
        Samples skipped at the start.

    Raises
    ------
    CheckFailed
        With the mistake named: RMSE instead of MSE, burn-in not skipped or a different
        one, a sum instead of a mean, errors not squared, ...
    """
    burn_in_steps = _burn_in(burn_in_steps)
    estimate = argument_array(estimate, "estimate", "positions (cm), shape (n,) or (runs, n)",
                              allow_nan=True)
    truth = argument_array(truth, "truth", "true positions (cm), shape (n,)")
    try:
        expected = metrics.mse(estimate, truth, burn_in_steps)
        problem = ""
    except ValueError as error:
        positions = ("" if "NaN" in str(error) else
                     ". It expects positions (cm): estimate of shape (n,) or (runs, n) and "
                     "truth of shape (n,), e.g. the position column of the states")
        problem = f"{error}{positions}"
    if problem:
        raise CheckFailed(f"check_mse could not compute the MSE from your estimate and truth: "
                          f"{problem}")
    got = argument_array(value, "your MSE", "one number or one per run (cm²)")
    runs = expected.size if expected.ndim else 0
    mistakes = mse_mistakes(estimate, truth, burn_in_steps)
    pooled = bool(runs and got.size == 1)
    if pooled:
        expected = np.mean(expected)
        mistakes = {cause: None if wrong is None else np.mean(wrong)
                    for cause, wrong in mistakes.items()}
    other = _matching_burn_in(got.reshape(()) if pooled else got, estimate, truth)
    if other is not None and other != burn_in_steps:
        mistakes[f"it is the MSE after skipping {other} sample{'s' * (other != 1)}, but "
                 f"burn_in_steps = {burn_in_steps}. Skip exactly the burn-in (in samples, not "
                 f"seconds) and tell the check the same number"] = got.reshape(expected.shape)
    skipped = f"skipping the first {burn_in_steps} samples" if burn_in_steps else "whole trial"
    judge("your MSE", got, expected, MSE_RTOL, unit="cm²", mistakes=mistakes,
          what=f"the MSE of these positions ({skipped})",
          hint="the MSE is the mean over the samples of (estimate − truth)²")
    if pooled:
        passed(f"mean MSE over {runs} runs matches metrics.mse (positions, {skipped}) to "
               f"rtol {tolerance_text(MSE_RTOL)}")
    else:
        what = f"{runs} MSEs (one per run)" if runs else "MSE"
        passed(f"{what} match{'es' * (not runs)} metrics.mse (positions, {skipped}) to "
               f"rtol {tolerance_text(MSE_RTOL)}")


def _matching_burn_in(got: np.ndarray, estimate: np.ndarray, truth: np.ndarray) -> int | None:
    """The burn-in (samples) whose MSE equals ``got``, if there is one.

    ``got`` has the shape of one MSE per run, or is one number for the mean over runs.
    """
    squared = (estimate - truth) ** 2
    if not np.all(np.isfinite(squared)):
        return None
    n = squared.shape[-1]
    tail_sums = np.cumsum(squared[..., ::-1], axis=-1)[..., ::-1]    # sum from b on
    per_burn_in = np.moveaxis(tail_sums / (n - np.arange(n)), -1, 0)  # (n, ...)
    if np.ndim(got) == 0 and per_burn_in.ndim > 1:
        per_burn_in = per_burn_in.reshape(n, -1).mean(axis=1)
    for b in range(n):
        if np.shape(got) == np.shape(per_burn_in[b]) and np.allclose(
                got, per_burn_in[b], rtol=MSE_RTOL, atol=0.0):
            return b
    return None


def _runs_argument(value: object, name: str) -> np.ndarray:
    array = argument_array(value, name, "one MSE per Monte Carlo run (cm²), shape (runs,)")
    if array.ndim != 1 or array.size < 2:
        raise CheckFailed(
            f"{name} must hold one MSE per Monte Carlo run, shape (runs,) with runs >= 2, "
            f"got shape {array.shape}")
    return array


def check_paired_difference(interval: metrics.Interval, mse_first: np.ndarray,
                            mse_second: np.ndarray) -> None:
    """Check a paired Monte Carlo difference against ``metrics.mean_ci95(first − second)``.

    ``mse_first`` and ``mse_second`` hold one MSE per run, computed on the same noise
    in run r; the answer to "is the first larger?" is the mean of the per-run
    differences with its 95 % Student-t interval. Tolerance :data:`INTERVAL_RTOL`
    relative to the interval's scale.

    Parameters
    ----------
    interval : metrics.Interval
        The student's interval (anything with ``mean``, ``low``, ``high``; ``runs`` is
        compared too if present).
    mse_first, mse_second : array_like, shape (runs,)
        Per-run MSEs (cm²) of the two conditions, run r of both on the same noise.

    Raises
    ------
    CheckFailed
        With the mistake named: not an Interval, reversed sign, unpaired interval, two
        intervals combined, standard deviation instead of standard error, 1.96 instead
        of the t value, the interval of one MSE alone, ...
    """
    first = _runs_argument(mse_first, "mse_first")
    second = _runs_argument(mse_second, "mse_second")
    if first.shape != second.shape:
        raise CheckFailed(
            f"mse_first and mse_second must hold one MSE per run for the same runs, got "
            f"shapes {first.shape} and {second.shape}")
    judge_interval("your interval", interval, metrics.mean_ci95(first - second), INTERVAL_RTOL,
                   mistakes=interval_mistakes(first, second, "mse_first", "mse_second"),
                   what="the mean of mse_first − mse_second per run with its 95 % interval")
    passed(f"paired difference: mean and 95 % interval match metrics.mean_ci95 of "
           f"mse_first − mse_second over {first.size} runs (to "
           f"{tolerance_text(INTERVAL_RTOL)} relative)")
