"""A saved my_filter or compensate, loaded in a later notebook, names an input that does not fit.

The trials' slip: notebook 03's vision-only run given y[:, :1] with both senses' R stopped in
numpy inside my_functions/my_filter.py ("matmul: … mismatch in its core dimension"); with
both senses' C it ran on silently (numpy broadcasts the one reading against two rows).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from lqe_helpers import student_code
from lqe_helpers.student_code import StudentCodeError
from lqe_helpers.student_code.guards import compensate_inputs_problem, filter_inputs_problem

SAVED_FILTER = '''\
def my_filter(y, A, C, Q, R, z0, P0):
    z, P, out = z0, P0, []
    for y_j in y:
        K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
        z = A @ z + K @ (y_j - C @ A @ z)
        P = A @ (P - K @ C @ P) @ A.T + Q
        out.append(z)
    return np.array(out)
'''

A = np.array([[1.0, 0.01, 5e-5], [0.0, 1.0, 0.01], [0.0, 0.0, 1.0]])
C2 = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
R2 = np.diag([2.25, 20.25])
Y2 = np.arange(20.0).reshape(10, 2)
MODEL = {"A": A, "Q": np.eye(3), "z0": np.zeros(3), "P0": np.eye(3)}


@pytest.fixture
def loaded(tmp_path):
    folder = tmp_path / "my_functions"
    folder.mkdir()
    (folder / "my_filter.py").write_text(f"{student_code.SAVE_HEADER}\nimport numpy as np\n\n\n"
                                         f"{SAVED_FILTER}", encoding="utf-8")
    return student_code.load("my_filter", folder)


def call(my_filter, y, C, R):
    return my_filter(y, MODEL["A"], C, MODEL["Q"], R, MODEL["z0"], MODEL["P0"])


def test_inputs_that_fit_run_the_students_function_unchanged(loaded):
    assert loaded.__name__ == "my_filter"
    fused = call(loaded, Y2, C2, R2)
    vision = call(loaded, Y2[:, :1], C2[:1], R2[:1, :1])
    assert fused.shape == vision.shape == (10, 3)


@pytest.mark.parametrize(("C", "R", "phrase"), [
    (C2[:1], R2, r"R has shape \(2, 2\); for 1 sensor \(the columns of y, shape \(10, 1\)\) it "
                 r"must be \(1, 1\): one row and column per sensor \(for vision alone, "
                 r"R\[:1, :1\]\)"),
    (C2, R2[:1, :1], r"C has shape \(2, 3\); for 1 sensor .* it must be \(1, 3\): one row per "
                     r"sensor \(for vision alone, C\[:1\] with y\[:, :1\]\)"),
])
def test_a_vision_only_run_with_both_senses_c_or_r_is_named(loaded, C, R, phrase):
    with pytest.raises(StudentCodeError, match=f"^my_filter was given inputs that do not fit: "
                                               f"{phrase}"):
        call(loaded, Y2[:, :1], C, R)


def test_one_column_of_two_senses_readings_names_y_not_c(loaded):
    """Issue 23: Y[:, :1] with both senses' C and R blamed C; C and R agree, y does not.
    Both fixes are said: y of both senses, or C and R cut for vision alone."""
    with pytest.raises(StudentCodeError, match=r"^my_filter was given inputs that do not fit: "
                                               r"y has shape \(10, 1\), 1 column of readings, "
                                               r"while C \(2, 3\) and R \(2, 2\) are for 2 "
                                               r"sensors: with this C and R, y needs all 2 "
                                               r"senses' readings, shape \(n, 2\)") as info:
        call(loaded, Y2[:, :1], C2, R2)   # both kept: numpy alone would run on silently
    assert "C[:1], R[:1, :1]" in str(info.value)


def test_readings_made_from_the_whole_true_state_name_y_not_c(loaded):
    """Issue 23: readings from the (n, 3) truth gave y 3 columns; the guard blamed C."""
    truth, noise = np.arange(30.0).reshape(10, 3), np.ones((10, 1))
    with pytest.raises(StudentCodeError, match=r"y has shape \(10, 3\), 3 columns of readings, "
                                               r"while C \(1, 3\) and R \(1, 1\) are for 1 "
                                               r"sensor: y must be \(n, 1\), one column per "
                                               r"sensor\. Were the readings made from the "
                                               r"whole true state"):
        call(loaded, truth + 1.5 * noise, C2[:1], R2[:1, :1])


def test_the_silent_broadcast_the_guard_prevents_is_real():
    """Unguarded, the same loop runs on the mismatched inputs without an error."""
    namespace = {"np": np}
    exec(SAVED_FILTER, namespace)
    assert call(namespace["my_filter"], Y2[:, :1], C2, R2).shape == (10, 3)


@pytest.mark.parametrize(("arguments", "phrase"), [
    ((Y2[:, 0], A, C2[:1], np.eye(3), R2[:1, :1], np.zeros(3), np.eye(3)),
     r"y has shape \(10,\); it must be \(n, m\)"),
    ((Y2, np.eye(2), C2, np.eye(3), R2, np.zeros(3), np.eye(3)), r"C has shape \(2, 3\)"),
    ((Y2, A, C2, np.eye(3), R2, np.zeros(2), np.eye(3)), r"z0 has shape \(2,\)"),
    ((Y2, A, C2, np.eye(3), R2, np.zeros(3), np.eye(2)), r"P0 has shape \(2, 2\)"),
    ((Y2, A[:2], C2, np.eye(3), R2, np.zeros(3), np.eye(3)), r"A has shape \(2, 3\)"),
])
def test_each_input_of_the_filter_is_named(arguments, phrase):
    assert re.match(phrase, filter_inputs_problem(*arguments))


def test_readings_broadcast_to_n_by_n_are_named_not_c(loaded):
    """Trial 3: truth (n,) + σ noise (n, 1) made y (n, n); the guard blamed C, not y."""
    truth, noise = np.arange(10.0), np.ones((10, 1))
    for R in (R2[:1, :1], 2.25):   # R right, or a number where (1, 1) belongs
        with pytest.raises(StudentCodeError, match=r"y has shape \(10, 10\), one column per "
                                                   r"time step, while C is for 1 sensor: y "
                                                   r"must be \(n, 1\)\. An \(n,\) array"):
            call(loaded, truth + 1.5 * noise, C2[:1], R)
    # A run of as few steps as sensors (n = m <= 3) keeps the C message.
    assert filter_inputs_problem(np.zeros((2, 2)), A, C2[:1], np.eye(3), R2, np.zeros(3),
                                 np.eye(3)).startswith("C has shape (1, 3)")
    # A number for R with vision's one column: no hint about cutting both senses' R.
    assert filter_inputs_problem(Y2[:, :1], A, C2[:1], np.eye(3), 2.25, np.zeros(3),
                                 np.eye(3)).endswith("one row and column per sensor")


@pytest.mark.parametrize(("arguments", "phrase"), [
    ((np.zeros((5, 3)), A, 2), None),
    ((np.zeros(5), A, 2), "estimates has shape (5,); it must be (n, k)"),
    ((np.zeros((5, 3)), np.eye(2), 2), "A has shape (2, 2); for estimates of 3 states"),
    ((np.zeros((5, 3)), A, 0.1), "delay_steps is 0.1; it must be a whole number of samples"),
    ((np.zeros((5, 3)), A, 5), "delay_steps is 5; it must be a whole number"),
    ((np.zeros((5, 3)), A, True), "delay_steps is True"),
])
def test_each_input_of_compensate_is_named(arguments, phrase):
    problem = compensate_inputs_problem(*arguments)
    assert problem == phrase if phrase is None else problem.startswith(phrase)
