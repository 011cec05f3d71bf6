"""The experiment builders the notebooks and explorers share."""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import experiments, model, simulation
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT

FUSED = ("vision", "proprioception")


def test_track_equals_the_filter_on_hand_built_inputs() -> None:
    tracking = experiments.track(DEFAULT, sensors=FUSED, sigmas=[1.5, 4.5])
    noise = DEFAULT.unit_noise()
    y = DEFAULT.truth[:, :1] + noise * [1.5, 4.5]
    direct = kalman_filter(
        y,
        DEFAULT.A,
        model.observation_matrix(FUSED),
        DEFAULT.Q,
        np.diag([2.25, 20.25]),
        np.zeros(3),
        np.eye(3),
    )
    np.testing.assert_array_equal(tracking.measurements, y)
    np.testing.assert_allclose(tracking.result.estimates, direct.estimates, rtol=1e-12)


def test_single_run_is_run_zero_of_the_monte_carlo_batch() -> None:
    single = experiments.track(DEFAULT)
    batch = experiments.track(DEFAULT, runs=5)
    np.testing.assert_allclose(batch.positions[0], single.positions, rtol=1e-12)


def test_sigma_sweep_is_one_call_matching_separate_calls() -> None:
    sweep = np.stack([np.full(3, 1.5), [0.5, 4.5, 50.0]], axis=-1)
    batched = experiments.track(DEFAULT, sensors=FUSED, sigmas=sweep, runs=4)
    assert batched.positions.shape == (4, 3, DEFAULT.n_steps)
    for s, sigmas in enumerate(sweep):
        one = experiments.track(DEFAULT, sensors=FUSED, sigmas=sigmas, runs=4)
        np.testing.assert_allclose(batched.positions[:, s], one.positions, rtol=1e-10, atol=1e-10)


def test_assumed_sigmas_change_the_filter_not_the_data() -> None:
    right = experiments.track(DEFAULT, sensors=FUSED, sigmas=[1.5, 4.5])
    wrong = experiments.track(DEFAULT, sensors=FUSED, sigmas=[1.5, 4.5], assumed_sigmas=[1.5, 1.5])
    np.testing.assert_array_equal(right.measurements, wrong.measurements)
    assert not np.allclose(right.positions, wrong.positions)


def test_delay_and_compensate_shifts_and_predicts() -> None:
    tracking = experiments.track(DEFAULT, runs=3)
    delayed = experiments.delay_and_compensate(tracking, 0.1)
    assert delayed.steps == 10
    np.testing.assert_array_equal(
        delayed.delayed_estimates[:, 10:], tracking.result.estimates[:, :-10]
    )
    np.testing.assert_array_equal(
        delayed.delayed_measurements, simulation.delay_signal(tracking.measurements, 10)
    )
    A10 = np.linalg.matrix_power(DEFAULT.A, 10)
    np.testing.assert_allclose(
        delayed.predictions[:, 10:], tracking.result.estimates[:, :-10] @ A10.T, rtol=1e-12
    )
    assert delayed.mse("predicted").shape == (3,)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: experiments.track(DEFAULT, sigmas=[1.5, 1.5]),
            "sigmas must have one σ per sensor",
        ),
        (
            lambda: experiments.track(DEFAULT, sensors=FUSED, assumed_sigmas=[1.5]),
            "assumed_sigmas must have one σ per sensor",
        ),
        (
            lambda: experiments.track(DEFAULT, sigmas=[-1.5]),
            r"sigmas must all be > 0 cm, got \[-1.5\]",
        ),
        (
            lambda: experiments.track(DEFAULT, sensors=FUSED, assumed_sigmas=[1.5, -1.0]),
            r"assumed_sigmas must all be > 0 cm, got \[1.5, -1.0\]",
        ),
        (
            lambda: experiments.track(DEFAULT, sigmas=[[1.5], [1.5], [0.0], [1.5], [1.5]]),
            r"sigmas must all be > 0 cm, got an array of shape \(5, 1\) whose smallest entry is 0",
        ),
        (
            lambda: experiments.track(DEFAULT, p0_variance=-1.0),
            "p0_variance must be > 0 cm², got -1.0",
        ),
        (
            lambda: experiments.track(DEFAULT, p0_variance=[1.0, np.nan]),
            "p0_variance must contain only finite numbers",
        ),
        (
            lambda: experiments.track(DEFAULT, p0_variance="large"),
            "p0_variance must be a numeric array, got 'large'",
        ),
        (
            lambda: experiments.track(DEFAULT, runs=3, noise=np.zeros((2, 1000, 1))),
            r"noise must have shape \(3, 1000, 1\) \(vision\), got shape \(2, 1000, 1\)",
        ),
        (
            lambda: experiments.track(DEFAULT, sensors=FUSED, noise=np.zeros(1000)),
            r"noise must have shape \(1000, 2\) \(vision, proprioception\), got shape \(1000,\)",
        ),
        (lambda: experiments.track(DEFAULT, sensors=("smell",)), "sensors must be distinct names"),
        (
            lambda: experiments.delay_and_compensate(experiments.track(DEFAULT), 0.013),
            "delay must be a whole number of time steps",
        ),
        (
            lambda: experiments.delay_and_compensate(experiments.track(DEFAULT), 0.1).mse("late"),
            "which must be one of",
        ),
    ],
)
def test_bad_input(call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()
