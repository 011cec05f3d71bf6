"""Checks of notebook 01's Going further: worked answers pass, a student's slips fail saying why.

Each task is written here as a student writes it (the notebook's worked code), with one
slip at a time, independently of the mistakes :mod:`lqe_helpers.checks` computes to
recognise them. Holds worked answers: never shipped to students.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, experiments, metrics, smoothing
from lqe_helpers.checks import CheckFailed
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.steady_state import steady_state
from lqe_helpers.student_code import calling

TIMES, TRUTH, BURN = DEFAULT.times, DEFAULT.truth[:, 0], DEFAULT.burn_in_steps
C = np.array([[1.0, 0.0, 0.0]])
Z0 = np.zeros(3)
SIGMAS = (1.5, 4.5)
ALPHAS = np.linspace(0.02, 0.6, 30)


@pytest.fixture(scope="module")
def batch() -> experiments.Tracking:
    """Task 3's runs, as the notebook makes them."""
    return experiments.track(DEFAULT, sigmas=[[1.5], [4.5]], runs=DEFAULT.mc_runs)


# ------------------------------------------------------------------------------------------
# check_smoother
# ------------------------------------------------------------------------------------------


def smoother(y, alpha, slip: str = ""):
    """A student's exponential smoother, optionally with one slip."""
    y = np.asarray(y, dtype=float)
    alpha = np.asarray(alpha, dtype=float)
    if slip == "no broadcasting":
        s = np.zeros_like(y)
    else:
        s = np.zeros(np.broadcast_shapes(y.shape[:-1], alpha.shape) + y.shape[-1:])
    s[..., 0] = 0.0 if slip == "from zero" else y[..., 0]
    if slip == "from zero":
        s[..., 0] = alpha * y[..., 0]
    for j in range(1, y.shape[-1]):
        if slip == "wrong way":
            s[..., j] = alpha * s[..., j - 1] + (1 - alpha) * y[..., j]
        elif slip == "one late":
            s[..., j] = s[..., j - 1] + alpha * (y[..., j - 1] - s[..., j - 1])
        elif slip == "previous reading":
            s[..., j] = y[..., j - 1] + alpha * (y[..., j] - y[..., j - 1])
        elif slip == "looks ahead" and j + 1 < y.shape[-1]:
            s[..., j] = s[..., j - 1] + alpha * (y[..., j + 1] - s[..., j - 1])
        else:
            s[..., j] = s[..., j - 1] + alpha * (y[..., j] - s[..., j - 1])
    if slip == "centred":          # a smoother run forwards, then backwards (zero lag)
        back = s[..., ::-1].copy()
        for j in range(1, y.shape[-1]):
            back[..., j] = back[..., j - 1] + alpha * (back[..., j] - back[..., j - 1])
        return back[..., ::-1]
    if slip == "last value":
        return s[..., -1]
    return s


def test_check_smoother_passes_the_worked_answer(capsys) -> None:
    def my_smoother(y, alpha):
        return smoother(y, alpha)

    line = assert_passes(capsys, checks.check_smoother, my_smoother)
    assert "no output depends on a later reading" in line and "to 1e-9" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("wrong way", "the weight is applied the wrong way round"),
    ("from zero", "the smoother starts from 0 before the first reading"),
    ("one late", "each smoothed value is one step late"),
    ("previous reading", "uses the previous reading y_(j−1) where the previous smoothed value"),
    ("looks ahead", "my_smoother uses future readings: changing y at step 6 changed"),
    ("centred", "my_smoother uses future readings"),
    ("no broadcasting", "alpha broadcasts against the leading axes of y"),
    ("last value", "only the last smoothed value?"),
])
def test_check_smoother_names_each_typical_mistake(slip: str, phrase: str) -> None:
    def my_smoother(y, alpha):
        return smoother(y, alpha, slip)

    assert_fails(phrase, checks.check_smoother, my_smoother)


def test_check_smoother_wants_time_on_the_last_axis() -> None:
    def my_smoother(y, alpha):               # loops over the first axis
        y = np.asarray(y, dtype=float)
        s = np.zeros_like(y)
        s[0] = y[0]
        for j in range(1, len(y)):
            s[j] = s[j - 1] + alpha * (y[j] - s[j - 1])
        return s

    message = assert_fails("my_smoother ", checks.check_smoother, my_smoother)
    assert "time runs along the first axis" in message or "shape" in message, message


def test_check_smoother_refuses_the_packs_own_and_a_stub() -> None:
    assert_fails("exponential_smoother runs the pack's own "
                 "lqe_helpers.smoothing.exponential_smoother", checks.check_smoother,
                 smoothing.exponential_smoother)

    def my_smoother(y, alpha):
        return smoothing.exponential_smoother(y, alpha)

    assert_fails("my_smoother runs the pack's own lqe_helpers.smoothing.exponential_smoother",
                 checks.check_smoother, my_smoother)

    def my_smoother(y, alpha):
        raise NotImplementedError

    assert_fails("my_smoother is not written yet", checks.check_smoother, my_smoother)


def test_check_smoother_reports_a_smoother_that_changes_its_input() -> None:
    def my_smoother(y, alpha):
        for j in range(1, y.shape[-1]):
            y[..., j] = y[..., j - 1] + alpha * (y[..., j] - y[..., j - 1])
        return y

    assert_fails("changed its input y in place", checks.check_smoother, my_smoother)


def test_check_smoother_is_instant() -> None:
    start = time.monotonic()
    with pytest.raises(CheckFailed):
        checks.check_smoother(lambda y, alpha: smoother(y, alpha, "wrong way"))
    assert time.monotonic() - start < 1.0


def test_check_smoother_stops_an_endless_loop(monkeypatch) -> None:
    monkeypatch.setattr(calling, "TIME_LIMIT", 0.2)

    def my_smoother(y, alpha):
        j = 1
        while j < y.shape[-1]:
            pass
        return y

    assert_fails("my_smoother did not return within 0.2 s", checks.check_smoother, my_smoother)


# ------------------------------------------------------------------------------------------
# check_smoother_comparison
# ------------------------------------------------------------------------------------------


def comparison(batch, slip: str = "") -> tuple[dict, dict, np.ndarray]:
    """Part 1's tuning task as a student writes it, with one ``slip``."""
    mse_raw, mse_est = batch.measurement_mse("vision"), batch.mse()
    best_alpha, smoother_vs_lqe = {}, {}
    for i, sigma_v in enumerate(SIGMAS):
        smoothed = smoother(batch.measurements[:, i, None, :, 0], ALPHAS)      # (runs, g, n)
        burn = 0 if slip == "whole trial" else BURN
        mse_grid = metrics.mse(smoothed, TRUTH, burn)                           # (runs, g)
        if slip == "largest":
            best = np.argmax(mse_grid.mean(axis=0))
        else:
            best = np.argmin(mse_grid.mean(axis=0))
        best_alpha[sigma_v] = best if slip == "index" else ALPHAS[best]
        reference = mse_raw[:, i] if slip == "against raw" else mse_est[:, i]
        difference = mse_grid[:, best] - reference
        if slip == "reversed":
            difference = -difference
        if slip == "unpaired":
            a, b = metrics.mean_ci95(mse_grid[:, best]), metrics.mean_ci95(reference)
            smoother_vs_lqe[sigma_v] = metrics.Interval(
                a.mean - b.mean, a.low - b.high, a.high - b.low, a.runs)
        else:
            smoother_vs_lqe[sigma_v] = metrics.mean_ci95(difference)
    return best_alpha, smoother_vs_lqe, ALPHAS


@pytest.mark.slow
def test_check_smoother_comparison_passes_the_worked_answer(batch, capsys) -> None:
    line = assert_passes(capsys, checks.check_smoother_comparison, *comparison(batch))
    assert "paired difference smoother − LQE over 300 runs" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("largest", "best_alpha[1.5] = 0.02 is not right: it is the α with the largest mean MSE"),
    ("index", "best_alpha[1.5] = 16 is not right: it is the position of the best α"),
    ("whole trial", "smoother's MSEs are those of the whole trial: leave out the burn-in"),
    ("against raw", "smoother_vs_lqe[1.5] is not right: it compares the smoother with the raw"),
    ("reversed", "smoother_vs_lqe[1.5] is not right: the sign is reversed"),
    ("unpaired", "it combines the two separate intervals"),
])
@pytest.mark.slow
def test_check_smoother_comparison_names_the_cause(batch, slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_smoother_comparison, *comparison(batch, slip))


@pytest.mark.slow
def test_check_smoother_comparison_follows_the_grid_and_refuses_a_bad_one(batch) -> None:
    best_alpha, smoother_vs_lqe, _ = comparison(batch)
    # The right answer for one grid is wrong for another: the grid is the task's input.
    assert_fails("best_alpha[1.5] = 0.34 does not match", checks.check_smoother_comparison,
                 best_alpha, smoother_vs_lqe, np.linspace(0.05, 0.6, 12))
    assert_fails("alphas must be a vector of at least two weights α in (0, 1]",
                 checks.check_smoother_comparison, best_alpha, smoother_vs_lqe,
                 np.array([0.0, 0.5]))


# ------------------------------------------------------------------------------------------
# check_systematic_error
# ------------------------------------------------------------------------------------------


def split(batch, slip: str = "") -> tuple[dict, dict, dict, dict]:
    """Part 2's task as a student writes it (their filter is the engine here)."""
    amplitude, lead_ms, systematic, noise_part = {}, {}, {}, {}
    for i, s in enumerate(SIGMAS):
        clean = kalman_filter(TRUTH[:, None], DEFAULT.A, C, DEFAULT.Q, np.array([[s**2]]), Z0,
                              DEFAULT.P0).estimates[:, 0]
        start = 0 if slip == "fit whole trial" else BURN
        fitted = batch.positions[0, i] if slip == "fit noisy run" else clean
        fit = metrics.fit_sinusoid(TIMES[start:], fitted[start:], DEFAULT.frequency)
        amplitude[s] = fit.amplitude
        lead_ms[s] = fit.lead if slip == "seconds" else 1000 * fit.lead
        systematic[s] = np.mean((clean[BURN:] - TRUTH[BURN:]) ** 2)
        if slip == "rest of the MSE":
            noise_part[s] = batch.mse()[:, i].mean() - systematic[s]
        elif slip == "around the mean":
            noise_part[s] = np.mean(np.var(batch.positions[:, i, BURN:], axis=0))
        else:
            noise_part[s] = np.mean((batch.positions[:, i, BURN:] - clean[BURN:]) ** 2)
    return amplitude, lead_ms, systematic, noise_part


def test_check_systematic_error_passes_the_worked_answer(batch, capsys) -> None:
    assert_passes(capsys, checks.check_systematic_error, *split(batch))


@pytest.mark.parametrize(("slip", "phrase"), [
    ("fit whole trial", "amplitude[1.5] = 10.1854 cm is not right"),
    ("fit whole trial", "the sine is fitted to the whole trial"),
    ("fit noisy run", "the sine is fitted to a noisy run's estimate"),
    ("seconds", "lead_ms[1.5] = 0.00744212 ms is not right: it is in seconds"),
    ("rest of the MSE", "noise_part[1.5] = 0.337864 cm² is not right: it is the Monte Carlo MSE "
                        "minus the systematic part"),
    ("around the mean", "it is the spread of the runs around their own mean"),
])
def test_check_systematic_error_names_the_cause(batch, slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_systematic_error, *split(batch, slip))


def test_check_systematic_error_wants_every_dict() -> None:
    assert_fails("lead_ms must be a dict of leads (ms) keyed by σ_v (cm)",
                 checks.check_systematic_error, {1.5: 1, 4.5: 1}, 7.4, {}, {})


# ------------------------------------------------------------------------------------------
# check_steady_state
# ------------------------------------------------------------------------------------------


def confidence(batch, slip: str = "") -> tuple[dict, dict]:
    """Part 3's first task as a student writes it, with one ``slip``."""
    forecast, coverage = {}, {}
    for i, s in enumerate(SIGMAS):
        R = np.array([[s if slip == "R = sigma" else s**2]])
        steady = steady_state(DEFAULT.A, C, DEFAULT.Q, R)
        covariance = steady.covariance if slip == "prediction" else steady.estimate_covariance
        forecast[s] = covariance[0, 0]
        start = 0 if slip == "whole trial" else BURN
        error = batch.positions[:, i, start:] - TRUTH[start:]
        std = np.sqrt(batch.position_variances[:, i, start:])
        inside = np.abs(error) <= (std if slip == "one sigma" else 2 * std)
        coverage[s] = inside.mean() if slip == "fraction" else 100 * inside.mean()
    return forecast, coverage


def test_check_steady_state_passes_the_worked_answer(batch, capsys) -> None:
    assert_passes(capsys, checks.check_steady_state, *confidence(batch))


@pytest.mark.parametrize(("slip", "phrase"), [
    ("prediction", "forecast[1.5] = 0.485115 cm² is not right"),
    ("prediction", "it is [P∞]pp, the covariance of the prediction before each reading"),
    ("R = sigma", "R holds σ_v (cm) where its variance σ_v² (cm²) belongs"),
    ("whole trial", "coverage[1.5] = 93.0723 % is not right: it includes the burn-in"),
    ("one sigma", "the band is ±1σ"),
    ("fraction", "it is a fraction; the task asks for a percentage"),
])
def test_check_steady_state_names_the_cause(batch, slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_steady_state, *confidence(batch, slip))


# ------------------------------------------------------------------------------------------
# check_nis
# ------------------------------------------------------------------------------------------


def nis_task(batch, slip: str = "") -> tuple[dict, dict]:
    """Part 3's NIS task as a student writes it, with one ``slip``."""
    innovations = batch.innovations()
    e = innovations.values[..., 0]                                # (runs, 2, n) cm
    S = innovations.covariances[..., 0, 0]                        # (runs, 2, n) cm²
    nis_mean, runs_inside = {}, {}
    for i, s in enumerate(SIGMAS):
        if slip == "divided by R":
            nis = e[:, i] ** 2 / s**2
        elif slip == "not squared":
            nis = np.abs(e[:, i]) / np.sqrt(S[:, i])
        else:
            nis = e[:, i] ** 2 / S[:, i]
        start = 0 if slip == "whole trial" else BURN
        run_means = nis[:, start:].mean(axis=-1)
        steps = DEFAULT.n_steps - BURN
        low, high = metrics.nis_band(1, steps * DEFAULT.mc_runs if slip == "grand band" else steps)
        nis_mean[s] = run_means.mean()
        share = np.mean((low <= run_means) & (run_means <= high))
        runs_inside[s] = share if slip == "fraction" else 100 * share
    return nis_mean, runs_inside


def test_check_nis_passes_the_worked_answer(batch, capsys) -> None:
    assert_passes(capsys, checks.check_nis, *nis_task(batch))


@pytest.mark.parametrize(("slip", "phrase"), [
    ("divided by R", "nis_mean[1.5] = 1.2"),
    ("divided by R", "each e² is divided by R, the readings' noise alone"),
    ("not squared", "e is divided by √S and not squared"),
    ("whole trial", "it includes the burn-in"),
    ("grand band", "runs_inside[1.5] = 9.66667 % is not right: the band is that of the mean"),
    ("fraction", "runs_inside[1.5] = 0.953333 % is not right: it is a fraction"),
])
def test_check_nis_names_the_cause(batch, slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_nis, *nis_task(batch, slip))


def test_check_nis_knows_the_true_path_is_not_the_observers() -> None:
    """NEES (it needs the truth) in place of the NIS is named."""
    b = experiments.track(DEFAULT, sigmas=[[1.5], [4.5]], runs=DEFAULT.mc_runs)
    nees = (b.positions - TRUTH) ** 2 / b.position_variances
    nis_mean = {s: nees[:, i, BURN:].mean() for i, s in enumerate(SIGMAS)}
    _, runs_inside = nis_task(b)
    assert_fails("it uses the true path (estimate − truth)² / variance, which no observer has",
                 checks.check_nis, nis_mean, runs_inside)


# ------------------------------------------------------------------------------------------
# check_sampling_ratio
# ------------------------------------------------------------------------------------------


def sampling(slip: str = "") -> dict:
    """Part 4's task as a student writes it, with one ``slip``."""
    ratio = {}
    for dt in (0.02, 0.01, 0.002):
        fixed = {"jerk_std": DEFAULT.process_jerk_std} if slip == "fixed jerk" else {}
        scenario = dataclasses.replace(DEFAULT, dt=dt, **fixed)
        runs = experiments.track(scenario, sigmas=[1.5], runs=DEFAULT.mc_runs)
        truth = scenario.truth[:, 0]
        burn = DEFAULT.burn_in_steps if slip == "burn in samples" else scenario.burn_in_steps
        raw = metrics.mse(runs.measurements[..., 0], truth, burn)
        filtered = metrics.mse(runs.positions, truth, burn)
        ratio[dt] = (filtered.mean() / raw.mean() if slip == "inverted"
                     else np.mean(raw / filtered) if slip == "mean of ratios"
                     else raw.mean() / filtered.mean())
    return ratio


@pytest.mark.slow
def test_check_sampling_ratio_passes_the_worked_answer(capsys) -> None:
    assert_passes(capsys, checks.check_sampling_ratio, sampling())


@pytest.mark.parametrize(("slip", "phrase"), [
    ("inverted", "ratio[0.02] = 0.287496 is not right: it is filtered / raw"),
    ("fixed jerk", "ratio[0.02] = 3.38541 is not right"),
    ("fixed jerk", "σ_j is held at 1,396 cm/s³ at every Δt"),
    ("burn in samples", "ratio[0.02] = 3.47184 is not right"),
    ("burn in samples", "it leaves out 100 samples at every Δt"),
    ("mean of ratios", "it is the mean of the per-run ratios"),
])
@pytest.mark.slow
def test_check_sampling_ratio_names_the_cause(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_sampling_ratio, sampling(slip))


@pytest.mark.slow
def test_check_sampling_ratio_wants_the_three_time_steps() -> None:
    ratio = sampling()
    assert_fails("ratio has no entry for Δt = 0.002 s", checks.check_sampling_ratio,
                 {0.02: ratio[0.02], 0.01: ratio[0.01]})
