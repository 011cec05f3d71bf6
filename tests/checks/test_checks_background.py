"""Checks of notebook 00: worked answers pass, typical mistakes fail with their own message.

The wrong answers are written here as a student would write them, independently of the
mistakes :mod:`lqe_helpers.checks` computes to recognise them.
"""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks
from lqe_helpers.scenario import DEFAULT

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


def test_check_transition_matrix_judges_the_tasks_A_too(capsys):
    line = assert_passes(capsys, checks.check_transition_matrix, make_A, make_A(DEFAULT.dt))
    assert line.endswith(f"and A is its value at Δt = {DEFAULT.dt:g} s")
    assert_fails("A is eq. (4)'s A at Δt = 0.1 s; the task's A is my_transition_matrix("
                 "DEFAULT.dt)", checks.check_transition_matrix, make_A, make_A(0.1))
    assert_fails("A is not my_transition_matrix(DEFAULT.dt)", checks.check_transition_matrix,
                 make_A, make_A(DEFAULT.dt).T)
    assert_fails("A must be", checks.check_transition_matrix, make_A, np.eye(2))


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
    if mistake == "no Ft":
        return F @ P + sigma**2 * G @ G.T
    if mistake == "no F":
        return P @ F.T + sigma**2 * G @ G.T
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
    ("no Ft", "Fᵀ is missing on the right"),
    ("no F", "F is missing on the left"),
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
    sigma = {"sigma squared": DEFAULT.process_jerk_std**2,
             "sigma_v": DEFAULT.sigma_v}.get(mistake, DEFAULT.process_jerk_std)
    A, g = model.transition_matrix(DEFAULT.dt), model.jerk_input_matrix(DEFAULT.dt)
    P_close = P
    entry = 1 if mistake == "velocity entry" else 0   # P[1, 1] for the position's P[0, 0]
    variances = [P[entry, entry]]
    for _ in range(100):
        if mistake == "restart":  # each step from P_close, not from the last P
            P = predict_covariance(P_close, A, g, sigma)
        else:
            P = predict_covariance(P, A, g, sigma)
        variances.append(P[entry, entry])
    variances = np.array(variances)
    two_sigma = {"one sigma": np.sqrt(variances), "no root": 2 * variances,
                 "no start": 2 * np.sqrt(variances[1:])}.get(mistake, 2 * np.sqrt(variances))
    compared = {"variance crossing": variances,
                "sigma crossing": np.sqrt(variances)}.get(mistake, 2 * np.sqrt(variances))
    above = np.argmax(compared > DEFAULT.amplitude)
    crossing = {"samples": above, "last below": (above - 1) * DEFAULT.dt,
                "trial time": 2.0 + above * DEFAULT.dt}.get(mistake, above * DEFAULT.dt)
    return two_sigma, crossing


def test_check_eyes_closed_passes_the_worked_solution(capsys):
    line = assert_passes(capsys, checks.check_eyes_closed, predict_covariance, *eyes_closed())
    assert "P_close" in line and "1e-9" in line and "crossing" in line


def test_check_eyes_closed_without_crossing_judges_the_band_only(capsys):
    """Notebook 00 computes the crossing in a given cell: the check takes the band alone."""
    two_sigma, _ = eyes_closed()
    line = assert_passes(capsys, checks.check_eyes_closed, predict_covariance, two_sigma)
    assert "two_sigma matches the band" in line and "crossing" not in line
    assert_fails("it is σ, not 2σ", checks.check_eyes_closed, predict_covariance,
                 eyes_closed(mistake="one sigma")[0])


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("one sigma", "it is σ, not 2σ"),
    ("no root", "twice the variance"),
    ("no start", "keep the moment the eyes close too"),
    ("from zero", "it starts from P = 0"),
    ("sigma squared", "σ_j² where its standard deviation σ_j belongs"),
    ("sigma_v", "sigma is vision's noise σ_v"),
    ("restart", "every step starts again from P_close"),
    ("samples", "it is in samples"),
    ("last below", "one step early"),
    ("trial time", "it counts from the start of the trial"),
    ("variance crossing", "it is when the variance P[0, 0] (cm²) exceeds the amplitude"),
    ("sigma crossing", "it is when σ exceeds the amplitude"),
    ("velocity entry", "two_sigma is not right: it is 2 √P[1, 1], the velocity's variance "
                       "(cm²/s²): the position's is the first diagonal entry, P[0, 0] (cm²)"),
])
def test_check_eyes_closed_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_eyes_closed, predict_covariance,
                 *eyes_closed(mistake=mistake))


def test_check_eyes_closed_checks_the_function_first():
    two_sigma, crossing = eyes_closed()
    assert_fails("σ is used where its square belongs", checks.check_eyes_closed,
                 lambda P, F, G, s: predict_covariance(P, F, G, s, mistake="sigma"),
                 two_sigma, crossing)
    assert_fails("Fᵀ is missing on the right", checks.check_eyes_closed,
                 lambda P, F, G, s: predict_covariance(P, F, G, s, mistake="no Ft"),
                 two_sigma)


# --- check_jerk_stds (Task 3) ----------------------------------------------------------------

PERIODS = {"an eighth": 1 / 8, "a quarter": 1 / 4, "a half": 1 / 2, "a whole": 1.0}


def jerk_stds(*, mistake=""):
    """jerk_stds of Task 3 as a student writes it, with one slip at most."""
    from lqe_helpers.scenario import DEFAULT

    f, dt, amplitude = DEFAULT.frequency, DEFAULT.dt, DEFAULT.amplitude
    omega = {"omega is f": f, "omega 2 pi over f": 2 * np.pi / f}.get(mistake, 2 * np.pi * f)
    found = {}
    for name, fraction in PERIODS.items():
        T = {"T in periods": fraction, "T times f": fraction * f}.get(mistake, fraction / f)
        found[name] = {
            "no sqrt": amplitude * omega**2 / (dt * T),
            "root over dt only": amplitude * omega**2 / np.sqrt(dt) * T,
            "root over dt, then divided by T": amplitude * omega**2 / np.sqrt(dt) / T,
            "omega not squared": amplitude * omega / np.sqrt(dt * T),
            "variance": (amplitude * omega**2 / np.sqrt(dt * T)) ** 2,
            "times the root": amplitude * omega**2 * np.sqrt(dt * T),
        }.get(mistake, amplitude * omega**2 / np.sqrt(dt * T))
    return found


def test_check_jerk_stds_passes_the_worked_solution(capsys):
    line = assert_passes(capsys, checks.check_jerk_stds, jerk_stds())
    assert "1/8, 1/4, 1/2 and 1 period" in line


def test_the_quarter_period_gives_the_scenarios_jerk_std():
    from lqe_helpers.scenario import DEFAULT

    assert np.isclose(jerk_stds()["a quarter"], DEFAULT.process_jerk_std, rtol=1e-12)


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("T in periods", "T is in periods, not seconds"),
    ("T times f", "the period was taken as f"),
    ("omega is f", "ω is f (Hz)"),
    ("omega 2 pi over f", "ω is 2π/f"),
    ("no sqrt", "the square root is missing"),
    ("root over dt, then divided by T", "the root covers Δt only"),
    ("root over dt only", "it multiplies by T"),
    ("omega not squared", "ω is not squared"),
    ("variance", "it is σ_j², a variance"),
    ("times the root", "it multiplies by √(Δt T)"),
])
def test_check_jerk_stds_names_each_realistic_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_jerk_stds, jerk_stds(mistake=mistake))


def test_check_jerk_stds_wants_the_names_of_periods():
    values = jerk_stds()
    renamed = {f"T = {PERIODS[name]:g}": value for name, value in values.items()}
    assert_fails("has no entry 'an eighth'", checks.check_jerk_stds, renamed)
    assert_fails("must be a dict", checks.check_jerk_stds, list(values.values()))
