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
