"""Truth, noise draws, measurements and delays."""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import simulation
from lqe_helpers.scenario import DEFAULT


def test_sinusoid_states_are_exact_derivatives() -> None:
    t = np.linspace(0.0, 3.0, 3001)
    states = simulation.sinusoid_states(t, 10.0, 0.5)
    # Central differences of the analytic position agree with the analytic v and a.
    h = 1e-5
    p = lambda s: simulation.sinusoid_states(s, 10.0, 0.5)[:, 0]  # noqa: E731
    np.testing.assert_allclose((p(t + h) - p(t - h)) / (2 * h), states[:, 1], atol=1e-5)
    np.testing.assert_allclose((p(t + h) - 2 * p(t) + p(t - h)) / h**2, states[:, 2], atol=1e-2)
    np.testing.assert_allclose(states[0], [0.0, 10.0 * np.pi, 0.0], atol=1e-12)


def test_unit_noise_is_standard_normal_and_independent_per_sensor() -> None:
    noise = simulation.unit_noise(np.random.default_rng(1), 20_000, 2, runs=5)
    assert noise.shape == (5, 20_000, 2)
    flat = noise.reshape(-1, 2)
    np.testing.assert_allclose(flat.mean(axis=0), 0.0, atol=0.01)
    np.testing.assert_allclose(flat.std(axis=0), 1.0, atol=0.01)
    assert abs(np.corrcoef(flat.T)[0, 1]) < 0.01


def test_vision_noise_does_not_depend_on_other_sensors_or_run_count() -> None:
    one = simulation.unit_noise(np.random.default_rng(3), 100, 1)
    two = simulation.unit_noise(np.random.default_rng(3), 100, 2)
    many = simulation.unit_noise(np.random.default_rng(3), 100, 2, runs=7)
    np.testing.assert_array_equal(one[:, 0], two[:, 0])
    np.testing.assert_array_equal(many[0], two)


def test_measure_scales_the_fixed_draw_by_sigma() -> None:
    positions = np.arange(5.0)
    noise = np.ones((5, 2))
    np.testing.assert_array_equal(
        simulation.measure(positions, noise, [1.5, 4.5]),
        np.stack([positions + 1.5, positions + 4.5], axis=-1),
    )
    sweep = simulation.measure(positions, noise, np.array([[1.0, 1.0], [2.0, 3.0]]))
    assert sweep.shape == (2, 5, 2)
    np.testing.assert_array_equal(sweep[1, :, 1], positions + 3.0)


def test_delay_signal_shifts_and_pads_with_nan() -> None:
    x = np.arange(12.0).reshape(6, 2)
    out = simulation.delay_signal(x, 2)
    assert np.all(np.isnan(out[:2]))
    np.testing.assert_array_equal(out[2:], x[:4])
    np.testing.assert_array_equal(simulation.delay_signal(x, 0), x)
    trace = simulation.delay_signal(np.arange(4.0), 1, axis=-1)
    np.testing.assert_array_equal(trace[1:], [0.0, 1.0, 2.0])


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: simulation.delay_signal(np.zeros((5, 1)), -1), "steps must be a whole number in"),
        (
            lambda: simulation.delay_signal(np.zeros((5, 1)), 5),
            r"steps must be a whole number in \[0, 4\], got 5",
        ),
        (lambda: simulation.delay_signal(np.zeros((5, 1)), 1.5), "steps must be a whole number"),
        (lambda: simulation.delay_signal(np.zeros(5), 1, axis=3), "axis must name an axis"),
        (lambda: simulation.delay_signal(np.zeros(5), 1),
         r"got -2 \(a single trace of shape \(n,\) has only axis -1 = 0: pass axis=-1"),
        (lambda: simulation.delay_signal(np.zeros(5), 1, axis="time"),
         r"axis must name an axis of signal with shape \(5,\), got 'time'"),
        (lambda: simulation.delay_signal(np.zeros(5), 1, axis=True),
         r"axis must name an axis of signal with shape \(5,\), got True"),
        (
            lambda: simulation.delay_signal(["a", "b"], 1, axis=-1),
            r"signal must be a numeric array, got \['a', 'b'\]",
        ),
        (
            lambda: simulation.delay_signal(2.0, 0),
            "signal must have a time axis, got a scalar 2.0",
        ),
        (
            lambda: simulation.simulate_model_states(
                np.random.default_rng(0), np.eye(3)[None], np.eye(3), np.zeros(3), np.eye(3),
                5, 2),
            r"A must have shape \(k, k\), got shape \(1, 3, 3\)",
        ),
        (
            lambda: simulation.simulate_model_states(
                np.random.default_rng(0), np.eye(3), np.eye(3), np.zeros(2), np.eye(3), 5, 2),
            r"mean0 must have shape \(3,\) like A, got shape \(2,\)",
        ),
        (
            lambda: simulation.simulate_model_states(
                np.random.default_rng(0), np.eye(3), np.eye(3)[None], np.zeros(3), np.eye(3),
                5, 2),
            r"Q must have shape \(3, 3\), got shape \(1, 3, 3\)",
        ),
        (
            lambda: simulation.simulate_model_states(
                np.random.default_rng(0), np.eye(3), np.eye(3), np.zeros(3), np.eye(3)[None],
                5, 2),
            r"P0 must have shape \(3, 3\), got shape \(1, 3, 3\)",
        ),
        (
            lambda: simulation.simulate_model_states(
                np.random.default_rng(0), np.eye(3), np.eye(3), np.zeros(3), np.eye(3), 0, 2),
            "n_steps must be a whole number >= 1, got 0",
        ),
        (
            lambda: simulation.unit_noise(np.random.RandomState(0), 5, 1),
            "rng must be a numpy.random.Generator",
        ),
        (
            lambda: simulation.unit_noise(np.random.default_rng(0), 0, 1),
            "n_steps must be a whole number >= 1, got 0",
        ),
        (lambda: simulation.measure(np.zeros(4), np.zeros((5, 1)), [1.0]), "must agree on n and m"),
        (
            lambda: simulation.measure(np.zeros(5), np.zeros((5, 1)), [-1.0]),
            "sigmas must all be > 0 cm",
        ),
        (
            lambda: simulation.sinusoid_states(np.arange(3.0), 0.0, 1.0),
            "amplitude must be a finite number > 0 cm",
        ),
        (
            lambda: simulation.sinusoid_states([0.0, np.nan], 1.0, 1.0),
            "times must contain only finite",
        ),
    ],
)
def test_bad_input(call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()


def test_scenario_noise_matches_between_single_run_and_monte_carlo() -> None:
    single = DEFAULT.unit_noise()
    batch = DEFAULT.unit_noise(runs=4)
    np.testing.assert_array_equal(batch[0], single)
    vision_only = DEFAULT.unit_noise(sensors=("vision",))
    np.testing.assert_array_equal(vision_only[:, 0], single[:, 0])


def test_delay_signal_passes_nan_through() -> None:
    out = simulation.delay_signal([np.nan, 1.0, 2.0], 1, axis=-1)
    assert np.all(np.isnan(out[:2]))
    assert out[2] == 1.0


def test_model_states_follow_the_model() -> None:
    A = np.array([[1.0, 0.1], [0.0, 1.0]])
    mean0 = np.array([2.0, -1.0])
    # No noise at all: the mean path A^(j+1) mean0 exactly.
    quiet = simulation.simulate_model_states(np.random.default_rng(0), A, np.zeros((2, 2)),
                                             mean0, np.zeros((2, 2)), 4, 3)
    expected = [np.linalg.matrix_power(A, j + 1) @ mean0 for j in range(4)]
    np.testing.assert_allclose(quiet, np.broadcast_to(expected, (3, 4, 2)), rtol=1e-14)
    # One kick per transition, each with covariance Q; a single sample has none.
    Q = np.array([[1.0, 0.3], [0.3, 0.5]])
    states = simulation.simulate_model_states(np.random.default_rng(1), A, Q, mean0,
                                              np.zeros((2, 2)), 3, 20_000)
    kicks = states[:, 1:] - states[:, :-1] @ A.T
    np.testing.assert_allclose(np.cov(kicks.reshape(-1, 2).T), Q, atol=0.03)
    one = simulation.simulate_model_states(np.random.default_rng(1), A, Q, mean0, np.eye(2),
                                           1, 5)
    assert one.shape == (5, 1, 2)
