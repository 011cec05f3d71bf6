"""Prediction past a delay (Tutorial eq. (7)) and open-loop covariance growth."""

from __future__ import annotations

import re

import numpy as np
import pytest

from lqe_helpers import model, prediction
from lqe_helpers.prediction import predict_ahead, propagate_covariance
from lqe_helpers.scenario import DEFAULT


def test_predict_ahead_applies_a_power_to_older_estimates() -> None:
    A = model.transition_matrix(0.01)
    rng = np.random.default_rng(0)
    estimates = rng.normal(size=(2, 30, 3))
    out = predict_ahead(estimates, A, 10)
    assert out.shape == estimates.shape
    assert np.all(np.isnan(out[:, :10]))
    A10 = A
    for _ in range(9):
        A10 = A10 @ A
    np.testing.assert_allclose(out[:, 10:], estimates[:, :20] @ A10.T, rtol=1e-12)
    np.testing.assert_array_equal(predict_ahead(estimates, A, 0), estimates)


def test_prediction_of_a_constant_acceleration_path_is_exact() -> None:
    dt = 0.01
    t = np.arange(100) * dt
    states = np.stack([3 + 2 * t + 5 * t**2, 2 + 10 * t, np.full_like(t, 10.0)], axis=-1)
    out = predict_ahead(states, model.transition_matrix(dt), 25)
    np.testing.assert_allclose(out[25:], states[25:], rtol=1e-12)


def test_propagate_covariance_matches_hand_recursion_and_grows() -> None:
    dt = 0.01
    A, Q = model.transition_matrix(dt), model.process_noise_covariance(dt, 100.0)
    P = propagate_covariance(np.eye(3), A, Q, 50)
    assert P.shape == (51, 3, 3)
    expected = np.eye(3)
    for _ in range(50):
        expected = A @ expected @ A.T + Q
    np.testing.assert_allclose(P[-1], expected, rtol=1e-12)
    assert np.all(np.diff(P[:, 0, 0]) > 0)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: predict_ahead(np.zeros((5, 3)), np.eye(3), 5),
            r"steps must be a whole number in \[0, 4\], got 5",
        ),
        (lambda: predict_ahead(np.zeros((5, 3)), np.eye(3), -1), "steps must be a whole number"),
        (
            lambda: predict_ahead(np.zeros((5, 3)), np.eye(2), 1),
            r"A must have trailing shape \(3, 3\)",
        ),
        (
            lambda: predict_ahead(np.full((5, 3), np.nan), np.eye(3), 1),
            "estimates must contain only finite",
        ),
        (
            lambda: propagate_covariance(-np.eye(3), np.eye(3), np.eye(3), 2),
            "P0 must be positive semidefinite",
        ),
        (
            lambda: propagate_covariance(np.eye(3), np.eye(3), np.eye(3), -2),
            "steps must be a whole number >= 0",
        ),
    ],
)
def test_bad_input(call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()


def test_open_loop_follows_the_model() -> None:
    estimate = np.array([1.0, -20.0, 50.0])
    P = np.diag([0.5, 4.0, 100.0])
    loop = prediction.open_loop(DEFAULT, estimate, P, 0.2)
    assert loop.times.shape == (21,)
    A = DEFAULT.A
    np.testing.assert_allclose(loop.means[-1], np.linalg.matrix_power(A, 20) @ estimate)
    # Constant acceleration from the start: p = p0 + v t + a t² / 2 exactly.
    t = loop.times
    np.testing.assert_allclose(loop.means[:, 0], 1.0 - 20.0 * t + 25.0 * t**2, atol=1e-12)
    expected = P
    for _ in range(20):
        expected = A @ expected @ A.T + DEFAULT.Q
    np.testing.assert_allclose(loop.covariances[-1], expected, rtol=1e-12)
    assert np.all(np.diff(loop.position_stds) > 0)


def test_open_loop_from_a_known_start_grows_as_t_to_five_halves() -> None:
    loop = prediction.open_loop(DEFAULT, np.zeros(3), np.zeros((3, 3)), 1.0)
    t, std = loop.times[50:], loop.position_stds[50:]
    slope = np.polyfit(np.log(t), np.log(std), 1)[0]
    assert slope == pytest.approx(2.5, abs=0.02)


def test_bad_open_loop_input_is_rejected_by_name() -> None:
    with pytest.raises(ValueError, match="estimate"):
        prediction.open_loop(DEFAULT, np.zeros(2), np.eye(3), 1.0)
    with pytest.raises(ValueError, match="duration"):
        prediction.open_loop(DEFAULT, np.zeros(3), np.eye(3), 0.0)
    # Less than a step, or between two steps: refused rather than rounded.
    with pytest.raises(ValueError, match=r"duration must be a whole number of time steps "
                                         r"dt = 0.01 s, got 0.004 s \(0.4 steps\)"):
        prediction.open_loop(DEFAULT, np.zeros(3), np.eye(3), 0.004)
    with pytest.raises(ValueError, match="duration must be a whole number of time steps"):
        prediction.open_loop(DEFAULT, np.zeros(3), np.eye(3), 0.255)
    # Whole steps up to floating-point rounding are accepted.
    assert prediction.open_loop(DEFAULT, np.zeros(3), np.eye(3), 0.3).times.shape == (31,)


def test_amplitude_crossing() -> None:
    loop = prediction.open_loop(DEFAULT, np.zeros(3), np.zeros((3, 3)), 1.0)
    crossing = prediction.amplitude_crossing(loop, 1.0)
    first = int(np.argmax(2 * loop.position_stds >= 1.0))
    assert crossing == pytest.approx(loop.times[first])
    assert 2 * loop.position_stds[first - 1] < 1.0
    assert prediction.amplitude_crossing(loop, 1e6) is None


@pytest.mark.parametrize(
    ("loop", "amplitude", "message"),
    [
        (None, 10.0, "loop must be an OpenLoop from open_loop(), got NoneType"),
        ("open", -10.0, "amplitude must be a finite number > 0 cm, got -10.0"),
        ("open", 0.0, "amplitude must be a finite number > 0 cm, got 0.0"),
        ("open", "ten", "amplitude must be a number > 0 cm, got 'ten'"),
    ],
)
def test_amplitude_crossing_bad_input(loop, amplitude, message: str) -> None:
    if loop == "open":
        loop = prediction.open_loop(DEFAULT, np.zeros(3), np.zeros((3, 3)), 0.5)
    with pytest.raises(ValueError, match=re.escape(message)):
        prediction.amplitude_crossing(loop, amplitude)
