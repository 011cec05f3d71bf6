"""Checks of notebook 00's Going further: worked answers pass, realistic slips fail saying why.

Each task is written here as the notebook's worked solution, with one slip a student
could make (a ``mistake`` keyword), independently of the mistakes
:mod:`lqe_helpers.checks.background_further` computes to recognise them.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, experiments, jerk_tuning, metrics, model
from lqe_helpers.checks import background_further, background_jerk_choice
from lqe_helpers.prediction import propagate_covariance
from lqe_helpers.scenario import DEFAULT

DT, TRUTH, SIGMA_J = DEFAULT.dt, DEFAULT.truth, DEFAULT.process_jerk_std
A = model.transition_matrix(DT)


# --- A · check_one_step_error ----------------------------------------------------------------

def one_step(*, mistake=""):
    moved = TRUTH[:-1] @ (A if mistake == "A not transposed" else A.T)
    residual = (TRUTH[:-1] if mistake == "same sample" else TRUTH[1:]) - moved
    max_error = np.abs(residual).mean(axis=0) if mistake == "mean" else \
        np.abs(residual).max(axis=0)
    omega = 2 * np.pi * DEFAULT.frequency
    jerk = DEFAULT.amplitude * omega ** (2 if mistake == "acceleration" else 3)
    terms = np.array([DT**3, DT**2, DT]) if mistake == "no factorials" else \
        np.array([DT**3 / 6, DT**2 / 2, DT])
    allowed = np.diag(DEFAULT.Q) if mistake == "variances" else np.sqrt(np.diag(DEFAULT.Q))
    return max_error, jerk * terms, allowed


def test_check_one_step_error_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_one_step_error, *one_step())


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("A not transposed", "A is applied transposed"),
    ("same sample", "compare with the next true state"),
    ("mean", "it is the mean absolute error"),
    ("acceleration", "the dropped term is the jerk's"),
    ("no factorials", "the factorials are missing"),
    ("variances", "Q's diagonal, the variances"),
])
def test_check_one_step_error_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_one_step_error, *one_step(mistake=mistake))


def test_check_one_step_error_wants_three_numbers_each():
    max_error, dropped, allowed = one_step()
    assert_fails("max_error must be the largest miss of p, v, a, an array of shape (3,)",
                 checks.check_one_step_error, max_error[:2], dropped, allowed)


# --- B · check_uncertainty_growth ------------------------------------------------------------

def growth(*, mistake=""):
    def two_sigma(P_start, Q):
        variances = propagate_covariance(P_start, A, Q, 100)[:, 0, 0]
        variances = variances if mistake == "start kept" else variances[1:]
        return np.sqrt(variances) if mistake == "one sigma" else 2 * np.sqrt(variances)

    from_zero = {}
    for factor in (0.1, 1, 10):
        Q = factor * DEFAULT.Q if mistake == "factor on Q" else \
            model.process_noise_covariance(DT, factor * SIGMA_J)
        from_zero[factor] = two_sigma(np.zeros((3, 3)), Q)
    steady = experiments.filter_model(DEFAULT).steady_state()
    start = steady.covariance if mistake == "prediction covariance" else \
        steady.estimate_covariance
    return from_zero, two_sigma(start, DEFAULT.Q)


def test_check_uncertainty_growth_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_uncertainty_growth, *growth())


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("one sigma", "it is σ, not 2σ"),
    ("start kept", "leave out the start"),
    ("factor on Q", "the factor multiplies Q, not σ_j"),
    ("prediction covariance", "prediction covariance"),
])
def test_check_uncertainty_growth_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_uncertainty_growth, *growth(mistake=mistake))


def test_check_uncertainty_growth_wants_the_three_factors():
    from_zero, from_settled = growth()
    del from_zero[10]
    assert_fails("has no entry 10.0", checks.check_uncertainty_growth, from_zero, from_settled)


# --- C · check_jerk_sweep, check_jerk_sweep_reading -----------------------------------------------

@functools.cache
def sweep(mistake=""):
    """The worked sweep of Task C (one slip at most), as NumPy arrays."""
    grid = np.sort(np.append(np.geomspace(10.0, 1.0e5, 25), SIGMA_J))
    zero_noise = np.zeros((DEFAULT.n_steps, 1))
    burn = DEFAULT.burn_in_steps
    runs, systematic, noise_part, expected = [], [], [], []
    for value in grid:
        variant = dataclasses.replace(DEFAULT, jerk_std=value)
        batch = experiments.track(variant, runs=DEFAULT.mc_runs)
        clean = experiments.track(variant, noise=zero_noise)
        runs.append(metrics.mse(batch.positions, TRUTH[:, 0]) if mistake == "whole trial"
                    else batch.mse())
        systematic.append(float(clean.mse()))
        noise_part.append(float(np.mean(metrics.mse(batch.positions - clean.positions,
                                                    np.zeros(DEFAULT.n_steps), burn))))
        steady = experiments.filter_model(variant).steady_state()
        expected.append((steady.covariance if mistake == "prediction" else
                         steady.estimate_covariance)[0, 0])
    runs = np.stack(runs, axis=1)
    noise_part = np.array(noise_part)
    if mistake == "difference":
        noise_part = runs.mean(axis=0) - np.array(systematic)
    return grid, runs, np.array(systematic), noise_part, np.array(expected)


@pytest.mark.slow
def test_check_jerk_sweep_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_jerk_sweep, *sweep()[1:])


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("whole trial", "of the whole trial"),
    ("prediction", "it is the prediction's variance"),
    ("difference", "it is the mean MSE minus the systematic MSE"),
])
@pytest.mark.slow
def test_check_jerk_sweep_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_jerk_sweep, *sweep(mistake)[1:])


def test_check_jerk_sweep_names_swapped_axes_and_lists():
    _, runs, systematic, noise_part, expected = sweep()
    assert_fails("one row per run and one column per σ_j", checks.check_jerk_sweep, runs.T,
                 systematic, noise_part, expected)
    assert_fails("a Python list, not a NumPy array", checks.check_jerk_sweep, runs,
                 list(systematic), noise_part, expected)


def reading(*, mistake=""):
    grid, runs, _, _, expected = sweep()
    mean = runs.mean(axis=0)
    inside = mean <= (mean.min() + 0.1 if mistake == "absolute" else 1.1 * mean.min())
    near = np.array([grid[inside].min(), grid[inside].max()])
    if mistake == "MSEs":
        near = np.array([mean[grid == near[0]][0], mean[grid == near[1]][0]])
    gap = np.log(expected) - np.log(mean)
    i = int(np.flatnonzero(np.diff(np.sign(gap)))[0])
    fraction = gap[i] / (gap[i] - gap[i + 1])
    crossing = grid[i] * (grid[i + 1] / grid[i]) ** fraction
    if mistake == "grid value":
        crossing = grid[i]
    if mistake == "linear":
        difference = expected - mean
        crossing = grid[i] + difference[i] / (difference[i] - difference[i + 1]) * (
            grid[i + 1] - grid[i])
    return near, crossing


def test_check_jerk_sweep_reading_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_jerk_sweep_reading, *reading())


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("absolute", "a margin of 0.1 cm²"),
    ("MSEs", "it holds MSEs"),
    ("grid value", "the grid value just before the crossing"),
    ("linear", "interpolates the difference linearly in σ_j"),
])
def test_check_jerk_sweep_reading_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_jerk_sweep_reading, *reading(mistake=mistake))


# --- D · check_white_jerk --------------------------------------------------------------------

@functools.cache
def white(mistake=""):
    M = 1000
    h = DT / M
    sigma = SIGMA_J if mistake == "no root M" else SIGMA_J * np.sqrt(M)
    Q_white = propagate_covariance(np.zeros((3, 3)), model.transition_matrix(h),
                                   model.process_noise_covariance(h, sigma), M)[-1]
    runs = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    held = runs.mse()
    estimates = dataclasses.replace(runs.model, Q=Q_white).filter(runs.measurements).estimates
    white_mse = metrics.mse(estimates[..., 0], TRUTH[:, 0], DEFAULT.burn_in_steps)
    scale = 100 / (held if mistake == "own MSE" else held.mean())
    difference = held - white_mse if mistake == "reversed" else white_mse - held
    return Q_white, metrics.mean_ci95(scale * difference)


def test_white_jerk_q_is_the_continuous_white_jerk_limit():
    """The direct sum tends to the textbook Q of white jerk, q Δt⁵/20, …, q Δt (q = σ_j² Δt)."""
    q, dt = SIGMA_J**2 * DT, DT
    limit = q * np.array([[dt**5 / 20, dt**4 / 8, dt**3 / 6], [dt**4 / 8, dt**3 / 3, dt**2 / 2],
                          [dt**3 / 6, dt**2 / 2, dt]])
    np.testing.assert_allclose(background_further.white_jerk_q(SIGMA_J, DT, 1000), limit,
                               rtol=1e-5)
    np.testing.assert_allclose(background_further.white_jerk_q(SIGMA_J, DT, 1), DEFAULT.Q,
                               rtol=1e-12)


def test_check_white_jerk_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_white_jerk, *white())


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("no root M", "needs σ_j √M"),
    ("own MSE", "each run is divided by its own held-jerk MSE"),
    ("reversed", "the sign is reversed"),
])
def test_check_white_jerk_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_white_jerk, *white(mistake))


# --- E · check_jerk_from_readings ------------------------------------------------------------

@functools.cache
def choice():
    return jerk_tuning.tune_jerk_std(DEFAULT, np.geomspace(700.0, 2800.0, 17))


def from_readings(*, mistake=""):
    innovations = experiments.track(DEFAULT, runs=DEFAULT.mc_runs).innovations()
    nu, S = innovations.values[..., 0], innovations.covariances[..., 0, 0]
    burn = 0 if mistake == "burn-in kept" else DEFAULT.burn_in_steps
    denominator = {"sqrt S": np.sqrt(S), "R only": DEFAULT.sigma_v**2}.get(mistake, S)
    nis_mean = float(np.mean((nu**2 / denominator)[:, burn:]))
    picked = choice()
    chosen = {"likelihood": picked.by_likelihood, "NIS": picked.by_nis, "MSE": picked.by_mse}
    if mistake == "swapped":
        chosen["likelihood"], chosen["MSE"] = chosen["MSE"], chosen["likelihood"]
    return nis_mean, chosen


@pytest.mark.slow
def test_check_jerk_from_readings_passes_the_worked_solution(capsys):
    line = assert_passes(capsys, checks.check_jerk_from_readings, *from_readings())
    assert "300 runs" in line


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("burn-in kept", "it includes the burn-in"),
    ("sqrt S", "divided by its standard deviation √S"),
    ("R only", "the sensor's variance σ_v² alone"),
    ("swapped", "it is the σ_j chosen by MSE, not by likelihood"),
])
@pytest.mark.slow
def test_check_jerk_from_readings_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_jerk_from_readings, *from_readings(mistake=mistake))


def test_the_checks_recomputation_agrees_with_jerk_tuning():
    """The check judges against jerk_tuning on the notebook's grid (700–2 800 cm/s³, 17 values).

    The check calls jerk_tuning.tune_jerk_std on its choice_grid(); this fails if that grid
    drifts from the notebook's. jerk_tuning itself is tested against metrics.nis_test and
    the Gaussian log-likelihood in test_jerk_tuning.py.
    """
    mine = background_jerk_choice._choice()["choice"]
    theirs = choice()
    np.testing.assert_allclose(mine.nis_mean, theirs.nis_mean, rtol=1e-10)
    np.testing.assert_allclose(mine.log_likelihood, theirs.log_likelihood, rtol=1e-10)
    np.testing.assert_allclose(mine.mse, theirs.mse, rtol=1e-12)
