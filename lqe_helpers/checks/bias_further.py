"""Checks of notebook 06's Going further tasks, each recomputed from the task's inputs.

- :func:`check_bias_precision` (A): the model's one-step miss on the true path, the
  honesty of the bias band and the bias's final precision beside σ_a/√n;
- :func:`check_dead_reckoning` (B): the RMS position error of dead reckoning (bias
  ignored, bias known) and of the filter;
- :func:`check_sigma_a_sweep` (C): the sweep of the signal's noise σ_a;
- :func:`check_bias_and_vision` (C): the size of the bias and vision's noise.

Every run is made with :func:`lqe_helpers.bias_model.track_with_input` (or its
:func:`~lqe_helpers.bias_model.unbiased_run`) and :func:`lqe_helpers.experiments.track`,
as the notebook's tasks make them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from .. import bias_model, experiments, metrics
from ..scenario import DEFAULT
from .judging import judge, judge_interval
from .machinery import (
    INTERVAL_RTOL,
    MATRIX_RTOL,
    MSE_RTOL,
    CheckFailed,
    interval_list,
    keyed_entries,
    passed,
    shaped_argument,
    tolerance_text,
)
from .paired_mistakes import interval_mistakes
from .remembering import remembered
from .shared_runs import vision_runs

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: The true bias (cm/s²) and signal noise (cm/s²) of the notebook's runs.
BIAS, SIGMA_A = bias_model.DEFAULT_BIAS, bias_model.DEFAULT_SIGMA_A


@remembered
def _monte_carlo() -> bias_model.InputTracking:
    """The notebook's ``mc``: the default runs with the signal."""
    return bias_model.track_with_input(DEFAULT, bias=BIAS, sigma_a=SIGMA_A,
                                       runs=DEFAULT.mc_runs, noise=_noise())


@remembered
def _vision_only() -> np.ndarray:
    """Per-run MSEs (runs,) of the vision-only filter on the same camera noise (cm²)."""
    return vision_runs().mse()  # bias_model.unit_noise's column 0 is vision's draw


# ------------------------------------------------------------------------------------------
# A · the model on the true path, and the bias's final precision
# ------------------------------------------------------------------------------------------

def _one_step_miss(readings: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Largest |true state − one model step from the previous true state| of p, v, b."""
    dt = DEFAULT.dt
    states = bias_model.true_states(DEFAULT, BIAS)
    G = bias_model.input_matrix(dt)[:, 0]
    stepped = states[:-1] @ F.T + readings[:, None] * G
    return np.abs(states[1:] - stepped).max(axis=0)


def check_bias_precision(miss: object, inside: object, final_std: object,
                         ideal: object) -> None:
    """Check Task A: one model step on the true path, the band's coverage, b̂'s precision.

    Recomputed from the task's inputs: ``miss``, the largest |z_{j+1} − (F z_j + G u)|
    over the true states ``[p, v, b]`` with the noise-free reading u = a_{j+1} + b of
    the step (absolute tolerance :data:`MSE_RTOL` times the largest miss); ``inside``,
    the fraction of the ``DEFAULT.mc_runs`` runs whose b̂ at 10 s lies within ±2σ of the
    true bias; ``final_std``, the filter's σ of b̂ at 10 s (cm/s²); ``ideal``,
    σ_a/√n for the n readings of the trial (cm/s²); the last three within
    :data:`MATRIX_RTOL` relative.

    Raises
    ------
    CheckFailed
        With the likely cause: the reading of the step before, the reading without the
        bias, F transposed; a ±1σ band, a percentage; the variance or the RMS error for
        the filter's σ; σ_a/n, the readings after the burn-in only, ...
    """
    F = bias_model.transition_matrix(DEFAULT.dt)
    accelerations = bias_model.step_accelerations(DEFAULT)
    right = _one_step_miss(accelerations[1:] + BIAS, F)
    judge("miss", shaped_argument(miss, "miss", (3,), "the largest miss of p, v and b"),
          right, MSE_RTOL, unit="cm, cm/s, cm/s²",
          what="the largest one-step miss recomputed on the true path",
          mistakes={
              "each step is fed the reading of the step before (accelerations[j] + b); the "
              "step from j to j + 1 gets the reading over that step, accelerations[j + 1] + b":
                  _one_step_miss(accelerations[:-1] + BIAS, F),
              "the reading has no bias: the signal reads a + b, and F removes the bias":
                  _one_step_miss(accelerations[1:], F),
              "F is applied transposed: a state stored as a row z moves as z Fᵀ":
                  _one_step_miss(accelerations[1:] + BIAS, F.T),
          })
    mc = _monte_carlo()
    error = np.abs(mc.bias_estimates[:, -1] - BIAS)
    std = mc.bias_stds[0]
    fraction = float(np.mean(error <= 2 * std[-1]))
    judge("inside", inside, fraction, MATRIX_RTOL,
          what="the fraction of runs inside ±2σ at 10 s, recomputed",
          mistakes={
              "it is the ±1σ band; the task asks for ±2σ": float(np.mean(error <= std[-1])),
              "it is a percentage; the task asks for the fraction (between 0 and 1)":
                  100 * fraction,
              "it compares with 2σ² (twice the variance) where 2σ belongs":
                  float(np.mean(error <= 2 * std[-1] ** 2)),
          })
    rms = float(np.sqrt(np.mean(error**2)))
    judge("final_std", final_std, std[-1], MATRIX_RTOL, unit="cm/s²",
          what="the filter's σ of b̂ at 10 s, recomputed",
          mistakes={
              "it is the variance; the filter's σ is its square root": std[-1] ** 2,
              "it is the RMS error over the runs; the task asks for the filter's own σ "
              "(mc.bias_stds)": rms,
              "it is 2σ; the task asks for σ": 2 * std[-1],
          })
    n, burn = DEFAULT.n_steps, DEFAULT.burn_in_steps
    judge("ideal", ideal, SIGMA_A / np.sqrt(n), MATRIX_RTOL, unit="cm/s²",
          what="σ_a/√n recomputed",
          mistakes={
              "it is σ_a/n; averaging n readings divides σ by √n": SIGMA_A / n,
              "it is σ_a²/n, the variance of the mean; its σ is σ_a/√n": SIGMA_A**2 / n,
              f"it counts the readings after the burn-in only ({n - burn}); the filter uses "
              f"all {n}": SIGMA_A / np.sqrt(n - burn),
          })
    passed(f"miss, inside, final_std and ideal match the true path, the {DEFAULT.mc_runs} "
           f"runs of the pack's bias model and σ_a/√n recomputed (to "
           f"{tolerance_text(MATRIX_RTOL)} relative; the miss to {tolerance_text(MSE_RTOL)})")


# ------------------------------------------------------------------------------------------
# B · dead reckoning
# ------------------------------------------------------------------------------------------

#: The keys of Task B's ``rms``.
DRIFT_KEYS = ("ignored", "known", "filter")


def check_dead_reckoning(rms: Mapping[str, np.ndarray]) -> None:
    """Check Task B: RMS position error over the runs against time, three observers.

    Recomputed from the notebook's runs (:func:`lqe_helpers.bias_model.track_with_input`,
    ``DEFAULT.mc_runs`` runs): dead reckoning that ignores the bias, dead reckoning that
    subtracts the true bias (:func:`lqe_helpers.bias_model.dead_reckoning`), and the
    filter with vision; each the root of the mean over runs of the squared position
    error, shape (n,), within :data:`MATRIX_RTOL` relative (cm).

    Parameters
    ----------
    rms : dict of str to ndarray, shape (n,)
        Keyed "ignored", "known" and "filter".

    Raises
    ------
    CheckFailed
        With the likely cause: no square root, the mean error, the bias added instead
        of subtracted, the RMS over time instead of over the runs, ...
    """
    curves = keyed_entries(rms, "rms", DRIFT_KEYS, "RMS errors (cm, shape (n,))")
    mc = _monte_carlo()
    truth = mc.truth[:, 0]
    start = bias_model.initial_state(DEFAULT, BIAS)

    def known(estimate: float) -> np.ndarray:
        return bias_model.dead_reckoning(mc.readings, start, DEFAULT.dt,
                                         bias_estimate=estimate)[..., 0]

    positions = {"ignored": mc.dead_reckoning[..., 0], "known": known(BIAS),
                 "filter": mc.positions}
    for key in DRIFT_KEYS:
        error = positions[key] - truth
        mistakes = {
            "it is the mean squared error; the RMS is its square root":
                np.mean(error**2, axis=0),
            "it is the mean error over the runs, not squared: the RMS squares each error, "
            "averages over the runs, then takes the root": np.mean(error, axis=0),
            "it is the mean absolute error; the RMS squares, averages, then roots":
                np.mean(np.abs(error), axis=0),
        }
        if key == "known":
            mistakes["the bias was added, not subtracted: bias_estimate is the b̂ that dead "
                     "reckoning removes from each reading, here b itself"] = np.sqrt(
                np.mean((known(-BIAS) - truth) ** 2, axis=0))
        value = curves[key]
        if np.shape(value) == (DEFAULT.mc_runs,):
            raise CheckFailed(f"rms[{key!r}] has one value per run: average over the runs "
                              f"(axis 0), one value per sample, shape ({DEFAULT.n_steps},)")
        judge(f"rms[{key!r}]", value, np.sqrt(np.mean(error**2, axis=0)), MATRIX_RTOL,
              unit="cm", what="the RMS error over the runs recomputed", mistakes=mistakes)
    passed(f"the three RMS error curves match the pack's bias model and dead reckoning over "
           f"{DEFAULT.mc_runs} runs, to {tolerance_text(MATRIX_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# C · σ_a, the size of the bias, and σ_v
# ------------------------------------------------------------------------------------------

def sigma_a_grid() -> np.ndarray:
    """Task C's σ_a (13,): log-spaced from 1 to 1000 cm/s²."""
    return np.geomspace(1.0, 1000.0, 13)


#: The entries of Task C's σ_a sweep that :func:`check_sigma_a_sweep` recomputes: every
#: third, both ends included (a sweep is one loop, so a slip shows in every entry).
SWEEP_CHECKED = (0, 3, 6, 9, 12)


@remembered
def _noise() -> np.ndarray:
    """The notebook's draw of ``[vision, acceleration]`` noise for its Monte Carlo runs."""
    noise = bias_model.unit_noise(DEFAULT, DEFAULT.mc_runs)
    noise.setflags(write=False)
    return noise


@remembered
def _sweep() -> dict[str, object]:
    """Task C's σ_a sweep recomputed at :data:`SWEEP_CHECKED`, with the usual wrong variants."""
    vision = _vision_only()
    truth = DEFAULT.truth[:, 0]
    found: dict[str, list] = {key: [] for key in (
        "mse", "paired", "rms", "std", "paired_mistakes", "mse_mistakes", "rms_mistakes",
        "std_mistakes")}
    for value in sigma_a_grid()[list(SWEEP_CHECKED)]:
        batch = bias_model.track_with_input(DEFAULT, bias=BIAS, sigma_a=float(value),
                                            runs=DEFAULT.mc_runs, noise=_noise())
        mse = batch.mse()
        error = batch.bias_estimates[:, -1] - BIAS
        std = batch.bias_stds[0, -1]
        found["mse"].append(metrics.mean_ci95(mse))
        found["paired"].append(metrics.mean_ci95(vision - mse))
        found["rms"].append(float(np.sqrt(np.mean(error**2))))
        found["std"].append(float(std))
        found["mse_mistakes"].append({
            "the MSE of the whole trial: leave out the burn-in": metrics.mean_ci95(
                metrics.mse(batch.positions, truth)),
            "it is dead reckoning's MSE, not the filter's": metrics.mean_ci95(
                batch.dead_reckoning_mse())})
        found["paired_mistakes"].append(interval_mistakes(vision, mse, "the vision-only MSE",
                                                          "the MSE with the signal"))
        found["rms_mistakes"].append({
            "it is the mean squared error of b̂; the RMS is its square root":
                float(np.mean(error**2)),
            "it is the mean error of b̂, not squared": float(np.mean(error)),
            "it is the filter's own σ of b̂, not the RMS error over the runs": float(std)})
        found["std_mistakes"].append({
            "it is the variance of b̂; the filter's σ is its square root": float(std**2),
            "it is the RMS error over the runs, not the filter's own σ (bias_stds)":
                float(np.sqrt(np.mean(error**2)))})
    return found


def check_sigma_a_sweep(sweep_mse: Sequence[metrics.Interval],
                        sweep_paired: Sequence[metrics.Interval], sweep_rms: np.ndarray,
                        sweep_std: np.ndarray) -> None:
    """Check Task C's sweep of σ_a over the 13 values of :func:`sigma_a_grid`.

    Recomputed at every third σ_a, both ends included (:data:`SWEEP_CHECKED`), with
    :func:`lqe_helpers.bias_model.track_with_input` (``DEFAULT.mc_runs`` runs, the default
    bias) and the vision-only runs: the MSE interval, the
    paired interval vision only − with the signal (positive: the signal helps; each within
    :data:`INTERVAL_RTOL` of the interval's scale), the RMS error of b̂ at 10 s over the
    runs and the filter's σ of b̂ at 10 s (within :data:`MATRIX_RTOL` relative, cm/s²).

    Raises
    ------
    CheckFailed
        With the likely cause, naming the σ_a: the difference the wrong way round or
        unpaired, dead reckoning's MSE, the whole trial; the RMS without its root or the
        mean error, the variance for σ, the RMS and σ swapped, ...
    """
    right = _sweep()
    grid = sigma_a_grid()
    mses = interval_list(sweep_mse, "sweep_mse", "σ_a of sigma_a_grid", grid.size)
    paired = interval_list(sweep_paired, "sweep_paired", "σ_a of sigma_a_grid", grid.size)
    arrays = {name: shaped_argument(value, name, (grid.size,), "one value per σ_a (cm/s²)")
              for name, value in (("sweep_rms", sweep_rms), ("sweep_std", sweep_std))}
    for j, i in enumerate(SWEEP_CHECKED):
        where = f"[{i}] (σ_a = {grid[i]:.3g} cm/s²)"
        judge_interval(f"sweep_mse{where}", mses[i], right["mse"][j], INTERVAL_RTOL,
                       unit="cm²", what="the MSE with the signal, recomputed",
                       mistakes=right["mse_mistakes"][j])
        judge_interval(f"sweep_paired{where}", paired[i], right["paired"][j], INTERVAL_RTOL,
                       unit="cm²", what="the paired difference vision only − with the signal, "
                            "recomputed",
                       mistakes=right["paired_mistakes"][j])
        for name, key in (("sweep_rms", "rms"), ("sweep_std", "std")):
            judge(f"{name}{where}", arrays[name][i], right[key][j], MATRIX_RTOL,
                  unit="cm/s²", what="the value recomputed for this σ_a",
                  mistakes=right[f"{key}_mistakes"][j])
    shown = ", ".join(f"{grid[i]:.4g}" for i in SWEEP_CHECKED)
    passed(f"the sweep of σ_a (MSE and paired intervals, RMS error and filter σ of b̂ at "
           f"10 s) matches the pack's bias model on the task's draws at σ_a = {shown} cm/s² "
           f"(intervals to {tolerance_text(INTERVAL_RTOL)}, the rest to "
           f"{tolerance_text(MATRIX_RTOL)} relative)")


#: Task C's other true biases (cm/s²) and vision noises (cm).
OTHER_BIASES = (-60.0, 0.0, 60.0)
SIGMAS_V = (0.5, 1.5, 4.5)


@remembered
def _bias_and_vision() -> dict[str, dict]:
    """Task C's changes by bias (intervals, %) and by σ_v (%), with wrong variants."""
    unbiased = bias_model.unbiased_run(DEFAULT, SIGMA_A, runs=DEFAULT.mc_runs, noise=_noise())
    reference = unbiased.at_bias(BIAS).mse()
    scale = 100 / reference.mean()
    by_bias, bias_mistakes = {}, {}
    for b in OTHER_BIASES:
        mse = unbiased.at_bias(b).mse()
        by_bias[b] = metrics.mean_ci95(scale * (mse - reference))
        bias_mistakes[b] = {
            **interval_mistakes(scale * mse, scale * reference, f"the MSE at b = {b:g}",
                                f"the MSE at b = {BIAS:g}"),
            "it is in cm²; the task asks for the change in % of the MSE at the default bias":
                metrics.mean_ci95(mse - reference),
            "each run is divided by its own MSE at the default bias; divide by the mean":
                metrics.mean_ci95(100 * (mse - reference) / reference)}
    by_sigma, sigma_mistakes = {}, {}
    default_alone = _vision_only()
    for s in SIGMAS_V:
        with_signal = bias_model.track_with_input(DEFAULT, sigma_v=s, runs=DEFAULT.mc_runs,
                                                  noise=_noise()).mse()
        alone = experiments.track(DEFAULT, sigmas=[s], runs=DEFAULT.mc_runs,
                                  noise=_noise()[..., :1]).mse()
        gain = 100 * np.mean(alone - with_signal) / alone.mean()
        by_sigma[s] = float(gain)
        sigma_mistakes[s] = {
            f"the vision-only MSE is that of σ_v = {DEFAULT.sigma_v:g} cm for every σ_v; "
            f"compare with vision alone at the same σ_v":
                float(100 * np.mean(default_alone - with_signal) / default_alone.mean()),
            "it is in % of the MSE with the signal; the task asks for % of the vision-only "
            "MSE": float(100 * np.mean(alone - with_signal) / with_signal.mean()),
            "it is a fraction; the task asks for a percentage": float(gain / 100),
            "the sign is reversed: with the signal − vision only; the task asks for vision "
            "only − with the signal (positive when the signal helps)": float(-gain)}
    return {"bias": by_bias, "bias_mistakes": bias_mistakes, "sigma": by_sigma,
            "sigma_mistakes": sigma_mistakes}


def check_bias_and_vision(change_by_bias: Mapping[float, metrics.Interval],
                          gain_by_sigma_v: Mapping[float, float]) -> None:
    """Check Task C's effect of the bias's size and of vision's noise.

    Recomputed with :func:`lqe_helpers.bias_model.track_with_input` on the task's draws:
    for b = −60, 0 and 60 cm/s², the paired MSE change against the default bias in % of
    its mean MSE, with its 95 % interval (within :data:`INTERVAL_RTOL` of the interval's
    scale); for σ_v = 0.5, 1.5 and 4.5 cm, the mean paired gain vision only − with the
    signal in % of the vision-only MSE at the same σ_v (positive: the signal helps; within
    :data:`MATRIX_RTOL` relative).

    Raises
    ------
    CheckFailed
        With the likely cause: cm² instead of %, each run divided by its own MSE, the
        sign reversed; vision alone at the default σ_v for every σ_v, % of the wrong
        MSE, a fraction, ...
    """
    right = _bias_and_vision()
    biases = keyed_entries(change_by_bias, "change_by_bias", OTHER_BIASES,
                           "paired changes (metrics.Interval, %)")
    for b in OTHER_BIASES:
        judge_interval(f"change_by_bias[{b:g}]", biases[b], right["bias"][b], INTERVAL_RTOL,
                       unit="%", what="the paired change against the default bias, recomputed",
                       mistakes=right["bias_mistakes"][b])
    sigmas = keyed_entries(gain_by_sigma_v, "gain_by_sigma_v", SIGMAS_V,
                           "gains in % (one number each)")
    for s in SIGMAS_V:
        judge(f"gain_by_sigma_v[{s:g}]", sigmas[s], right["sigma"][s], MATRIX_RTOL,
              unit="%", what="the gain vision only − with the signal at this σ_v, "
                             "recomputed",
              mistakes=right["sigma_mistakes"][s])
    passed(f"the changes by bias (intervals, to {tolerance_text(INTERVAL_RTOL)}) and the gains "
           f"by σ_v "
           f"(to {tolerance_text(MATRIX_RTOL)} relative) match the pack's bias model and the "
           f"vision-only filter on the task's draws")
