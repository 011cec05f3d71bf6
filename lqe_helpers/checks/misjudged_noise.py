"""Checks of notebook 04, Going further 4: a fused filter that misjudges σ_p (true 4.5 cm).

- :func:`check_misjudged`: the paired extra MSE of the overtrusting (σ̃_p = 1.5 cm) and
  undertrusting (13.5 cm) filters over the correctly informed one;
- :func:`check_misjudged_nis`: their normalised innovation squared (NIS), which an
  observer can compute without the true path;
- :func:`check_assumed_sweep`: the extra MSE along a sweep of the assumed σ̃_p.

Each recomputes its task's values with the pack's engine on the scenario's draws, sharing
the Monte Carlo runs of :mod:`lqe_helpers.checks.noisier_proprioception`.
"""

from __future__ import annotations

import numpy as np

from .. import experiments, metrics
from ..scenario import DEFAULT
from .judging import judge, judge_interval
from .machinery import INTERVAL_RTOL, MSE_RTOL, interval_list, passed, tolerance_text
from .noisier_proprioception import (
    BURN,
    FUSED,
    SIGMA_P,
    SIGMA_V,
    entries,
    monte_carlo,
    paired,
    sigma_grid,
)
from .paired_mistakes import interval_mistakes
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: The σ̃_p the misjudging filters assume (cm), by case.
ASSUMED = {"overtrust": 1.5, "undertrust": 13.5}


def _as_number(value: object) -> object:
    """A result object's ``mean`` (a NISTest, an Interval), else ``value`` itself."""
    mean = getattr(value, "mean", value)
    return value if callable(mean) else mean


def _excess_mistakes(assumed: float) -> tuple[metrics.Interval, dict]:
    """The right excess MSE (cm²) of a filter assuming σ̃_p = ``assumed`` and its mistakes."""
    fused, fused_whole = monte_carlo((SIGMA_V, SIGMA_P))
    wrong, wrong_whole = monte_carlo((SIGMA_V, SIGMA_P), (SIGMA_V, assumed))
    swapped = monte_carlo((SIGMA_V, assumed), (SIGMA_V, SIGMA_P))[0]
    return paired(wrong, fused), {
        **interval_mistakes(wrong, fused, f"the MSE assuming σ̃_p = {assumed:g} cm",
                            "the correctly informed fused MSE"),
        "it is the excess over vision alone; the task compares with the correctly informed "
        "fused filter": paired(wrong, monte_carlo((SIGMA_V,))[0]),
        f"true and assumed σ_p are swapped (readings made with {assumed:g} cm): sigmas holds "
        f"the true σ's, assumed_sigmas what the filter believes": paired(swapped, fused),
        "it is over the whole trial; the MSEs leave out the first second":
            paired(wrong_whole, fused_whole),
    }


def check_misjudged(excess: dict) -> None:
    """Check the paired extra MSE of the filters that misjudge σ_p (true 4.5 cm).

    For ``excess["overtrust"]`` (the filter assumes σ̃_p = 1.5 cm) and
    ``excess["undertrust"]`` (13.5 cm): ``metrics.mean_ci95`` of the per-run MSE minus the
    correctly informed fused filter's, recomputed with
    :func:`lqe_helpers.experiments.track` (``assumed_sigmas``); within
    :data:`INTERVAL_RTOL` of the interval's scale.

    Parameters
    ----------
    excess : dict of str to metrics.Interval
        The paired extra MSE (cm²) by case, "overtrust" and "undertrust" at least.

    Raises
    ------
    CheckFailed
        With the likely cause: the sign reversed, true and assumed σ swapped, the excess
        over vision alone, the other case's value, the whole trial, unpaired, ...
    """
    given = entries("excess", excess, tuple(ASSUMED), "metrics.Interval (cm²)")
    for case, assumed in ASSUMED.items():
        expected, mistakes = _excess_mistakes(assumed)
        for other, other_assumed in ASSUMED.items():
            if other != case:
                mistakes[f"it is the {other} case's value"] = _excess_mistakes(other_assumed)[0]
        judge_interval(f"excess[{case!r}]", given[case], expected, INTERVAL_RTOL,
                       unit="cm²", mistakes=mistakes, what="the paired excess MSE recomputed "
                       "from the task's inputs")
    passed(f"the paired excess MSE of both misjudging filters over {DEFAULT.mc_runs} runs "
           f"matches the pack's engine to {tolerance_text(INTERVAL_RTOL)} relative")


@remembered
def _nis(assumed: float) -> dict[str, float]:
    """The NIS of the fused filter assuming σ̃_p = ``assumed`` (true 4.5 cm), and mistakes."""
    tracking = experiments.track(DEFAULT, FUSED, sigmas=[SIGMA_V, SIGMA_P],
                                 assumed_sigmas=[SIGMA_V, assumed], runs=DEFAULT.mc_runs)
    innovations = tracking.innovations()
    test, whole = metrics.nis_test(innovations, BURN), metrics.nis_test(innovations, 0)
    steps, sensors = DEFAULT.n_steps - BURN, len(FUSED)

    def share(means: np.ndarray, band: tuple[float, float]) -> float:
        return float(100 * np.mean((band[0] <= means) & (means <= band[1])))

    inside = share(test.run_means, metrics.nis_band(sensors, steps))
    squared = np.sum(innovations.values[..., BURN:, :] ** 2, axis=-1)
    return {"mean": test.mean, "whole": whole.mean, "squared": float(np.mean(squared)),
            "inside": inside, "grand": share(test.run_means, (test.low, test.high)),
            "one step": share(test.run_means, metrics.nis_band(sensors, 1)),
            "one sensor": share(test.run_means, metrics.nis_band(1, steps)),
            "inside whole": share(whole.run_means, metrics.nis_band(sensors, DEFAULT.n_steps))}


def check_misjudged_nis(nis: dict, inside: dict) -> None:
    """Check the NIS test of the correct, overtrusting and undertrusting fused filters.

    For each case ("correct": σ̃_p = 4.5 cm, "overtrust": 1.5, "undertrust": 13.5; true
    4.5): ``nis[case]`` is :func:`lqe_helpers.metrics.nis_test` of its innovations after
    the first second (its ``mean`` is judged), ``inside[case]`` the % of runs whose own
    mean NIS lies in one run's 95 % band ``metrics.nis_band(2, steps after the burn-in)``;
    recomputed with the engine, each within :data:`MSE_RTOL` relative.

    Parameters
    ----------
    nis : dict of str to metrics.NISTest
        The NIS test of each case (or its mean, a number).
    inside : dict of str to float
        The % of runs inside one run's band, by case.

    Raises
    ------
    CheckFailed
        With the likely cause: the burn-in kept, innovations not normalised by S, the
        NIS divided by the number of sensors, the grand mean's band for one run, a single
        step's band, a fraction, the % outside, another case's value, ...
    """
    cases = {"correct": SIGMA_P, **ASSUMED}
    means = entries("nis", nis, tuple(cases), "metrics.nis_test results")
    shares = entries("inside", inside, tuple(cases), "percentages of runs")
    for case, assumed in cases.items():
        right = _nis(assumed)
        judge(f"nis[{case!r}].mean", _as_number(means[case]), right["mean"], MSE_RTOL,
              what="the mean NIS recomputed from the task's inputs", mistakes={
                  "the first second is not left out: give nis_test the burn-in": right["whole"],
                  "the innovations are not normalised by their covariance S: the NIS is "
                  "eᵀS⁻¹e (no unit), not eᵀe (cm²)": right["squared"],
                  "it is divided by the number of sensors; the NIS of two sensors is "
                  "expected to be 2": right["mean"] / 2,
                  **{f"it is the {other} case's value": _nis(value)["mean"]
                     for other, value in cases.items() if other != case}})
        judge(f"inside[{case!r}]", shares[case], right["inside"], MSE_RTOL, unit="%",
              what="the % of runs inside one run's band recomputed from the task's inputs",
              mistakes={
                  "it uses the band of the grand mean (runs × steps, nis_test's low and "
                  "high); one run's mean needs the band of one run's steps": right["grand"],
                  "it uses the band of a single step; one run's mean averages all its steps "
                  "after the burn-in": right["one step"],
                  "it uses the band of one sensor; the fused filter has two":
                      right["one sensor"],
                  "it is a fraction between 0 and 1; the task asks for %":
                      right["inside"] / 100,
                  "it is the % of runs outside the band": 100 - right["inside"],
                  "the first second is not left out": right["inside whole"]})
    passed(f"the mean NIS of all three filters and the share of runs inside one run's band "
           f"match the pack's engine ({DEFAULT.mc_runs} runs, after the first {BURN} samples)"
           f" to {tolerance_text(MSE_RTOL)} relative")


def check_assumed_sweep(assumed_grid: np.ndarray, excess_ci: list) -> None:
    """Check the sweep of the assumed σ̃_p: the paired extra MSE over the correct model.

    ``excess_ci[i]`` is ``metrics.mean_ci95`` of the per-run MSE of the filter assuming
    ``assumed_grid[i]`` (true σ_p = 4.5 cm) minus the correctly informed fused MSE (cm²).
    Recomputed with the engine at three σ̃_p of the grid (the first, a quarter of the
    way along, the last; the whole sweep would take seconds), within
    :data:`INTERVAL_RTOL` of the interval's scale.

    Parameters
    ----------
    assumed_grid : array_like, shape (S,)
        The σ̃_p the filter assumes (cm), increasing.
    excess_ci : list of metrics.Interval, length S
        The paired extra MSE (cm²) at each σ̃_p.

    Raises
    ------
    CheckFailed
        With the likely cause: the sign reversed, true and assumed σ swapped, the excess
        over vision alone, the whole trial, unpaired, ...
    """
    grid = sigma_grid("assumed_grid", assumed_grid)
    excesses = interval_list(excess_ci, "excess_ci", "value of assumed_grid in its order",
                             grid.size)
    # The first, a quarter of the way, the last; never the true σ_p, whose excess is
    # zero up to round-off.
    true = np.isclose(grid, SIGMA_P, rtol=1e-9, atol=0)
    quarter = grid.size // 4 + int(true[grid.size // 4])
    picked = sorted(index for index in {0, quarter, grid.size - 1} if not true[index])
    for index in picked:
        expected, mistakes = _excess_mistakes(float(grid[index]))
        judge_interval(f"excess_ci[{index}]", excesses[index], expected, INTERVAL_RTOL,
                       unit="cm²", mistakes=mistakes, what=f"the paired excess MSE at σ̃_p = "
                       f"{grid[index]:g} cm recomputed from the task's inputs")
    shown = ", ".join(f"{grid[index]:g}" for index in picked)
    passed(f"the paired excess MSE at σ̃_p = {shown} cm matches the pack's engine over "
           f"{DEFAULT.mc_runs} runs to {tolerance_text(INTERVAL_RTOL)} relative")
