"""Checks of notebook 03's core tasks: the worked answers pass, realistic slips fail saying why.

The wrong answers are written here as a student would write them (the task's own code with
one slip), independently of the mistakes :mod:`lqe_helpers.checks.fusion` computes to
recognise them. The worked filter is the test oracle ``reference_loops`` (outside the
package). The Going further checks are tested in ``test_checks_fusion_further.py``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import reference_loops as reference
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, experiments, metrics, model
from lqe_helpers.scenario import DEFAULT

C_FUSED = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])


def test_check_fusion_passes_the_worked_solution(capsys) -> None:
    C = model.observation_matrix(("vision", "proprioception"))
    R = model.measurement_noise_covariance([1.5, 4.5])
    line = assert_passes(capsys, checks.check_fusion, C, R, 1.5, 4.5)
    assert "diag(2.25, 20.25) cm²" in line


@pytest.mark.parametrize(("C", "R", "phrase"), [
    (C_FUSED.T, np.diag([2.25, 20.25]), "it is transposed"),
    (C_FUSED[:1], np.diag([2.25, 20.25]), "one row only"),
    (np.array([[1.0, 0, 0], [0, 1.0, 0]]), np.diag([2.25, 20.25]),
     "row 1 (proprioception) is [0.0, 1.0, 0.0], which reads velocity v"),
    (C_FUSED, np.diag([1.5, 4.5]), "R holds the standard deviations"),
    (C_FUSED, np.diag([20.25, 2.25]), "R's rows are swapped"),
    (C_FUSED, np.diag([2.25, 4.5]), "R's proprioception entry holds σ = 4.5 cm, not its "
                                    "variance σ² (cm²)"),
    (C_FUSED, np.diag([1.5, 20.25]), "R's vision entry holds σ = 1.5 cm"),
    (C_FUSED, np.array([[2.25, 6.75], [6.75, 20.25]]), "R has off-diagonal entries"),
    (C_FUSED, np.array([2.25, 20.25]), "R has shape (2,): a vector"),
    (C_FUSED, np.diag([2.25, 20.25, 1.0]), "R must have shape (2, 2)"),
])
def test_check_fusion_names_each_typical_mistake(C, R, phrase: str) -> None:
    assert_fails(phrase, checks.check_fusion, C, R, 1.5, 4.5)


@pytest.mark.parametrize(("C", "R", "sigma_v", "phrase"), [
    (None, np.diag([2.25, 20.25]), 1.5,
     "C must be the observation matrix, an array of shape (2, 3), got None"),
    (C_FUSED, None, 1.5,
     "R must be the noise covariance (cm²), an array of shape (2, 2), got None"),
    (1e200 * C_FUSED, np.diag([2.25, 20.25]), 1.5, "got values too large to square"),
    (C_FUSED, np.diag([2.25, 20.25]) + 0j, 1.5, "R must be the noise covariance (cm²), an array "
                                                "of shape (2, 2), got complex numbers"),
    (C_FUSED, np.diag([2.25, np.nan]), 1.5, "got NaN (not a number) or an infinite value at "
                                            "index (1, 1)"),
    (C_FUSED, np.diag([2.25, 20.25]), True, "sigma_v must be a number > 0 cm, got True (a "
                                            "boolean)"),
    (C_FUSED, np.diag([2.25, 20.25]), 1e300, "sigma_v must be a number > 0 cm, got values too "
                                             "large to square"),
])
def test_check_fusion_names_a_bad_argument(C, R, sigma_v, phrase: str) -> None:
    assert_fails(phrase, checks.check_fusion, C, R, sigma_v, 4.5)


# ------------------------------------------------------------------------------------------
# Task 2: one trial filtered both ways (the worked filter is the oracle reference_loops)
# ------------------------------------------------------------------------------------------

FUSED = ("vision", "proprioception")
SIGMA = 1.5


def plain_loop(y, A, C, Q, R, z0, P0):
    """Eq. (5) as a student writes it, without the oracle's shape checks: numpy broadcasts a
    reading y_j of shape (1,) against a prediction C A ẑ of shape (2,) without a word."""
    return reference.student_lqe_filter(y, A, C, Q, R, z0, P0)


def task2(mistake: str = "") -> tuple[np.ndarray, np.ndarray, float, float]:
    """Task 2 as a student writes it, with their filter, optionally with one slip."""
    trial = experiments.track(DEFAULT, FUSED)
    y, truth, burn = trial.measurements, DEFAULT.truth[:, 0], DEFAULT.burn_in_steps
    A, Q, z0, P0 = DEFAULT.A, DEFAULT.Q, np.zeros(3), np.eye(3)
    C = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    R = np.diag([SIGMA**2, SIGMA**2])
    fused_all = reference.lqe_filter(y, A, C, Q, R, z0, P0)
    vision_all = reference.lqe_filter(y[:, :1], A, C[:1], Q, R[:1, :1], z0, P0)
    fused, vision = fused_all[:, 0], vision_all[:, 0]
    if mistake == "proprioception column":
        vision = reference.lqe_filter(y[:, 1:], A, C[:1], Q, R[:1, :1], z0, P0)[:, 0]
    if mistake == "full C and R for vision":   # numpy broadcasts y_j (1,) against C A ẑ (2,)
        vision = plain_loop(y[:, :1], A, C, Q, R, z0, P0)[:, 0]
    if mistake == "velocity":
        fused = fused_all[:, 1]
    if mistake == "velocity in both":
        fused, vision = fused_all[:, 1], vision_all[:, 1]
    if mistake == "averaged readings":
        fused = reference.lqe_filter(y.mean(axis=1, keepdims=True), A, C[:1], Q, R[:1, :1], z0,
                                     P0)[:, 0]
    if mistake == "sigma in R":
        fused = reference.lqe_filter(y, A, C, Q, np.diag([SIGMA, SIGMA]), z0, P0)[:, 0]
    if mistake == "swapped":
        fused, vision = vision, fused
    if mistake == "all states":
        fused = fused_all
    if mistake == "P0 large":
        big = np.diag([1e5, 1e5, 1e5])
        fused = reference.lqe_filter(y, A, C, Q, R, z0, big)[:, 0]
        vision = reference.lqe_filter(y[:, :1], A, C[:1], Q, R[:1, :1], z0, big)[:, 0]
    if mistake == "metres":
        fused = reference.lqe_filter(y / 100, A, C, Q, R, z0, P0)[:, 0]
    start = {"burn-in in seconds": 1, "whole trial": 0, "burn-in + 1": burn + 1,
             "burn-in - 1": burn - 1, "burn-in of 2 s": 2 * burn}.get(mistake, burn)
    mse_fused = np.mean((fused[start:] - truth[start:]) ** 2) if fused.ndim == 1 else 0.0
    mse_vision = np.mean((vision[start:] - truth[start:]) ** 2)
    if mistake == "against the readings":
        mse_vision = np.mean((vision[burn:] - y[burn:, 0]) ** 2)
    if mistake == "rmse":
        mse_fused = np.sqrt(mse_fused)
    if mistake == "readings' MSE":
        mse_vision = np.mean((y[burn:, 0] - truth[burn:]) ** 2)
    if mistake == "fused MSE twice":
        mse_vision = mse_fused
    return vision, fused, mse_vision, mse_fused


def test_check_fusion_trial_passes_the_worked_solution(capsys) -> None:
    line = assert_passes(capsys, checks.check_fusion_trial, *task2())
    assert line == ("✓ both filters' positions match the pack's engine on the task's trial to "
                    "1e-9 of the largest, and both MSEs (after the first 100 samples) to 1e-6 "
                    "relative")


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("proprioception column", "vision_positions is not right: it is the filter run on "
                              "proprioception's readings (column 1 of y)"),
    ("full C and R for vision", "vision_positions is not right: the vision-only run kept both "
                                "senses' C and R: with vision's readings y[:, :1] it needs "
                                "C[:1] (1, 3) and R[:1, :1] (1, 1) too"),
    ("velocity", "fused_positions is not right: it is column 1 of the estimates, the velocity"),
    ("averaged readings", "fused_positions is not right: the two readings were averaged and "
                          "filtered as one sense"),
    ("sigma in R", "fused_positions is not right: R holds σ (cm) where the variance σ² (cm²) "
                   "belongs"),
    ("swapped", "vision_positions is not right: it is the fused filter's estimate"),
    ("all states", "fused_positions has shape (1000, 3): it holds 3 column(s) of estimates"),
    ("whole trial", "mse_vision_trial = 0.363507 cm²"),
    ("whole trial", "is not right: it is the MSE of the whole trial: the first 100 samples"),
    ("burn-in in seconds", "it leaves out the first 1 sample(s): the burn-in is 1 s"),
    ("rmse", "mse_fused_trial = 0.39"),
    ("rmse", "is not right: it is the root mean squared error (RMSE, in cm)"),
    ("readings' MSE", "mse_vision_trial = 2.03754 cm²"),
    ("readings' MSE", "it is the MSE of vision's raw readings, not of the filter's estimate"),
    ("fused MSE twice", "mse_vision_trial = 0.15961 cm² is not right: it is the MSE of the "
                        "fused filter's estimate"),
    ("against the readings", "mse_vision_trial = 1.6"),
    ("against the readings", "is not right: it compares the estimate with vision's readings "
                             "(column 0 of y), not with the true position"),
    ("burn-in + 1", "is not right: it leaves out one sample too many (101 instead of 100)"),
    ("burn-in - 1", "is not right: it leaves out one sample too few (99 instead of 100)"),
    ("burn-in of 2 s", "mse_vision_trial = 0.325 cm²"),  # the seventh trial (G1): any burn-in
    ("burn-in of 2 s", "is not right: it leaves out the first 200 samples (2 s), not the "
                       "burn-in's 100: keep the samples from index 100 on"),
    ("P0 large", "vision_positions is not right: P0 is diag(1e5), notebook 02's uncertain "
                 "start: this question starts from P0 = diag(1)"),
    ("metres", "fused_positions is not right: the readings are in metres"),
])
@pytest.mark.slow
def test_check_fusion_trial_names_each_realistic_mistake(mistake: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_fusion_trial, *task2(mistake))


def test_check_fusion_trial_names_a_slip_made_in_both_filters_for_both() -> None:
    message = assert_fails("vision_positions is not right: it is column 1 of the estimates, "
                           "the velocity", checks.check_fusion_trial, *task2("velocity in both"))
    assert "Also, fused_positions is not right: it is column 1 of the estimates" in message


def test_check_fusion_trial_refuses_what_is_not_a_position_array() -> None:
    vision, fused, mse_vision, mse_fused = task2()
    assert_fails("vision_positions must be the estimated positions (cm), an array of shape "
                 "(1000,), got None", checks.check_fusion_trial, None, fused, mse_vision,
                 mse_fused)
    assert_fails("mse_fused_trial must be one number (cm²), got an array of shape (2,)",
                 checks.check_fusion_trial, vision, fused, mse_vision,
                 np.array([mse_fused, mse_fused]))
    assert_fails("mse_fused_trial is NaN", checks.check_fusion_trial, vision, fused,
                 mse_vision, float("nan"))


# ------------------------------------------------------------------------------------------
# Task 3: many trials, compared pair by pair
# ------------------------------------------------------------------------------------------


def task3(mistake: str = "") -> tuple[np.ndarray, np.ndarray, object]:
    """Task 3 as a student writes it, optionally with one slip."""
    runs, truth, burn = DEFAULT.mc_runs, DEFAULT.truth[:, 0], DEFAULT.burn_in_steps
    vision_mc = experiments.track(DEFAULT, ("vision",), runs=runs)
    fused_mc = experiments.track(DEFAULT, FUSED, runs=runs)
    start = {"burn-in in seconds": 1, "whole trial": 0, "burn-in + 1": burn + 1,
             "burn-in - 1": burn - 1, "burn-in of 50": burn // 2}.get(mistake, burn)
    mse_vision = metrics.mse(vision_mc.positions, truth, start)
    mse_fused = metrics.mse(fused_mc.positions, truth, start)
    difference = metrics.mean_ci95(mse_vision - mse_fused)
    if mistake in ("burn-in + 1", "burn-in - 1"):   # per-run MSEs right, difference not
        mse_vision = metrics.mse(vision_mc.positions, truth, burn)
        mse_fused = metrics.mse(fused_mc.positions, truth, burn)
    if mistake == "against the readings":
        mse_vision = np.mean((vision_mc.positions - vision_mc.measurements[..., 0])[:, burn:] ** 2,
                             axis=-1)
    if mistake == "whole-trial difference":
        difference = metrics.mean_ci95(metrics.mse(vision_mc.positions, truth)
                                       - metrics.mse(fused_mc.positions, truth))
    if mistake == "fused minus vision":
        difference = metrics.mean_ci95(mse_fused - mse_vision)
    if mistake == "two intervals combined":
        alone_v, alone_f = metrics.mean_ci95(mse_vision), metrics.mean_ci95(mse_fused)
        difference = metrics.Interval(alone_v.mean - alone_f.mean, alone_v.low - alone_f.high,
                                      alone_v.high - alone_f.low, runs)
    if mistake == "percent":
        difference = metrics.mean_ci95(100 * (mse_vision - mse_fused) / mse_vision)
    if mistake == "ratio":
        difference = metrics.mean_ci95(mse_vision / mse_fused)
    if mistake == "means only":
        difference = mse_vision.mean() - mse_fused.mean()
    if mistake == "one run":
        mse_vision = float(metrics.mse(vision_mc.positions[0], truth, burn))
    if mistake == "swapped":
        mse_vision, mse_fused = mse_fused, mse_vision
    if mistake == "runs not paired":   # the student trial: run r − run r−1 of the other
        difference = metrics.mean_ci95(mse_vision - np.roll(mse_fused, 1))
    return mse_vision, mse_fused, difference


def test_check_fusion_difference_passes_the_worked_solution(capsys) -> None:
    line = assert_passes(capsys, checks.check_fusion_difference, *task3())
    assert "over 300 runs match the pack's engine to 1e-6" in line
    assert "the paired difference vision only − fused after the first second" in line


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("whole-trial difference", "difference is not right: it is the difference over the whole "
                               "trial"),
    ("fused minus vision", "difference is not right: the sign is reversed"),
    ("two intervals combined", "difference is not right: it combines the two separate "
                               "intervals"),
    ("percent", "difference is not right: it is the relative difference in % of the "
                "vision-only MSE"),
    ("ratio", "difference is not right: it is the interval of the ratio vision only / fused"),
    ("means only", "difference is a number; it must be the metrics.Interval"),
    ("one run", "mse_vision is one number; the task asks for one MSE per run, shape (300,)"),
    ("whole trial", "mse_vision is not right: it is the MSE of the whole trial"),
    ("burn-in in seconds", "mse_vision is not right: it leaves out the first 1 sample(s)"),
    ("swapped", "mse_vision is not right: these are the fused filter's MSEs"),
    ("against the readings", "mse_vision is not right: it compares the estimate with vision's "
                             "readings (column 0 of y), not with the true position"),
    ("burn-in + 1", "difference is not right: it leaves out one sample too many (101 instead "
                    "of 100)"),
    ("burn-in - 1", "difference is not right: it leaves out one sample too few (99 instead "
                    "of 100)"),
    ("runs not paired", "is not right: its runs are not paired: the mean is right"),
    ("burn-in of 50", "mse_vision is not right: it leaves out the first 50 samples (0.5 s), "
                      "not the burn-in's 100"),  # the seventh trial (G1)
])
@pytest.mark.slow
def test_check_fusion_difference_names_each_realistic_mistake(mistake: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_fusion_difference, *task3(mistake))


def test_check_fusion_difference_names_a_slip_made_in_both_filters_for_both() -> None:
    message = assert_fails("mse_vision is not right: it is the MSE of the whole trial",
                           checks.check_fusion_difference, *task3("whole trial"))
    assert "Also, mse_fused is not right: it is the MSE of the whole trial" in message


def test_check_fusion_difference_uses_the_vision_only_runs_of_the_same_noise() -> None:
    """Pairing is what the check recomputes: vision-only runs on another draw fail."""
    _, mse_fused, _ = task3()
    other = experiments.track(dataclasses.replace(DEFAULT, seed=DEFAULT.seed + 1), ("vision",),
                              runs=DEFAULT.mc_runs)
    unpaired = metrics.mse(other.positions, DEFAULT.truth[:, 0], DEFAULT.burn_in_steps)
    assert_fails("mse_vision does not match the vision-only MSEs recomputed from the task's "
                 "runs", checks.check_fusion_difference, unpaired, mse_fused,
                 metrics.mean_ci95(unpaired - mse_fused))
