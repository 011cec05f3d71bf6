"""Model matrices (Tutorial eq. (4), Lesson 0.5 eqs. (1), (5), (9))."""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import model


def test_transition_matrix_integrates_constant_acceleration_exactly() -> None:
    dt, p, v, a = 0.01, 2.0, -3.0, 40.0
    A = model.transition_matrix(dt)
    expected = [p + v * dt + a * dt**2 / 2, v + a * dt, a]
    np.testing.assert_allclose(A @ [p, v, a], expected, rtol=1e-15)
    # Two steps of dt equal one step of 2 dt (a group property of exact integration).
    np.testing.assert_allclose(A @ A, model.transition_matrix(2 * dt), rtol=1e-14)


def test_jerk_input_is_the_exact_integral_of_a_held_jerk() -> None:
    dt, jerk = 0.2, 7.0
    G = model.jerk_input_matrix(dt)
    # p(t) = j t³/6, v = j t²/2, a = j t from rest: exact at t = dt.
    np.testing.assert_allclose(G[:, 0] * jerk, [jerk * dt**3 / 6, jerk * dt**2 / 2, jerk * dt])


def test_process_noise_is_g_sigma2_gt_and_matches_monte_carlo() -> None:
    dt, sigma = 0.01, 1400.0
    Q = model.process_noise_covariance(dt, sigma)
    G = model.jerk_input_matrix(dt)
    np.testing.assert_allclose(Q, sigma**2 * G @ G.T)
    assert np.linalg.matrix_rank(Q) == 1
    # Independent check: the empirical covariance of G·(σ ξ) for ξ ~ N(0, 1).
    rng = np.random.default_rng(0)
    kicks = (G @ (sigma * rng.standard_normal((1, 200_000)))).T
    np.testing.assert_allclose(np.cov(kicks.T), Q, rtol=0.02)


def test_observation_and_noise_matrices() -> None:
    np.testing.assert_array_equal(model.observation_matrix(), [[1.0, 0.0, 0.0]])
    np.testing.assert_array_equal(
        model.observation_matrix(("vision", "proprioception")), [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
    )
    np.testing.assert_array_equal(
        model.measurement_noise_covariance([1.5, 4.5]), [[2.25, 0.0], [0.0, 20.25]]
    )
    sweep = model.measurement_noise_covariance(np.array([[1.0, 2.0], [3.0, 4.0]]))
    assert sweep.shape == (2, 2, 2)
    np.testing.assert_array_equal(sweep[1], np.diag([9.0, 16.0]))
    np.testing.assert_array_equal(model.diagonal_covariance(1e5), 1e5 * np.eye(3))
    assert model.diagonal_covariance(np.array([1.0, 2.0])).shape == (2, 3, 3)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: model.transition_matrix(0.0), "dt must be a finite number > 0 s, got 0.0"),
        (lambda: model.transition_matrix(-0.01), "dt must be a finite number > 0 s, got -0.01"),
        (lambda: model.transition_matrix(float("nan")), "dt must be a finite number > 0 s"),
        (lambda: model.transition_matrix("fast"), "dt must be a number > 0 s, got 'fast'"),
        (
            lambda: model.process_noise_covariance(0.01, -1.0),
            "jerk_std must be a finite number >= 0",
        ),
        (lambda: model.observation_matrix(("eyes",)), "sensors must be distinct names from"),
        (lambda: model.observation_matrix("vision"), "sensors must be a non-empty sequence"),
        (lambda: model.observation_matrix(()), "sensors must be a non-empty sequence"),
        (lambda: model.observation_matrix(("vision", "vision")), "sensors must be distinct"),
        (lambda: model.measurement_noise_covariance([1.5, -1.5]), "sigmas must all be > 0 cm"),
        (lambda: model.measurement_noise_covariance([1.5, 0.0]), "sigmas must all be > 0 cm"),
        (lambda: model.measurement_noise_covariance([np.inf]), "sigmas must contain only finite"),
        (lambda: model.diagonal_covariance(-1.0), "variance must be > 0, got [-1.0]"),
        (lambda: model.diagonal_covariance(1.0, size=0), "size must be a whole number >= 1"),
    ],
)
def test_bad_input_names_parameter_value_and_rule(call, message: str) -> None:
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")):
        call()
