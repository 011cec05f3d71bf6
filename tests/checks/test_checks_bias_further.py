"""Checks of notebook 06's Going further: worked answers pass, realistic slips fail saying why.

Each task is written here as the notebook's worked solution, with one slip a student
could make (a ``mistake`` keyword), independently of the mistakes
:mod:`lqe_helpers.checks.bias_further` computes to recognise them.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import bias_model, checks, experiments, metrics
from lqe_helpers.scenario import DEFAULT

DT, B_TRUE, SIGMA_A = DEFAULT.dt, bias_model.DEFAULT_BIAS, bias_model.DEFAULT_SIGMA_A
F, G = bias_model.transition_matrix(DT), bias_model.input_matrix(DT)


@functools.cache
def mc():
    return bias_model.track_with_input(DEFAULT, bias=B_TRUE, sigma_a=SIGMA_A,
                                       runs=DEFAULT.mc_runs)


@functools.cache
def vision_only():
    return experiments.track(DEFAULT, runs=DEFAULT.mc_runs)


# --- A · check_bias_precision ----------------------------------------------------------------

def precision(*, mistake=""):
    accelerations = bias_model.step_accelerations(DEFAULT)
    states = bias_model.true_states(DEFAULT, B_TRUE)
    readings = {"step before": accelerations[:-1] + B_TRUE,
                "no bias": accelerations[1:]}.get(mistake, accelerations[1:] + B_TRUE)
    one_step = states[:-1] @ F.T + readings[:, None] * G[:, 0]
    miss = np.abs(states[1:] - one_step).max(axis=0)
    std = mc().bias_stds[0]
    band = std[-1] if mistake == "one sigma" else 2 * std[-1]
    inside = np.mean(np.abs(mc().bias_estimates[:, -1] - B_TRUE) <= band)
    if mistake == "percent":
        inside = 100 * inside
    final_std = std[-1] ** 2 if mistake == "variance" else std[-1]
    n = DEFAULT.n_steps
    ideal = {"over n": SIGMA_A / n, "after burn-in": SIGMA_A / np.sqrt(n - DEFAULT.burn_in_steps)
             }.get(mistake, SIGMA_A / np.sqrt(n))
    return miss, inside, final_std, ideal


def test_check_bias_precision_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_bias_precision, *precision())


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("step before", "the reading of the step before"),
    ("no bias", "the reading has no bias"),
    ("one sigma", "it is the ±1σ band"),
    ("percent", "it is a percentage"),
    ("variance", "it is the variance"),
    ("over n", "it is σ_a/n"),
    ("after burn-in", "after the burn-in only"),
])
def test_check_bias_precision_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_bias_precision, *precision(mistake=mistake))


# --- B · check_dead_reckoning ----------------------------------------------------------------

def drift(*, mistake=""):
    truth = mc().truth[:, 0]
    estimate = -B_TRUE if mistake == "bias added" else B_TRUE
    known = bias_model.dead_reckoning(mc().readings, bias_model.initial_state(DEFAULT, B_TRUE),
                                      DT, bias_estimate=estimate)
    positions = {"ignored": mc().dead_reckoning[..., 0], "known": known[..., 0],
                 "filter": mc().positions}
    if mistake == "no root":
        return {k: np.mean((v - truth) ** 2, axis=0) for k, v in positions.items()}
    if mistake == "over time":
        return {k: np.sqrt(np.mean((v - truth) ** 2, axis=-1)) for k, v in positions.items()}
    if mistake == "mean error":
        return {k: np.mean(v - truth, axis=0) for k, v in positions.items()}
    return {k: np.sqrt(np.mean((v - truth) ** 2, axis=0)) for k, v in positions.items()}


def test_check_dead_reckoning_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_dead_reckoning, drift())


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("no root", "it is the mean squared error"),
    ("over time", "has one value per run"),
    ("mean error", "it is the mean error over the runs"),
    ("bias added", "the bias was added, not subtracted"),
])
def test_check_dead_reckoning_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_dead_reckoning, drift(mistake=mistake))


def test_check_dead_reckoning_wants_the_three_keys():
    curves = drift()
    curves["bias ignored"] = curves.pop("ignored")
    assert_fails("has no entry 'ignored'", checks.check_dead_reckoning, curves)


# --- C · check_sigma_a_sweep -----------------------------------------------------------------

@functools.cache
def sigma_a_sweep(mistake=""):
    grid = np.geomspace(1.0, 1000.0, 13)
    sweep_mse, sweep_paired, sweep_rms, sweep_std = [], [], [], []
    alone = vision_only().mse()
    for value in grid:
        batch = bias_model.track_with_input(DEFAULT, bias=B_TRUE, sigma_a=value,
                                            runs=DEFAULT.mc_runs)
        sweep_mse.append(metrics.mean_ci95(batch.mse()))
        # vision only − with the signal (positive: the signal helps); reversed: the other way
        difference = batch.mse() - alone if mistake == "reversed" else alone - batch.mse()
        sweep_paired.append(metrics.mean_ci95(difference))
        error = batch.bias_estimates[:, -1] - B_TRUE
        sweep_rms.append(np.mean(error**2) if mistake == "no root" else np.sqrt(np.mean(error**2)))
        std = batch.bias_stds[0, -1]
        sweep_std.append(std**2 if mistake == "variance" else std)
    sweep_rms, sweep_std = np.array(sweep_rms), np.array(sweep_std)
    if mistake == "swapped":
        sweep_rms, sweep_std = sweep_std, sweep_rms
    return sweep_mse, sweep_paired, sweep_rms, sweep_std


@pytest.mark.slow
def test_check_sigma_a_sweep_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_sigma_a_sweep, *sigma_a_sweep())


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("reversed", "the sign is reversed: it is the MSE with the signal − the vision-only MSE"),
    ("no root", "the RMS is its square root"),
    ("variance", "it is the variance of b̂"),
    ("swapped", "it is the filter's own σ of b̂, not the RMS error"),
])
@pytest.mark.slow
def test_check_sigma_a_sweep_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_sigma_a_sweep, *sigma_a_sweep(mistake))


def test_check_sigma_a_sweep_wants_one_interval_per_sigma_a():
    sweep_mse, sweep_paired, sweep_rms, sweep_std = sigma_a_sweep()
    assert_fails("must be a list of 13 metrics.Interval", checks.check_sigma_a_sweep,
                 sweep_mse[:12], sweep_paired, sweep_rms, sweep_std)


# --- C · check_bias_and_vision ---------------------------------------------------------------

@functools.cache
def bias_and_vision(mistake=""):
    by_bias = {b: bias_model.track_with_input(DEFAULT, bias=b, runs=DEFAULT.mc_runs)
               for b in (-60.0, 0.0, 20.0, 60.0)}
    reference = by_bias[B_TRUE].mse()
    change_by_bias = {}
    for b, batch in by_bias.items():
        if b == B_TRUE:
            continue
        scale = 100 / (reference if mistake == "own MSE" else reference.mean())
        change_by_bias[b] = metrics.mean_ci95(
            (batch.mse() - reference) if mistake == "cm²" else scale * (batch.mse() - reference))
    gain_by_sigma_v = {}
    for s in (0.5, 1.5, 4.5):
        with_signal = bias_model.track_with_input(DEFAULT, sigma_v=s, runs=DEFAULT.mc_runs).mse()
        alone = vision_only().mse() if mistake == "default sigma_v" else experiments.track(
            DEFAULT, sigmas=[s], runs=DEFAULT.mc_runs).mse()
        base = with_signal if mistake == "wrong base" else alone
        gain = alone - with_signal if mistake != "reversed" else with_signal - alone
        gain_by_sigma_v[s] = 100 * np.mean(gain) / base.mean()
    return change_by_bias, gain_by_sigma_v


@pytest.mark.slow
def test_check_bias_and_vision_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_bias_and_vision, *bias_and_vision())


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("own MSE", "each run is divided by its own MSE"),
    ("cm²", "it is in cm²"),
    ("default sigma_v", "compare with vision alone at the same σ_v"),
    ("wrong base", "in % of the MSE with the signal"),
    ("reversed", "the sign is reversed: with the signal − vision only"),
])
@pytest.mark.slow
def test_check_bias_and_vision_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_bias_and_vision, *bias_and_vision(mistake))
