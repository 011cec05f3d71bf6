"""Checks of notebook 00's Going further tasks C and E: choosing σ_j, with and without the truth.

- :func:`check_jerk_sweep` (C): the Monte Carlo sweep of σ_j split into its systematic
  and noise parts, beside the filter's expected variance;
- :func:`check_jerk_sweep_reading` (C): where the sweep is flat and where the filter's belief
  matches its real error;
- :func:`check_jerk_from_readings` (E): the NIS and the σ_j chosen without the true path.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np

from .. import experiments, jerk_tuning, metrics
from ..scenario import DEFAULT
from .judging import judge
from .machinery import (
    MATRIX_RTOL,
    MSE_RTOL,
    CheckFailed,
    keyed_entries,
    passed,
    shaped_argument,
    tolerance_text,
)
from .remembering import remembered
from .shared_runs import vision_runs

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback


def jerk_grid() -> np.ndarray:
    """Task C's grid (26,): 25 log-spaced σ_j from 10 to 100 000 cm/s³ and the derived one."""
    return np.sort(np.append(np.geomspace(10.0, 1.0e5, 25), DEFAULT.process_jerk_std))


def choice_grid() -> np.ndarray:
    """Task E's grid (17,) of σ_j (cm/s³), 700 to 2 800, log-spaced."""
    return np.geomspace(700.0, 2800.0, 17)


# ------------------------------------------------------------------------------------------
# C · too small or too large
# ------------------------------------------------------------------------------------------

@remembered
def _sweep() -> dict[str, np.ndarray]:
    """Task C's sweep recomputed (read-only arrays), with the usual wrong variants."""
    grid = jerk_grid()
    truth, burn, runs = DEFAULT.truth[:, 0], DEFAULT.burn_in_steps, DEFAULT.mc_runs
    parts: dict[str, list] = {key: [] for key in (
        "runs", "systematic", "noise", "expected", "whole", "systematic_whole", "noise_var",
        "predicted", "runs_variance")}
    # The task's draw, then one noise-free run: one filter call per σ_j gives both.
    draw = np.concatenate([DEFAULT.unit_noise(runs, ("vision",)),
                           np.zeros((1, DEFAULT.n_steps, 1))])
    for value in grid:
        variant = dataclasses.replace(DEFAULT, jerk_std=float(value))
        both = experiments.track(variant, runs=runs + 1, noise=draw)
        positions, clean = both.positions[:runs], both.positions[runs]
        noise = positions - clean
        steady = experiments.filter_model(variant).steady_state()
        parts["runs"].append(both.mse()[:runs])
        parts["whole"].append(metrics.mse(positions, truth))
        parts["runs_variance"].append(np.var(positions[:, burn:] - truth[burn:], axis=-1))
        parts["systematic"].append(float(both.mse()[runs]))
        parts["systematic_whole"].append(float(metrics.mse(clean, truth)))
        parts["noise"].append(float(np.mean(np.mean(noise[:, burn:] ** 2, axis=-1))))
        parts["noise_var"].append(float(np.mean(np.var(noise[:, burn:], axis=0))))
        parts["expected"].append(steady.estimate_covariance[0, 0])
        parts["predicted"].append(steady.covariance[0, 0])
    found = {"grid": grid}
    for key, values in parts.items():
        found[key] = np.stack(values, axis=-1) if key in ("runs", "whole", "runs_variance") \
            else np.array(values)
    for array in found.values():
        array.setflags(write=False)
    return found


def check_jerk_sweep(sweep_runs: np.ndarray, systematic: np.ndarray, noise_part: np.ndarray,
                     expected: np.ndarray) -> None:
    """Check Task C's sweep of σ_j (the 26 values of :func:`jerk_grid`).

    Recomputed with the pack's engine on the task's draws: per-run MSEs after the burn-in
    of ``DEFAULT.mc_runs`` runs at each σ_j, the MSE of a noise-free run, the mean MSE of
    each run minus the noise-free run, and the settled filter's own position variance
    ``experiments.filter_model(variant).steady_state().estimate_covariance[0, 0]``; each
    within :data:`MSE_RTOL` relative (cm²).

    Parameters
    ----------
    sweep_runs : ndarray, shape (runs, 26)
    systematic, noise_part, expected : ndarray, shape (26,)

    Raises
    ------
    CheckFailed
        With the likely cause: the runs and σ_j axes swapped, the whole trial, the
        variance of the error, the prediction's variance for the estimate's, ...
    """
    right = _sweep()
    runs, size = DEFAULT.mc_runs, right["grid"].size
    if np.shape(sweep_runs) == (size, runs):
        raise CheckFailed(f"sweep_runs has shape ({size}, {runs}): one row per run and one "
                          f"column per σ_j, shape ({runs}, {size})")
    judge("sweep_runs", sweep_runs, right["runs"], MSE_RTOL, unit="cm²",
          what="the per-run MSEs recomputed with the engine",
          mistakes={"the MSEs are those of the whole trial: leave out the burn-in":
                    right["whole"],
                    "it is the variance of each run's error (its mean subtracted); the MSE "
                    "averages the squared errors themselves": right["runs_variance"]})
    judge("systematic", systematic, right["systematic"], MSE_RTOL, unit="cm²",
          what="the noise-free run's MSE recomputed",
          mistakes={"it is the noise-free MSE of the whole trial: leave out the burn-in":
                    right["systematic_whole"],
                    "it is the Monte Carlo mean MSE; the systematic part is the MSE of the "
                    "run with no sensor noise": right["runs"].mean(axis=0)})
    judge("noise_part", noise_part, right["noise"], MSE_RTOL, unit="cm²",
          what="the mean MSE of each run minus the noise-free run, recomputed",
          mistakes={"it is the variance over runs at each sample, averaged; the noise part "
                    "is the mean squared difference from the noise-free run":
                    right["noise_var"],
                    "it is the mean MSE minus the systematic MSE; compute it from each run "
                    "minus the noise-free run (the two agree only on average)":
                    right["runs"].mean(axis=0) - right["systematic"]})
    judge("expected", expected, right["expected"], MSE_RTOL, unit="cm²",
          what="the settled filter's position variance recomputed",
          mistakes={"it is the prediction's variance (.covariance, before a reading); the "
                    "estimate's is .estimate_covariance": right["predicted"],
                    "it is a standard deviation (cm); the filter's expected MSE is the "
                    "variance [0, 0] itself": np.sqrt(right["expected"])})
    passed(f"the sweep over {size} values of σ_j (per-run MSEs of {runs} runs, systematic and "
           f"noise parts, the settled filter's variance) matches the pack's engine on the "
           f"task's draws to {tolerance_text(MSE_RTOL)} relative")


def check_jerk_sweep_reading(near: object, crossing_jerk: object) -> None:
    """Check Task C's reading of the sweep: the flat valley and where belief meets reality.

    Recomputed from the sweep of :func:`check_jerk_sweep`: ``near``, the smallest and
    largest σ_j of the grid whose Monte Carlo mean MSE is within 10 % of the smallest;
    ``crossing_jerk``, where the filter's expected variance equals the mean MSE,
    the log of their ratio interpolated linearly in log σ_j between the grid values
    around its sign change; both within :data:`MATRIX_RTOL` relative (cm/s³).

    Raises
    ------
    CheckFailed
        With the likely cause: the MSEs instead of the σ_j, an absolute margin, the
        grid value before or after the crossing, linear instead of logarithmic
        interpolation, ...
    """
    right = _sweep()
    grid, mean = right["grid"], right["runs"].mean(axis=0)
    inside = grid[mean <= 1.1 * mean.min()]
    absolute = grid[mean <= mean.min() + 0.1]
    judge("near", shaped_argument(near, "near", (2,), "(smallest σ_j, largest σ_j) in cm/s³"),
          [inside.min(), inside.max()], MATRIX_RTOL, unit="cm/s³",
          what="the σ_j within 10 % of the smallest mean MSE, recomputed",
          mistakes={
              "it holds MSEs (cm²); the task asks for the σ_j (cm/s³) at both ends":
                  [mean[grid == inside.min()][0], mean[grid == inside.max()][0]],
              "it uses a margin of 0.1 cm²; within 10 % means up to 1.1 times the smallest":
                  [absolute.min(), absolute.max()],
          })
    gap = np.log(right["expected"]) - np.log(mean)
    i = int(np.flatnonzero(np.diff(np.sign(gap)))[0])
    fraction = gap[i] / (gap[i] - gap[i + 1])
    logs = np.log(grid[i:i + 2])
    linear_gap = right["expected"] - mean
    linear = grid[i] + linear_gap[i] / (linear_gap[i] - linear_gap[i + 1]) * (grid[i + 1]
                                                                             - grid[i])
    judge("crossing_jerk", crossing_jerk, np.exp(logs[0] + fraction * (logs[1] - logs[0])),
          MATRIX_RTOL, unit="cm/s³",
          what="the σ_j where the expected variance meets the mean MSE, recomputed",
          mistakes={
              "it is the grid value just before the crossing; interpolate between the two "
              "values around it": grid[i],
              "it is the grid value just after the crossing; interpolate between the two "
              "values around it": grid[i + 1],
              "it interpolates the difference linearly in σ_j; interpolate the log of the "
              "ratio linearly in log σ_j": linear,
          })
    passed(f"near and crossing_jerk match the sweep recomputed with the pack's engine, to "
           f"{tolerance_text(MATRIX_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# E · σ_j without the true path
# ------------------------------------------------------------------------------------------

#: The keys of Task E's ``chosen``.
CHOICE_KEYS = ("likelihood", "NIS", "MSE")


@remembered
def _choice() -> dict[str, object]:
    """Task E recomputed: the NIS at the derived σ_j (and wrong variants), and the choice.

    The NIS is ν²/S of the shared runs' innovations, as the task computes it; the choice
    is the pack's :func:`lqe_helpers.jerk_tuning.tune_jerk_std` on the task's grid (the
    engine the task names, tested against the NIS and the Gaussian log-likelihood in
    ``tests/test_jerk_tuning.py``), not a second copy of its formulas.
    """
    burn = DEFAULT.burn_in_steps
    tracking = vision_runs()
    innovations = tracking.innovations()
    nu, S = innovations.values[..., 0], innovations.covariances[..., 0, 0]
    R = DEFAULT.sigma_v**2
    nis = {"right": float(np.mean(nu[:, burn:] ** 2 / S[:, burn:])), "mistakes": {
        "the NIS divides by S, the innovation's variance (cm²); it was divided by its "
        "standard deviation √S": float(np.mean(nu[:, burn:] ** 2 / np.sqrt(S[:, burn:]))),
        "the innovation is not squared: the NIS is ν²/S":
            float(np.mean(nu[:, burn:] / S[:, burn:])),
        "it divides by the sensor's variance σ_v² alone; S = C P Cᵀ + R also holds the "
        "prediction's own uncertainty": float(np.mean(nu[:, burn:] ** 2 / R)),
        f"it includes the burn-in: leave out the first {burn} samples":
            float(np.mean(nu**2 / S)),
        "it is the mean squared innovation (cm²), not normalised by S":
            float(np.mean(nu[:, burn:] ** 2)),
    }}
    choice = jerk_tuning.tune_jerk_std(DEFAULT, choice_grid())
    chosen = {"likelihood": choice.by_likelihood, "NIS": choice.by_nis, "MSE": choice.by_mse}
    return {"nis": nis, "chosen": chosen, "choice": choice}


def check_jerk_from_readings(nis_mean: object, chosen: Mapping[str, float]) -> None:
    """Check Task E: the mean NIS at the derived σ_j and the σ_j chosen three ways.

    Recomputed before looking at the student's: the innovations of ``DEFAULT.mc_runs``
    vision-only runs at the derived σ_j, ``nis_mean`` the mean of ν²/S after the burn-in
    (within :data:`MSE_RTOL` relative); then, on the grid :func:`choice_grid` and the
    same draws, the σ_j of the largest mean innovation log-likelihood, of the mean NIS
    equal to 1 and of the smallest mean MSE, each refined between grid points, from
    :func:`lqe_helpers.jerk_tuning.tune_jerk_std` (within :data:`MSE_RTOL` relative).

    Parameters
    ----------
    nis_mean : float
        The mean NIS (no unit).
    chosen : dict of str to float
        σ_j (cm/s³) keyed "likelihood", "NIS" and "MSE".

    Raises
    ------
    CheckFailed
        With the likely cause: divided by √S or by σ_v² alone, not squared, the burn-in
        included; two choices swapped, ...
    """
    right = _choice()
    judge("nis_mean", nis_mean, right["nis"]["right"], MSE_RTOL,
          what="the mean NIS recomputed from the innovations", mistakes=right["nis"]["mistakes"])
    picks = keyed_entries(chosen, "chosen", CHOICE_KEYS, "σ_j values (cm/s³)")
    for key in CHOICE_KEYS:
        others = {f"it is the σ_j chosen by {other}, not by {key}": right["chosen"][other]
                  for other in CHOICE_KEYS if other != key}
        judge(f"chosen[{key!r}]", picks[key], right["chosen"][key], MSE_RTOL, unit="cm/s³",
              what=f"the σ_j chosen by {key} on the task's grid, recomputed", mistakes=others)
    passed(f"nis_mean and the three choices of σ_j match the innovations, NIS and MSEs "
           f"recomputed on the task's grid and draws ({DEFAULT.mc_runs} runs), to "
           f"{tolerance_text(MSE_RTOL)} relative")
