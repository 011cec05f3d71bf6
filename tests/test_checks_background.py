"""Checks of notebook 00: worked answers pass, typical mistakes fail with their own message.

The wrong answers are written here as a student would write them, independently of the
mistakes :mod:`lqe_helpers.checks` computes to recognise them.
"""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks

# --- check_transition_matrix ----------------------------------------------------------------

def make_A(dt, *, mistake=""):
    corner = {"no half": dt**2, "no corner": 0.0, "half dt": dt / 2}.get(mistake, dt**2 / 2)
    A = np.array([[1.0, dt, corner], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])
    if mistake == "transposed":
        return A.T
    if mistake == "identity":
        return np.eye(3)
    return A


def test_check_transition_matrix_passes_the_worked_solution(capsys):
    line = assert_passes(capsys, checks.check_transition_matrix, make_A)
    assert "make_A" in line and "eq. (4)" in line


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("transposed", "A is transposed"),
    ("no half", "is Δt², but the Taylor term"),
    ("no corner", "ignores the acceleration"),
    ("half dt", "the corner entry is Δt/2"),
    ("identity", "A is the identity"),
])
def test_check_transition_matrix_names_each_typical_mistake(mistake, phrase):
    messages = assert_fails(phrase, checks.check_transition_matrix,
                            lambda dt: make_A(dt, mistake=mistake))
    assert "np." not in messages and "@" not in messages


def test_check_transition_matrix_rejects_a_hard_coded_answer():
    assert_fails("the same matrix for every time step", checks.check_transition_matrix,
                 lambda dt: make_A(0.01))


def test_check_transition_matrix_wants_a_3_by_3_matrix_and_the_function_written():
    assert_fails("must be 3 × 3", checks.check_transition_matrix, lambda dt: np.eye(2))
    assert_fails("returned None (nothing)", checks.check_transition_matrix, lambda dt: None)

    def not_written(dt):
        raise NotImplementedError

    assert_fails("is not written yet", checks.check_transition_matrix, not_written)


# --- check_covariance_step -------------------------------------------------------------------

def predict_covariance(P, F, G, sigma, *, mistake=""):
    if mistake == "sides":
        return F.T @ P @ F + sigma**2 * G @ G.T
    if mistake == "no noise":
        return F @ P @ F.T
    if mistake == "sigma":
        return F @ P @ F.T + sigma * G @ G.T
    if mistake == "no transpose":
        return F @ P @ F + sigma**2 * G @ G.T
    if mistake == "not moved":
        return P + sigma**2 * G @ G.T
    return F @ P @ F.T + sigma**2 * G @ G.T


def test_check_covariance_step_passes_the_worked_solution(capsys):
    line = assert_passes(capsys, checks.check_covariance_step, predict_covariance)
    assert "F P Fᵀ + G σ² Gᵀ" in line


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("sides", "on the wrong sides"),
    ("no noise", "is not added"),
    ("sigma", "σ is used where its square belongs"),
    ("no transpose", "the second F is not transposed"),
    ("not moved", "P is not carried through the model"),
])
def test_check_covariance_step_names_each_typical_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_covariance_step,
                 lambda P, F, G, s: predict_covariance(P, F, G, s, mistake=mistake))


def test_check_covariance_step_rejects_changing_p_in_place_and_wrong_shapes():
    def in_place(P, F, G, sigma):
        P += sigma**2 * G @ G.T
        return P

    assert_fails("changed its input P in place", checks.check_covariance_step, in_place)
    assert_fails("the new covariance has the shape of P", checks.check_covariance_step,
                 lambda P, F, G, s: s**2 * G.T @ G)


def test_check_covariance_step_agrees_with_the_pack_on_the_butterfly(capsys):
    from lqe_helpers import model, prediction

    dt, sigma_j = 0.01, 1400.0
    A, g = model.transition_matrix(dt), model.jerk_input_matrix(dt)
    P = np.diag([1.0, 4.0, 9.0])
    expected = prediction.propagate_covariance(P, A, model.process_noise_covariance(
        dt, sigma_j), 1)[1]
    np.testing.assert_allclose(predict_covariance(P, A, g, sigma_j), expected, rtol=1e-12)


def test_check_transition_matrix_stops_an_endless_loop(monkeypatch):
    from lqe_helpers.student_code import calling

    monkeypatch.setattr(calling, "TIME_LIMIT", 0.2)

    def make_A_forever(dt):
        steps = 0
        while steps >= 0:
            steps += 1
        return make_A(dt)

    assert_fails("make_A_forever did not return within 0.2 s", checks.check_transition_matrix,
                 make_A_forever)


def test_check_covariance_step_refuses_a_complex_or_boolean_result():
    assert_fails("returned complex numbers", checks.check_covariance_step,
                 lambda P, F, G, s: predict_covariance(P, F, G, s) + 0j)
    assert_fails("returned an array of True/False values (booleans)", checks.check_covariance_step,
                 lambda P, F, G, s: predict_covariance(P, F, G, s) > 0)


# --- check_eyes_closed (Task 2) --------------------------------------------------------------
# The task as a student writes it: the notebook's P_close, their own loop, one slip at a time.

def eyes_closed(*, mistake=""):
    """two_sigma (101,) and crossing (s) of Task 2, written as the notebook's task asks."""
    from lqe_helpers import experiments, model
    from lqe_helpers.scenario import DEFAULT

    tracking = experiments.track(DEFAULT)
    close = round(2.0 / DEFAULT.dt)
    P = tracking.result.estimate_covariances[close]
    if mistake == "from zero":
        P = np.zeros((3, 3))
    sigma = DEFAULT.process_jerk_std**2 if mistake == "sigma squared" else \
        DEFAULT.process_jerk_std
    A, g = model.transition_matrix(DEFAULT.dt), model.jerk_input_matrix(DEFAULT.dt)
    variances = [P[0, 0]]
    for _ in range(100):
        P = predict_covariance(P, A, g, sigma)
        variances.append(P[0, 0])
    variances = np.array(variances)
    two_sigma = {"one sigma": np.sqrt(variances), "no root": 2 * variances,
                 "no start": 2 * np.sqrt(variances[1:])}.get(mistake, 2 * np.sqrt(variances))
    above = np.argmax(2 * np.sqrt(variances) > DEFAULT.amplitude)
    crossing = {"samples": above, "last below": (above - 1) * DEFAULT.dt,
                "trial time": 2.0 + above * DEFAULT.dt}.get(mistake, above * DEFAULT.dt)
    return two_sigma, crossing


def test_check_eyes_closed_passes_the_worked_solution(capsys):
    line = assert_passes(capsys, checks.check_eyes_closed, predict_covariance, *eyes_closed())
    assert "P_close" in line and "1e-9" in line


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("one sigma", "it is σ, not 2σ"),
    ("no root", "twice the variance"),
    ("no start", "keep the moment the eyes close too"),
    ("from zero", "it starts from P = 0"),
    ("sigma squared", "σ_j² where its standard deviation σ_j belongs"),
    ("samples", "it is in samples"),
    ("last below", "one step early"),
    ("trial time", "it counts from the start of the trial"),
])
def test_check_eyes_closed_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_eyes_closed, predict_covariance,
                 *eyes_closed(mistake=mistake))


def test_check_eyes_closed_checks_the_function_first():
    two_sigma, crossing = eyes_closed()
    assert_fails("σ is used where its square belongs", checks.check_eyes_closed,
                 lambda P, F, G, s: predict_covariance(P, F, G, s, mistake="sigma"),
                 two_sigma, crossing)


# --- check_jerk_matching (Task 3) ------------------------------------------------------------

PERIODS = {"an eighth": 1 / 8, "a quarter": 1 / 4, "a half": 1 / 2, "a whole": 1.0}


def jerk_matching(*, mistake=""):
    """jerk_stds, mse_runs and whole_vs_quarter of Task 3 as a student writes them."""
    import dataclasses

    from lqe_helpers import experiments, metrics
    from lqe_helpers.scenario import DEFAULT

    f = DEFAULT.frequency
    omega = f if mistake == "omega is f" else 2 * np.pi * f
    jerk_stds, mse_runs, per_run = {}, {}, {}
    for name, fraction in PERIODS.items():
        T = fraction if mistake == "T in periods" else fraction / f
        jerk_stds[name] = DEFAULT.amplitude * omega**2 / np.sqrt(DEFAULT.dt * T)
        if mistake == "no sqrt":
            jerk_stds[name] = DEFAULT.amplitude * omega**2 / (DEFAULT.dt * T)
        variant = DEFAULT if mistake == "default scenario" else dataclasses.replace(
            DEFAULT, jerk_std=jerk_stds[name])
        batch = experiments.track(variant, runs=DEFAULT.mc_runs)
        per_run[name] = {"whole trial": metrics.mse(batch.positions, DEFAULT.truth[:, 0])
                         }.get(mistake, batch.mse())
        # "mean only": the interval below still made from the runs (else it would not run)
        mse_runs[name] = per_run[name].mean() if mistake == "mean only" else per_run[name]
    whole, quarter = per_run["a whole"], per_run["a quarter"]
    whole_vs_quarter = {
        "reversed": lambda: metrics.mean_ci95(quarter - whole),
        "percent": lambda: metrics.mean_ci95(100 * (whole - quarter) / quarter.mean()),
        "unpaired": lambda: metrics.Interval(
            whole.mean() - quarter.mean(),
            whole.mean() - quarter.mean() - metrics.mean_ci95(whole).half_width
            - metrics.mean_ci95(quarter).half_width,
            whole.mean() - quarter.mean() + metrics.mean_ci95(whole).half_width
            + metrics.mean_ci95(quarter).half_width, whole.size),
    }.get(mistake, lambda: metrics.mean_ci95(whole - quarter))()
    return jerk_stds, mse_runs, whole_vs_quarter


def test_check_jerk_matching_passes_the_worked_solution(capsys):
    line = assert_passes(capsys, checks.check_jerk_matching, *jerk_matching())
    assert "300 runs" in line


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("T in periods", "T is in periods, not seconds"),
    ("omega is f", "ω is f (Hz)"),
    ("no sqrt", "the square root is missing"),
    ("default scenario", "every run used the pack's σ_j"),
    ("whole trial", "of the whole trial"),
    ("mean only", "is one number"),
    ("reversed", "the sign is reversed"),
    ("percent", "it is in % of the quarter's MSE"),
    ("unpaired", "combines the two separate intervals"),
])
def test_check_jerk_matching_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_jerk_matching, *jerk_matching(mistake=mistake))


def test_check_jerk_matching_wants_the_names_of_periods():
    jerk_stds, mse_runs, interval = jerk_matching()
    renamed = {f"T = {PERIODS[name]:g}": value for name, value in jerk_stds.items()}
    assert_fails("has no entry 'an eighth'", checks.check_jerk_matching, renamed, mse_runs,
                 interval)
    assert_fails("must be a dict", checks.check_jerk_matching, list(jerk_stds.values()),
                 mse_runs, interval)
