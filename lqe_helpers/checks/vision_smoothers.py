"""Checks of notebook 01, Going further part 1: the LQE against the smoother the tutorial names.

- :func:`check_smoother`: the student's exponential smoother ``my_smoother(y, alpha)`` on
  small random readings (one run, several runs, a grid of weights), against the pack's
  :func:`lqe_helpers.smoothing.exponential_smoother`; a smoother that looks at future
  samples is caught by changing one future reading;
- :func:`check_smoother_comparison`: the best weight on the grid and the paired
  difference smoother − LQE over the Monte Carlo runs, recomputed with the pack's
  smoother and engine on the task's draws.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import metrics, smoothing
from ..scenario import DEFAULT
from .judging import judge, judge_interval
from .machinery import (
    FUNCTION_RTOL,
    INTERVAL_RTOL,
    MSE_RTOL,
    SEED,
    CheckFailed,
    answers_on_cases,
    argument_array,
    call_student,
    close,
    match_mistake,
    passed,
    require_callable,
    student_result,
    time_limit_text,
    tolerance_text,
)
from .own_work import FUNCTION_TASKS
from .paired_mistakes import interval_mistakes
from .remembering import remembered
from .vision import SIGMAS_V, keyed, monte_carlo

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: Readings per case of :func:`check_smoother`.
SMOOTHER_STEPS = 12
#: The sample a future-reading probe changes (the outputs before it must not move).
PROBE_STEP = 6

_SMOOTHER_ARGS = ("y", "alpha")
_SMOOTHER_SHAPE_HINT = (
    "alpha broadcasts against the leading axes of y, y.shape[:-1]: with y of shape "
    "(runs, 1, n) and alpha of shape (g,), each step's y[..., j] is (runs, 1) and the "
    "result s[..., j] is (runs, g); make s with that shape before the loop.")


@dataclass(frozen=True)
class SmootherCase:
    """Readings y (..., n) (cm) and a weight alpha for :func:`check_smoother` (read-only)."""

    y: np.ndarray
    alpha: np.ndarray

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of the smoothed result: broadcast of y.shape[:-1] and alpha, then n."""
        return (*np.broadcast_shapes(self.y.shape[:-1], self.alpha.shape), self.y.shape[-1])

    def describe(self) -> str:
        alpha = (f"alpha = {float(self.alpha):g}" if self.alpha.ndim == 0
                 else f"alpha of shape {self.alpha.shape}")
        return f"readings y of shape {self.y.shape} and {alpha}"

    def args(self) -> tuple[object, ...]:
        """The arguments: alpha as a plain float when it is one number, as a student gives it."""
        return (self.y, float(self.alpha) if self.alpha.ndim == 0 else self.alpha)


@remembered
def smoother_cases() -> tuple[SmootherCase, ...]:
    """The cases of :func:`check_smoother`, drawn once from :data:`SEED` (read-only).

    One run with one α; four runs with one α; three runs against a grid of four α (y of
    shape (3, 1, n)); and the second case again with its reading at :data:`PROBE_STEP`
    moved by 5 cm (the future-reading probe). No α is 1, so that a weight applied the
    wrong way round (1 − α) is a valid smoother too.
    """
    rng = np.random.default_rng(SEED)
    n = SMOOTHER_STEPS
    one = 10.0 * np.sin(np.linspace(0.0, 3.0, n)) + rng.normal(size=n)
    runs = 3.0 * rng.normal(size=(4, n))
    grid = 3.0 * rng.normal(size=(3, 1, n))
    probe = runs.copy()
    probe[:, PROBE_STEP] += 5.0
    cases = [(one, 0.3), (runs, 0.55), (grid, np.array([0.1, 0.25, 0.5, 0.8])), (probe, 0.55)]
    made = []
    for y, alpha in cases:
        arrays = [np.array(y, dtype=float), np.array(alpha, dtype=float)]
        for array in arrays:
            array.setflags(write=False)
        made.append(SmootherCase(*arrays))
    return tuple(made)


@remembered
def _right(index: int) -> np.ndarray:
    case = smoother_cases()[index]
    return smoothing.exponential_smoother(case.y, case.alpha)


@remembered
def _mistaken(mistake: str, index: int) -> np.ndarray | None:
    """The smoother of case ``index`` with one of :data:`SMOOTHER_MISTAKES`."""
    case = smoother_cases()[index]
    y, alpha = case.y, case.alpha
    right = _right(index)
    if mistake == "wrong_way":
        return smoothing.exponential_smoother(y, 1.0 - alpha)
    if mistake == "from_zero":          # s before the first reading taken as 0
        padded = np.concatenate([np.zeros((*y.shape[:-1], 1)), y], axis=-1)
        return smoothing.exponential_smoother(padded, alpha)[..., 1:]
    if mistake == "one_late":           # s_j built from y_(j−1): right shifted by one
        first = np.broadcast_to(y[..., :1], (*right.shape[:-1], 1))
        return np.concatenate([first, right[..., :-1]], axis=-1)
    if mistake == "previous_reading":   # y_(j−1) where s_(j−1) belongs: α y_j + (1 − α) y_(j−1)
        shifted = np.concatenate([y[..., :1], y[..., :-1]], axis=-1)
        return alpha[..., None] * y + (1.0 - alpha[..., None]) * shifted
    if mistake == "time_first" and y.ndim == 2 and alpha.ndim == 0:
        return smoothing.exponential_smoother(y.T, alpha).T
    return None


#: Typical mistakes in the smoother and what to tell the student, in the order tried.
SMOOTHER_MISTAKES = {
    "wrong_way": (
        "the weight is applied the wrong way round: the new reading gets 1 − α and the old "
        "smoothed value α. In s_j = s_(j−1) + α (y_j − s_(j−1)) = (1 − α) s_(j−1) + α y_j "
        "the newest reading y_j gets the weight α"),
    "from_zero": (
        "the smoother starts from 0 before the first reading, so s_0 = α y_0. It starts "
        "from the first reading itself: s_0 = y_0"),
    "one_late": (
        "each smoothed value is one step late: s_j is built from the readings up to "
        "y_(j−1). It must take in y_j itself (and s_0 = y_0)"),
    "previous_reading": (
        "the recursion uses the previous reading y_(j−1) where the previous smoothed value "
        "s_(j−1) belongs, so it averages two readings instead of all the past ones"),
    "time_first": (
        "time runs along the first axis of y; here time is the last axis, y[..., j], and "
        "the leading axes are runs (rows of y are runs)"),
}


def _future_problem(answers: dict[int, np.ndarray]) -> bool:
    """Whether the outputs before :data:`PROBE_STEP` moved when a later reading changed."""
    if 1 not in answers or 3 not in answers:
        return False
    before = slice(None, PROBE_STEP)
    return not close(answers[1][..., before], answers[3][..., before], FUNCTION_RTOL)


def check_smoother(my_smoother: Callable[..., np.ndarray]) -> None:
    """Check a student's exponential smoother ``my_smoother(y, alpha)``.

    The function is called on the cases of :func:`smoother_cases` (one run, several
    runs, a grid of α against y of shape (runs, 1, n); each call given at most
    :data:`lqe_helpers.student_code.TIME_LIMIT` s) and must return ``s_j = s_(j−1) +
    α (y_j − s_(j−1))`` from ``s_0 = y_0``, of shape (broadcast of y.shape[:-1] and
    alpha.shape) + (n,), equal to :func:`lqe_helpers.smoothing.exponential_smoother`
    (computed before the student's function runs) within :data:`FUNCTION_RTOL` of the
    largest value. A smoother whose early outputs change when a later reading changes
    uses future samples, and is told so.

    Raises
    ------
    CheckFailed
        If the function is not written yet, fails, does not return in time, runs the
        pack's own smoother, returns the wrong type or shape, changes its inputs, uses
        future readings, or computes other numbers; the message names the mistake when it
        is a typical one.
    """
    name = require_callable(my_smoother, "my_smoother", "check_smoother")
    cases = smoother_cases()
    correct = {index: _right(index) for index in range(len(cases))}
    answers, errors = answers_on_cases(
        cases,
        lambda case: call_student(my_smoother, *case.args(), name=name, where=case.describe(),
                                  arg_names=_SMOOTHER_ARGS, shape_hint=_SMOOTHER_SHAPE_HINT,
                                  allow=FUNCTION_TASKS["my_smoother"]),
        lambda output, case: _smoother_output(output, name, case))
    wrong = [i for i in answers if not close(answers[i], correct[i], FUNCTION_RTOL)]
    if not wrong and not errors:
        passed(f"{name} matches s_j = s_(j−1) + α (y_j − s_(j−1)) from s_0 = y_0 on "
               f"{len(cases)} cases (one run, several runs, a grid of α) to "
               f"{tolerance_text(FUNCTION_RTOL)}, and no output depends on a later reading; "
               f"{time_limit_text()}")
        return
    if _future_problem(answers):
        raise CheckFailed(
            f"{name} uses future readings: changing y at step {PROBE_STEP} changed its "
            f"output at earlier steps ({cases[1].describe()}). A causal smoother's s_j "
            f"may use only y_0 … y_j, as an observer has nothing later at time j")
    mistake = match_mistake(list(SMOOTHER_MISTAKES), _mistaken, answers, correct)
    if mistake is not None:
        also = " (On some inputs it also raises an error.)" if errors else ""
        raise CheckFailed(f"{name} is not the exponential smoother: "
                          f"{SMOOTHER_MISTAKES[mistake]}.{also}")
    if errors:
        raise errors[min(errors)]
    index = wrong[0]
    difference = np.abs(answers[index] - correct[index])
    step = int(np.argmax(np.any(difference > FUNCTION_RTOL * max(
        1.0, float(np.max(np.abs(correct[index])))), axis=tuple(range(difference.ndim - 1)))))
    raise CheckFailed(
        f"{name} does not match s_j = s_(j−1) + α (y_j − s_(j−1)) from s_0 = y_0 on "
        f"{cases[index].describe()}: the first difference is at step {step} (largest "
        f"difference {float(np.max(difference)):.3g} cm)")


def _smoother_output(output: object, name: str, case: SmootherCase) -> np.ndarray:
    """The smoother's output as an array of the case's shape, or a CheckFailed saying why."""
    shape = case.shape
    array = student_result(output, name=name, what=f"the smoothed readings, an array of shape "
                           f"{shape}", where=case.describe())
    if array.shape == shape:
        return array
    n = case.y.shape[-1]
    if array.shape == case.y.shape and shape != case.y.shape:
        message = (f"returned the shape of y, {array.shape}, for {case.describe()}: each α "
                   f"must give its own smoothed readings, shape {shape}")
    elif array.shape == shape[:-1]:
        message = (f"returned shape {array.shape} for {case.describe()}: only the last "
                   f"smoothed value? It must return s at every step, shape {shape}")
    elif array.ndim == len(shape) and array.shape[0] == n and array.shape[1:] == shape[:-1]:
        message = (f"returned shape {array.shape} for {case.describe()}: time is on the "
                   f"first axis. Keep time on the last axis, like y: shape {shape}")
    else:
        message = (f"returned an array of shape {array.shape} for {case.describe()}; "
                   f"expected shape {shape} (the leading axes of y broadcast with alpha, "
                   f"then the {n} steps)")
    raise CheckFailed(f"{name} {message}")


# ------------------------------------------------------------------------------------------
# Tuning the weight and comparing with the LQE
# ------------------------------------------------------------------------------------------

def _grid(alphas: object) -> np.ndarray:
    """The student's grid of α: a vector of at least two values in (0, 1]."""
    grid = argument_array(alphas, "alphas", "a vector of weights α in (0, 1]")
    if grid.ndim != 1 or grid.size < 2 or np.any(grid <= 0) or np.any(grid > 1):
        raise CheckFailed(f"alphas must be a vector of at least two weights α in (0, 1], got "
                          f"shape {grid.shape} with values from {np.min(grid):g} to "
                          f"{np.max(grid):g}")
    return grid


@remembered
def _tuned(column: int, grid: tuple[float, ...], burn_in_steps: int) -> smoothing.TunedSmoother:
    """The pack's tuned smoother on the core path's readings at σ_v = SIGMAS_V[column].

    Kept for the four (column, burn-in) pairs of one grid only: the grid is the student's,
    and each result holds the smoothed runs (runs, n), so a cache of every grid a student
    tries would grow by about 10 MB an attempt.
    """
    readings = monte_carlo().measurements[:, column, :, 0]
    return smoothing.tune_smoother("exponential", readings, DEFAULT.truth[:, 0],
                                   np.array(grid), burn_in_steps)


def check_smoother_comparison(best_alpha: dict[float, float],
                              smoother_vs_lqe: dict[float, metrics.Interval],
                              alphas: np.ndarray) -> None:
    """Check the tuned smoother's weight and its paired difference with the LQE at both σ_v.

    Recomputed from the task's inputs before looking at the student's: the core path's
    ``DEFAULT.mc_runs`` runs (the engine's, the same draws), every α of ``alphas``
    applied by :func:`lqe_helpers.smoothing.tune_smoother` to each run's readings, the α
    with the smallest Monte Carlo mean MSE after the burn-in (within :data:`MSE_RTOL`),
    and :func:`lqe_helpers.metrics.mean_ci95` of the per-run MSEs of that smoother minus
    the LQE's (mean and ends within :data:`INTERVAL_RTOL` of the interval's scale).

    Parameters
    ----------
    best_alpha : dict of float to float
        The best α at σ_v = 1.5 and 4.5 cm, keyed by σ_v (cm).
    smoother_vs_lqe : dict of float to metrics.Interval
        The paired differences smoother − LQE (cm²), keyed by σ_v (cm).
    alphas : array_like, shape (g,)
        The grid of α the task tried.

    Raises
    ------
    CheckFailed
        Naming the entry and the likely cause: the α of the largest MSE, its index instead
        of its value, chosen on one run or on the whole trial, the other σ_v, the sign
        reversed, the raw readings' MSE instead of the LQE's, unpaired intervals, ...
    """
    grid = tuple(float(value) for value in _grid(alphas))
    chosen = keyed(best_alpha, "best_alpha", "weights α")
    compared = keyed(smoother_vs_lqe, "smoother_vs_lqe", "paired intervals (metrics.Interval)")
    burn = DEFAULT.burn_in_steps
    batch_mse, raw_mse = monte_carlo().mse(), monte_carlo().measurement_mse("vision")
    for column, sigma in enumerate(SIGMAS_V):
        tuned, whole = _tuned(column, grid, burn), _tuned(column, grid, 0)
        other = _tuned(1 - column, grid, burn)
        settings = tuned.settings
        judge(f"best_alpha[{sigma:g}]", chosen[sigma], tuned.best, MSE_RTOL,
              what="the α of the smallest Monte Carlo mean MSE recomputed from the task's "
                   "inputs",
              mistakes={
                  "it is the α with the largest mean MSE: the best is the smallest":
                      settings[int(np.argmax(tuned.mean_mse))],
                  "it is the position of the best α in alphas, not the value of α itself":
                      float(np.argmin(tuned.mean_mse)),
                  "it is chosen on the whole trial: leave the first burn samples out of "
                  "every MSE, as for the LQE": whole.best,
                  f"it is the best α for σ_v = {SIGMAS_V[1 - column]:g} cm": other.best,
              })
        lqe = batch_mse[:, column]
        mistakes = {
            **interval_mistakes(tuned.mse, lqe, "the smoother's MSE", "the LQE's MSE"),
            "it compares the smoother with the raw readings; the task compares it with the "
            "LQE's per-run MSEs (the core path's mse_est)":
                metrics.mean_ci95(tuned.mse - raw_mse[:, column]),
            "the smoother's MSEs are those of the whole trial: leave out the burn-in, as "
            "in the LQE's": metrics.mean_ci95(
                metrics.mse(tuned.smoothed, DEFAULT.truth[:, 0]) - lqe),
            f"it uses the LQE's MSEs at σ_v = {SIGMAS_V[1 - column]:g} cm: pair each "
            f"smoother with the LQE on the same readings":
                metrics.mean_ci95(tuned.mse - batch_mse[:, 1 - column]),
            "it uses the smoother with the α of the largest mean MSE":
                _interval_at(column, grid, int(np.argmax(tuned.mean_mse)), lqe),
        }
        judge_interval(f"smoother_vs_lqe[{sigma:g}]", compared[sigma],
                       metrics.mean_ci95(tuned.mse - lqe), INTERVAL_RTOL, unit="cm²",
                       what="the paired difference smoother − LQE recomputed from the task's "
                            "inputs", mistakes=mistakes)
    passed(f"the best α on your grid and the paired difference smoother − LQE over "
           f"{DEFAULT.mc_runs} runs at σ_v = {' and '.join(f'{s:g}' for s in SIGMAS_V)} cm "
           f"match the pack's smoother and engine on the core path's draws (α to "
           f"{tolerance_text(MSE_RTOL)}, the interval to {tolerance_text(INTERVAL_RTOL)} "
           f"relative)")


def _interval_at(column: int, grid: tuple[float, ...], index: int,
                 lqe: np.ndarray) -> metrics.Interval:
    """Paired interval smoother − LQE of the grid's α number ``index`` at ``column``."""
    readings = monte_carlo().measurements[:, column, :, 0]
    smoothed = smoothing.exponential_smoother(readings, grid[index])
    return metrics.mean_ci95(
        metrics.mse(smoothed, DEFAULT.truth[:, 0], DEFAULT.burn_in_steps) - lqe)
