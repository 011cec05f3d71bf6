"""Checks of notebook 04, question (d): proprioception three times noisier than vision.

Task 1 (C and R) uses :func:`lqe_helpers.checks.fusion.check_fusion`. Every other check
recomputes what its task asks from the task's own inputs and draws (the scenario's seed,
the pack's engine :func:`lqe_helpers.experiments.track`) before it looks at the student's
value, and names the likely cause of a wrong one:

- :func:`check_noisier_trial` (Task 2): one trial filtered both ways, the two MSEs;
- :func:`check_noisier_difference` (Task 3): the paired vision-only − fused MSE over the
  Monte Carlo runs, after the first second and over the whole trial;
- Going further: :func:`check_noisier_theory` (1), :func:`check_proprioception_sweep` and
  :func:`check_sweep_reading` (2); the checks of Going further 4 (a misjudged σ_p) are in
  :mod:`lqe_helpers.checks.misjudged_noise`, which shares this module's Monte Carlo runs.
"""

from __future__ import annotations

import functools

import numpy as np

from .. import experiments, metrics
from ..scenario import DEFAULT
from ..steady_state import SteadyState
from .judging import interval_mistakes, judge, judge_interval, mse_mistakes
from .machinery import (
    INTERVAL_RTOL,
    MATRIX_RTOL,
    MSE_RTOL,
    CheckFailed,
    argument_array,
    interval_list,
    keyed_entries,
    passed,
    tolerance_text,
)

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: σ_v and σ_p of question (d) (cm).
SIGMA_V, SIGMA_P = 1.5, 4.5
#: σ_p of question (c) (cm), a value left in by mistake.
SIGMA_P_C = 1.5
#: The benefit levels (%) whose crossing Going further 2 reads off the theory.
BENEFIT_LEVELS = (10, 1)

#: The fused filter's sensors, in the column order of its readings.
FUSED = ("vision", "proprioception")
#: True position (cm), shape (n,), and the samples every MSE leaves out.
TRUTH = DEFAULT.truth[:, 0]
BURN = DEFAULT.burn_in_steps


@functools.cache
def monte_carlo(sigmas: tuple[float, ...],
                assumed: tuple[float, ...] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per-run MSEs (runs,) (cm²) after the burn-in and over the whole trial, read-only.

    ``DEFAULT.mc_runs`` runs of the engine on the scenario's draws with the true
    ``sigmas`` (cm): vision alone for one σ, fused for two; the filter assumes
    ``assumed`` (default the truth). Kept, so several checks share one run.
    """
    tracking = experiments.track(DEFAULT, FUSED[:len(sigmas)], sigmas=list(sigmas),
                                 assumed_sigmas=assumed, runs=DEFAULT.mc_runs)
    pair = (tracking.mse(), metrics.mse(tracking.positions, TRUTH))
    for array in pair:
        array.flags.writeable = False
    return pair


def paired(first: np.ndarray, second: np.ndarray) -> metrics.Interval:
    """The paired difference ``first − second`` (per run) with its 95 % interval."""
    return metrics.mean_ci95(first - second)

def entries(name: str, values: object, keys: tuple[object, ...], what: str) -> dict:
    """The student's dict ``name``, which must hold ``keys``."""
    return keyed_entries(values, name, keys, what, keyed_by=f"{keys[0]!r}, … (the task's keys)",
                         advice=f"; the task asks for {', '.join(repr(key) for key in keys)}")


def sigma_grid(name: str, values: object) -> np.ndarray:
    """A σ grid the student chose (cm): 1-D, > 0, increasing."""
    grid = argument_array(values, name, "a 1-D array of σ values (cm)")
    if grid.ndim != 1 or grid.size < 3 or np.any(grid <= 0) or np.any(np.diff(grid) <= 0):
        raise CheckFailed(f"{name} must be a 1-D array of at least 3 increasing σ values > 0 "
                          f"(cm), got shape {grid.shape}")
    return grid


# ------------------------------------------------------------------------------------------
# Task 2: one trial, filtered both ways
# ------------------------------------------------------------------------------------------

@functools.cache
def _trial() -> dict[str, tuple[float, dict[str, float | None]]]:
    """The right MSE (cm²) of each filter on Task 2's trial, with its likely mistakes."""
    trial = experiments.track(DEFAULT, FUSED, sigmas=[SIGMA_V, SIGMA_P])
    y = trial.measurements
    alone = experiments.filter_model(DEFAULT, ("vision",), [SIGMA_V])
    vision, fused = alone.filter(y[:, :1]).estimates[:, 0], trial.positions

    def mse(x: np.ndarray) -> float:
        return float(metrics.mse(x, TRUTH, BURN))

    raw = {"it is the MSE of vision's raw readings, not of a filtered estimate": mse(y[:, 0]),
           "it is the MSE of proprioception's raw readings, not of a filtered estimate":
               mse(y[:, 1])}
    wrong_r = experiments.filter_model(DEFAULT, ("vision",), [SIGMA_P])
    return {
        "vision": (mse(vision), {**raw,
                   "it is the fused filter's MSE: the vision-only filter reads column 0 of the "
                   "readings only, with row 0 of C and the top-left entry of R": mse(fused),
                   "the vision-only filter was given proprioception's readings (column 1); "
                   "vision's are column 0": mse(alone.filter(y[:, 1:]).estimates[:, 0]),
                   "the vision-only filter's R holds proprioception's variance σ_p²; "
                   "vision's σ_v² is the top-left entry of R":
                       mse(wrong_r.filter(y[:, :1]).estimates[:, 0]),
                   **mse_mistakes(vision, TRUTH, BURN, DEFAULT.dt)}),
        "fused": (mse(fused), {**raw,
                  "it is the vision-only filter's MSE: the fused filter reads both columns of "
                  "the readings with your C and R": mse(vision),
                  **mse_mistakes(fused, TRUTH, BURN, DEFAULT.dt)}),
    }


def check_noisier_trial(mse_vision_trial: float, mse_fused_trial: float) -> None:
    """Check Task 2's MSEs of one trial filtered with vision alone and with both senses.

    Recomputed before looking at the student's values: the scenario's trial at σ_v =
    1.5 cm and σ_p = 4.5 cm (:func:`lqe_helpers.experiments.track`), filtered by the
    pack's engine with P0 = diag(1, 1, 1) cm², both senses and vision alone (column 0
    of the readings); each MSE (cm²) after the first ``DEFAULT.burn_in_steps`` samples
    must agree within :data:`MSE_RTOL` relative.

    Parameters
    ----------
    mse_vision_trial, mse_fused_trial : float
        The student's MSEs (cm²).

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: the two swapped, proprioception's readings
        in the vision-only filter, σ_p² as vision's R, the raw readings, the whole trial,
        the burn-in in seconds, the RMSE, ...
    """
    right = _trial()
    for name, value, kind in (("mse_vision_trial", mse_vision_trial, "vision"),
                              ("mse_fused_trial", mse_fused_trial, "fused")):
        expected, mistakes = right[kind]
        judge(name, value, expected, MSE_RTOL, unit="cm²", mistakes=mistakes,
              what=f"the {'vision-only' if kind == 'vision' else 'fused'} filter's MSE "
                   f"recomputed from the task's inputs")
    passed(f"both MSEs of the trial (σ_v = {SIGMA_V:g} cm, σ_p = {SIGMA_P:g} cm, after the "
           f"first {BURN} samples) match the pack's engine on the scenario's draw to "
           f"{tolerance_text(MSE_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Task 3: many runs, paired
# ------------------------------------------------------------------------------------------

def check_noisier_difference(difference: metrics.Interval,
                             whole_difference: metrics.Interval) -> None:
    """Check Task 3's paired difference vision-only − fused MSE, after 1 s and whole trial.

    Recomputed before looking at the student's values: ``DEFAULT.mc_runs`` runs of both
    filters on the scenario's draws (:func:`lqe_helpers.experiments.track`, σ_v = 1.5 cm,
    σ_p = 4.5 cm, run r of both on the same visual noise) and ``metrics.mean_ci95`` of
    the per-run differences, after the first second and over the whole trial; mean and
    ends must agree within :data:`INTERVAL_RTOL` of the interval's scale.

    Parameters
    ----------
    difference, whole_difference : metrics.Interval
        The student's paired differences (cm²) after the first second and whole trial.

    Raises
    ------
    CheckFailed
        With the likely cause: the sign reversed, the runs unpaired, the two time windows
        swapped, σ_p of question (c), σ_p² given as the noise, a percentage, ...
    """
    vision = monte_carlo((SIGMA_V,))
    fused = monte_carlo((SIGMA_V, SIGMA_P))
    fused_c = monte_carlo((SIGMA_V, SIGMA_P_C))
    fused_squared = monte_carlo((SIGMA_V, SIGMA_P**2))
    both_squared = monte_carlo((SIGMA_V**2, SIGMA_P**2))
    windows = ("after the first second", "over the whole trial")
    for part, (name, value) in enumerate((("difference", difference),
                                          ("whole_difference", whole_difference))):
        first, second = vision[part], fused[part]
        mistakes = {
            **interval_mistakes(first, second, "the vision-only MSE", "the fused MSE"),
            f"it is the difference {windows[1 - part]}; {name} is the one "
            f"{windows[part]}": paired(vision[1 - part], fused[1 - part]),
            f"the fused filter's σ_p is question (c)'s {SIGMA_P_C:g} cm; (d) sets σ_p = "
            f"{SIGMA_P:g} cm": paired(first, fused_c[part]),
            "σ_p² (cm²) was given where σ_p (cm) belongs: sigmas holds standard deviations":
                paired(first, fused_squared[part]),
            "the σ² (cm²) were given where the σ (cm) belong: sigmas holds standard "
            "deviations": paired(first, both_squared[part]),
            "it is in % of the vision-only MSE; the task asks for the difference in cm²":
                metrics.mean_ci95(100 * (first - second) / first),
        }
        judge_interval(name, value, paired(first, second), INTERVAL_RTOL, unit="cm²",
                       mistakes=mistakes, what=f"the paired difference vision-only − fused "
                       f"MSE {windows[part]} recomputed from the task's inputs")
    passed(f"vision-only − fused MSE, paired over {DEFAULT.mc_runs} runs after the first "
           f"second and over the whole trial: means and 95 % intervals match the pack's "
           f"engine on the scenario's draws to {tolerance_text(INTERVAL_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Going further 1: theory beside simulation
# ------------------------------------------------------------------------------------------

def _steady(sigmas: list[float]) -> SteadyState:
    """The steady state of vision alone (one σ, cm) or of both senses (two)."""
    sensors = FUSED[:len(sigmas)]
    return experiments.filter_model(DEFAULT, sensors, sigmas).steady_state()


def check_noisier_theory(theory_vision: float, theory_fused: float, weight_p: float) -> None:
    """Check the steady-state position variances and proprioception's share of the gain.

    Recomputed from the filters' models (:func:`lqe_helpers.experiments.filter_model`,
    σ_v = 1.5 cm, σ_p = 4.5 cm) with :func:`lqe_helpers.steady_state.steady_state`: each
    variance is ``estimate_covariance[0, 0]`` (cm²), ``weight_p = K∞[0, 1] / (K∞[0, 0] +
    K∞[0, 1])``; each within :data:`MATRIX_RTOL` relative.

    Parameters
    ----------
    theory_vision, theory_fused : float
        The student's steady-state position variances (cm²).
    weight_p : float
        Proprioception's share of the settled position gain, a fraction.

    Raises
    ------
    CheckFailed
        With the likely cause: the prediction's P∞ for the estimate's variance, σ in R
        where σ² belongs, a standard deviation, the Monte Carlo MSE, vision's share, the
        raw gain, a percentage, ...
    """
    for name, value, sigmas in (("theory_vision", theory_vision, [SIGMA_V]),
                                ("theory_fused", theory_fused, [SIGMA_V, SIGMA_P])):
        steady = _steady(sigmas)
        expected = steady.estimate_covariance[0, 0]
        mistakes = {
            "it is P∞[0, 0], the variance of the one-step prediction (.covariance); the "
            "estimate's is that of (I − K∞C)P∞ (.estimate_covariance)": steady.covariance[0, 0],
            "R holds σ (cm) where the variance σ² (cm²) belongs":
                _steady(list(np.sqrt(sigmas))).estimate_covariance[0, 0],
            "it is a standard deviation (cm); the task asks for the variance (cm²)":
                np.sqrt(expected),
            "it is the Monte Carlo MSE, not the steady state of eq. (5)":
                monte_carlo(tuple(sigmas))[0].mean(),
        }
        if len(sigmas) == 2:
            mistakes["it is the vision-only filter's; theory_fused is the fused filter's"] = \
                _steady([SIGMA_V]).estimate_covariance[0, 0]
            mistakes[f"σ_p is question (c)'s {SIGMA_P_C:g} cm"] = \
                _steady([SIGMA_V, SIGMA_P_C]).estimate_covariance[0, 0]
        judge(name, value, expected, MATRIX_RTOL, unit="cm²", mistakes=mistakes,
              what="the steady-state position variance recomputed from the filter's model")
    gain = _steady([SIGMA_V, SIGMA_P]).gain[0]
    share = gain[1] / gain.sum()
    judge("weight_p", weight_p, share, MATRIX_RTOL, what="proprioception's share of K∞[0]",
          mistakes={
              "it is vision's share: proprioception is column 1 of the gain": gain[0] / gain.sum(),
              "it is K∞[0, 1] itself; its share divides by the row's sum K∞[0, 0] + K∞[0, 1]":
                  gain[1],
              "it is in %; the task asks for a fraction between 0 and 1": 100 * share})
    passed(f"both steady-state position variances and proprioception's share of K∞[0] match "
           f"steady_state of the filters' models to {tolerance_text(MATRIX_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Going further 2: the sweep over σ_p
# ------------------------------------------------------------------------------------------

def _theory_margin(dense: np.ndarray, sigma_v: float = SIGMA_V) -> np.ndarray:
    """The steady-state improvement (%) of fusion over vision alone at each σ_p (cm)."""
    level = _steady([SIGMA_V]).estimate_covariance[0, 0]
    sigmas = np.stack([np.full_like(dense, sigma_v), dense], axis=-1)
    fused = experiments.filter_model(DEFAULT, FUSED, sigmas).steady_state()
    return 100 * (1 - fused.estimate_covariance[..., 0, 0] / level)


def check_proprioception_sweep(sweep_sigma_p: np.ndarray, margin_by_sigma: list,
                               dense_sigma_p: np.ndarray, theory_margin: np.ndarray) -> None:
    """Check the sweep's paired improvement (%) and the theory's, against σ_p.

    ``sweep_sigma_p`` must include 1.5 and 4.5 cm. The paired improvement
    ``metrics.mean_ci95(100 (MSE_vision − MSE_fused) / MSE_vision)`` is recomputed with
    the engine at three of its σ_p (the smallest, 1.5 and 4.5 cm; the full sweep would
    take seconds) within :data:`INTERVAL_RTOL`; the theory on the whole ``dense_sigma_p``
    from the steady states, within :data:`MATRIX_RTOL` relative.

    Parameters
    ----------
    sweep_sigma_p : array_like, shape (S,)
        The σ_p simulated (cm), increasing.
    margin_by_sigma : list of metrics.Interval, length S
        The paired improvement (%) at each σ_p.
    dense_sigma_p, theory_margin : array_like, shape (T,)
        The theory's σ_p (cm) and its improvement (%) at each.

    Raises
    ------
    CheckFailed
        With the likely cause: cm² instead of %, % of the fused MSE, the sign reversed, a
        fraction, the whole trial, σ in R, the prediction's P∞, ...
    """
    grid = sigma_grid("sweep_sigma_p", sweep_sigma_p)
    margins = interval_list(margin_by_sigma, "margin_by_sigma",
                            "value of sweep_sigma_p in its order", grid.size)
    marks = [np.flatnonzero(np.isclose(grid, mark, rtol=1e-9, atol=0)) for mark in (1.5, 4.5)]
    if not all(mark.size for mark in marks):
        raise CheckFailed("sweep_sigma_p must include 1.5 and 4.5 cm, the σ_p of questions (c) "
                          "and (d)")
    vision, vision_whole = monte_carlo((SIGMA_V,))
    for index in sorted({0, int(marks[0][0]), int(marks[1][0])}):
        fused, fused_whole = monte_carlo((SIGMA_V, float(grid[index])))
        judge_interval(
            f"margin_by_sigma[{index}]", margins[index],
            metrics.mean_ci95(100 * (vision - fused) / vision), INTERVAL_RTOL, unit="%",
            what=f"the paired improvement at σ_p = {grid[index]:g} cm recomputed with the engine",
            mistakes={
                "it is the difference in cm²; the task asks for it in % of the vision-only MSE":
                    paired(vision, fused),
                "it is in % of the fused MSE; divide by the vision-only MSE":
                    metrics.mean_ci95(100 * (vision - fused) / fused),
                "the sign is reversed: the improvement is vision-only − fused":
                    metrics.mean_ci95(100 * (fused - vision) / vision),
                "it is a fraction; the task asks for %":
                    metrics.mean_ci95((vision - fused) / vision),
                "it is over the whole trial; the MSEs leave out the first second":
                    metrics.mean_ci95(100 * (vision_whole - fused_whole) / vision_whole)})
    dense = sigma_grid("dense_sigma_p", dense_sigma_p)
    expected = _theory_margin(dense)
    small = np.all(dense < 1e3)
    judge("theory_margin", theory_margin, expected, MATRIX_RTOL, unit="%",
          what="the steady-state improvement recomputed on dense_sigma_p", mistakes={
              "the variances σ² went where the σ belong (the model squares them itself)":
                  _theory_margin(dense**2, SIGMA_V**2) if small else None,
              "σ_p² went where σ_p belongs (the model squares it itself)":
                  _theory_margin(dense**2) if small else None,
              "it is a fraction; the task asks for %": expected / 100,
              "the sign is reversed: the improvement is 1 − fused / vision-only": -expected})
    passed(f"the paired improvement at σ_p = {grid[0]:g}, 1.5 and 4.5 cm matches the engine "
           f"to {tolerance_text(INTERVAL_RTOL)} relative, the theory at all "
           f"{dense.size} σ_p matches the steady states to {tolerance_text(MATRIX_RTOL)}")


def check_sweep_reading(better: int, worse: int, benefit_below: dict,
                        margin_by_sigma: list, dense_sigma_p: np.ndarray) -> None:
    """Check what the task read off the sweep: counts and where the benefit fades.

    ``better`` and ``worse`` count the σ_p whose paired interval in ``margin_by_sigma``
    (judged by :func:`check_proprioception_sweep`) lies entirely above or below zero;
    ``benefit_below[level]`` is the first σ_p of ``dense_sigma_p`` (cm) from which the
    steady-state improvement, recomputed from the theory, is below ``level`` % (10 and 1).
    Counts exactly, σ_p within :data:`MATRIX_RTOL` relative.

    Parameters
    ----------
    better, worse : int
        The student's counts.
    benefit_below : dict of int to float
        σ_p (cm) keyed by the level (%), 10 and 1.
    margin_by_sigma : list of metrics.Interval
        The sweep's paired improvements (%), as the previous task made them.
    dense_sigma_p : array_like, shape (T,)
        The theory's σ_p (cm), increasing.

    Raises
    ------
    CheckFailed
        With the likely cause: a positive mean counted as significant, an interval that
        reaches below zero counted as worse, σ_p in units of σ_v, the last σ_p above the
        level, ...
    """
    dense = sigma_grid("dense_sigma_p", dense_sigma_p)
    margins = interval_list(margin_by_sigma, "margin_by_sigma",
                            "value of sweep_sigma_p in its order")
    try:
        parts = np.array([[float(m.low), float(m.mean), float(m.high)] for m in margins])
    except (AttributeError, TypeError, ValueError):
        raise CheckFailed("margin_by_sigma must hold the metrics.Interval of each σ_p "
                          "(check_proprioception_sweep passes it)") from None
    low, mean, high = parts.T
    judge("better", better, np.sum(low > 0), MSE_RTOL, unit="σ_p values", mistakes={
        "it counts every positive mean; significantly better needs the whole interval above "
        "zero (its low end > 0)": np.sum(mean > 0),
        "it counts the σ_p where fusion is not significantly better": np.sum(low <= 0)},
        what="the number of intervals entirely above zero")
    judge("worse", worse, np.sum(high < 0), MSE_RTOL, unit="σ_p values", mistakes={
        "it counts every interval that reaches below zero; significantly worse needs the "
        "whole interval below zero (its high end < 0)": np.sum(low < 0),
        "it counts every negative mean; significantly worse needs the whole interval below "
        "zero (its high end < 0)": np.sum(mean < 0)},
        what="the number of intervals entirely below zero")
    crossings = entries("benefit_below", benefit_below, BENEFIT_LEVELS, "σ_p (cm)")
    theory = _theory_margin(dense)
    for level in BENEFIT_LEVELS:
        below = np.flatnonzero(theory < level)
        if below.size == 0 or below[0] == 0:
            raise CheckFailed(f"dense_sigma_p must reach from below to above where the "
                              f"benefit falls under {level} %")
        first = below[0]
        judge(f"benefit_below[{level}]", crossings[level], dense[first], MATRIX_RTOL,
              unit="cm", what="the first σ_p of dense_sigma_p where the theory is below "
              f"{level} %", mistakes={
                  "it is σ_p in units of σ_v (σ_p / σ_v); the task asks for σ_p in cm":
                      dense[first] / SIGMA_V,
                  f"it is the last σ_p where the benefit is still above {level} %; the task "
                  f"asks for the first where it is below": dense[first - 1]})
    passed(f"the counts match the intervals ({int(np.sum(low > 0))} above zero, "
           f"{int(np.sum(high < 0))} below) and the σ_p where the theory falls below "
           f"{' and '.join(f'{level} %' for level in BENEFIT_LEVELS)} match the steady states "
           f"to {tolerance_text(MATRIX_RTOL)} relative")
