"""Checks of notebook 04's Going further 1 and 2: theory beside simulation, the σ_p sweep.

- :func:`check_noisier_theory` (1): the steady-state position variances and
  proprioception's share of the settled gain;
- :func:`check_proprioception_sweep` and :func:`check_sweep_reading` (2): the paired
  improvement along a sweep of σ_p, the theory's, and what the task reads off them.

Each recomputes its task's values from the filters' models and the pack's engine on the
scenario's draws, sharing the Monte Carlo runs of
:mod:`lqe_helpers.checks.noisier_proprioception`.
"""

from __future__ import annotations

import numpy as np

from .. import experiments, metrics
from ..scenario import DEFAULT
from ..steady_state import SteadyState
from .judging import judge, judge_interval
from .machinery import (
    INTERVAL_RTOL,
    MATRIX_RTOL,
    MSE_RTOL,
    CheckFailed,
    interval_list,
    passed,
    tolerance_text,
)
from .noisier_proprioception import (
    BENEFIT_LEVELS,
    FUSED,
    SIGMA_P,
    SIGMA_P_C,
    SIGMA_V,
    entries,
    monte_carlo,
    paired,
    sigma_grid,
)

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback


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
