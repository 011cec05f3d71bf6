"""A function check refuses a student's function that only calls the pack's own answer.

The engine ships with the package (the notebooks' Monte Carlo runs need it), so a student
could wrap it: ``def my_filter(...): return kalman_filter(...).estimates``. The checks of
the tasks that ask for that function fail then, naming what was called (through
``student_code.call(forbid=...)``).
"""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails

from lqe_helpers import checks, model, prediction, smoothing
from lqe_helpers.filter import kalman_filter


def wrapped_filter(y, A, C, Q, R, z0, P0):
    return kalman_filter(y, A, C, Q, R, z0, P0).estimates


def wrapped_transition_matrix(dt):
    return model.transition_matrix(dt)


def wrapped_covariance_step(P, F, G, sigma):
    return prediction.propagate_covariance(P, F, sigma**2 * G @ G.T, 1)[-1]


def wrapped_compensation(estimates, A, delay_steps):
    return prediction.predict_ahead(estimates, A, delay_steps)


def wrapped_smoother(y, alpha):
    return smoothing.exponential_smoother(y, alpha)


@pytest.mark.parametrize(("check", "function", "called"), [
    (checks.check_filter, wrapped_filter, "lqe_helpers.filter.kalman_filter"),
    (checks.check_transition_matrix, wrapped_transition_matrix,
     "lqe_helpers.model.transition_matrix"),
    (checks.check_covariance_step, wrapped_covariance_step,
     "lqe_helpers.prediction.propagate_covariance"),
    (checks.check_compensation, wrapped_compensation, "lqe_helpers.prediction.predict_ahead"),
    (checks.check_smoother, wrapped_smoother, "lqe_helpers.smoothing.exponential_smoother"),
])
def test_a_function_that_calls_the_packs_answer_fails_naming_it(check, function, called):
    assert_fails(f"runs the pack's own {called}", check, function)


def test_the_pack_wrapped_would_otherwise_give_the_right_numbers():
    """So the refusal, not a wrong number, is what fails the wrapped functions above."""
    y = np.arange(12.0).reshape(6, 2)
    A, C = np.eye(2), np.eye(2)
    np.testing.assert_array_equal(wrapped_filter(y, A, C, np.eye(2), np.eye(2), np.zeros(2),
                                                 np.eye(2)),
                                  kalman_filter(y, A, C, np.eye(2), np.eye(2), np.zeros(2),
                                                np.eye(2)).estimates)
