"""Checks of notebook 06: F, G and Q of the bias model; the worked answer passes, slips fail."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import bias_model, checks

# --- check_bias_model ------------------------------------------------------------------------

DT, SIGMA_A = 0.01, 20.0


def bias_matrices(*, mistake=""):
    F = bias_model.transition_matrix(DT).copy()
    G = bias_model.input_matrix(DT).copy()
    sigma = SIGMA_A if mistake != "sigma" else np.sqrt(SIGMA_A)
    if mistake == "bias added":
        F[:2, 2] *= -1
    if mistake == "G no half":
        G[0, 0] = DT**2
    if mistake == "G flat":
        G = G[:, 0]
        return F, G, sigma**2 * np.outer(G, G)
    Q = sigma**2 * G @ G.T
    if mistake == "Q identity":
        Q = SIGMA_A**2 * np.eye(3)
    if mistake == "Gt G":
        Q = sigma**2 * G.T @ G
    if mistake == "F transposed":
        F = F.T
    if mistake == "Q diagonal":
        Q = np.diag(np.diag(sigma**2 * G @ G.T))
    if mistake == "jerk Q":
        from lqe_helpers.scenario import DEFAULT
        Q = DEFAULT.Q
    return F, G, Q


def test_check_bias_model_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_bias_model, *bias_matrices(), DT, SIGMA_A)


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("bias added", "adds the bias"),
    ("G no half", "G[0] holds Δt²"),
    ("G flat", "make it a column"),
    ("sigma", "uses σ_a where its square belongs"),
    ("Q identity", "is not pushed through G"),
    ("Gt G", "Q has shape (1, 1), one number: it is built as Gᵀ G"),
    ("F transposed", "F is transposed"),
    ("jerk Q", "Q is notebook 00's jerk noise"),
    ("Q diagonal", "Q holds only the diagonal"),
])
def test_check_bias_model_names_each_typical_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_bias_model, *bias_matrices(mistake=mistake), DT, SIGMA_A)


def test_check_bias_model_names_a_bad_argument():
    F, G, Q = bias_matrices()
    assert_fails("F must be the transition matrix, an array of shape (3, 3), got None",
                 checks.check_bias_model, None, G, Q, DT, SIGMA_A)
    assert_fails("dt must be a number > 0 s, got NaN", checks.check_bias_model, F, G, Q,
                 np.nan, SIGMA_A)
    assert_fails("Q must be the process noise covariance, an array of shape (3, 3), got values "
                 "too large to square", checks.check_bias_model, F, G, Q * 1e300, DT, SIGMA_A)


# --- check_signal_worth (Task 2) ------------------------------------------------------------

def signal_worth(*, mistake=""):
    """improvement of Task 2 (vision only − with the signal), as a student writes it, with
    one slip at most."""
    from lqe_helpers import experiments, metrics
    from lqe_helpers.scenario import DEFAULT

    mc = bias_model.track_with_input(DEFAULT, runs=DEFAULT.mc_runs)
    vision_only = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    with_signal = mc.dead_reckoning_mse() if mistake == "dead reckoning" else mc.mse()
    alone = vision_only.mse()
    if mistake == "reversed":  # the old convention: with − without
        return metrics.mean_ci95(with_signal - alone)
    if mistake == "percent":
        return metrics.mean_ci95(100 * (alone - with_signal) / alone.mean())
    if mistake == "whole trial":
        truth = DEFAULT.truth[:, 0]
        return metrics.mean_ci95(metrics.mse(vision_only.positions, truth)
                                 - metrics.mse(mc.positions, truth))
    if mistake == "one vision run":
        return metrics.mean_ci95(float(experiments.track(DEFAULT).mse()) - with_signal)
    if mistake == "percent reversed":
        return metrics.mean_ci95(100 * (with_signal - alone) / alone.mean())
    if mistake == "per-run relative":
        return metrics.mean_ci95((alone - with_signal) / alone)
    if mistake == "ratio":
        return metrics.mean_ci95(alone / with_signal)
    if mistake == "mean vision":
        return metrics.mean_ci95(alone.mean() - with_signal)
    if mistake == "mean signal":
        return metrics.mean_ci95(alone - with_signal.mean())
    if mistake == "percent per run":
        return metrics.mean_ci95(100 * (alone - with_signal) / alone)
    if mistake == "percent of the signal's":
        return metrics.mean_ci95(100 * (alone - with_signal) / with_signal)
    if mistake == "rmse":
        return metrics.mean_ci95(np.sqrt(alone) - np.sqrt(with_signal))
    if mistake == "root":
        right = metrics.mean_ci95(alone - with_signal)
        return metrics.Interval(np.sqrt(right.mean), np.sqrt(right.low), np.sqrt(right.high),
                                right.runs)
    if mistake in ("burn-in + 1", "burn-in - 1"):
        truth = DEFAULT.truth[:, 0]
        start = DEFAULT.burn_in_steps + (1 if mistake.endswith("+ 1") else -1)
        return metrics.mean_ci95(metrics.mse(vision_only.positions, truth, start)
                                 - metrics.mse(mc.positions, truth, start))
    if mistake == "shuffled":   # the runs out of their pairs
        return metrics.mean_ci95(np.random.default_rng(0).permutation(alone) - with_signal)
    if mistake == "another draw":
        other = experiments.track(dataclasses.replace(DEFAULT, seed=DEFAULT.seed + 1),
                                  runs=DEFAULT.mc_runs)
        return metrics.mean_ci95(other.mse() - with_signal)
    return metrics.mean_ci95(alone - with_signal)


def test_check_signal_worth_passes_the_worked_solution(capsys):
    line = assert_passes(capsys, checks.check_signal_worth, signal_worth())
    assert "300 runs" in line and "vision only − with the signal" in line


def test_the_signal_helps_so_the_improvement_is_positive():
    assert signal_worth().low > 0


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("reversed", "the sign is reversed: it is the MSE with the signal − the vision-only MSE"),
    ("percent", "it is in % of the vision-only MSE"),
    ("whole trial", "of the whole trial"),
    ("dead reckoning", "dead reckoning's MSE"),
    ("one vision run", "a single run"),
    ("percent reversed", "in % of the vision-only MSE and the wrong way round"),
    ("per-run relative", "divided by that run's vision-only MSE"),
    ("ratio", "it is a ratio of the MSEs"),
    ("mean vision", "one side is the mean MSE over the runs"),
    ("mean signal", "the other the mean MSE over the runs"),
    ("percent per run", "is not right: it is in % of each run's vision-only MSE"),
    ("percent of the signal's", "is not right: it is in % of each run's MSE with the signal"),
    ("rmse", "is not right: it is the difference of the root mean squared errors (√MSE"),
    ("root", "is not right: it is the square root of the interval of the MSE difference"),
    ("burn-in + 1", "is not right: it leaves out one sample too many (101 instead of 100)"),
    ("burn-in - 1", "is not right: it leaves out one sample too few (99 instead of 100)"),
    ("shuffled", "is not right: its runs are not paired: the mean is right, but its width is "
                 "that of two independent samples"),
    # Here pairing narrows the interval little, so another draw is asked about, not asserted.
    ("another draw", "and not by one of the usual mistakes: its mean and width are what "
                     "another noise draw would give"),
])
@pytest.mark.slow
def test_check_signal_worth_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_signal_worth, signal_worth(mistake=mistake))


def test_check_signal_worth_wants_the_interval():
    interval = signal_worth()
    assert_fails("it must be the metrics.Interval", checks.check_signal_worth, interval.mean)
