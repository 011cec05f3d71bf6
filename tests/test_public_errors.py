"""The errors a student actually meets: each is one ValueError naming the parameter,
the value received and what is allowed (issue 10, "Public API")."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lqe_helpers import experiments, model, prediction
from lqe_helpers.scenario import DEFAULT, Scenario
from lqe_helpers.steady_state import steady_state


def test_track_with_a_bare_string_for_sensors() -> None:
    # Before: "got ('v', 'i', 's', 'i', 'o', 'n')", the string split into letters.
    with pytest.raises(ValueError, match=r"^sensors must be a non-empty sequence of names from "
                                         r"\('vision', 'proprioception'\), e\.g\. \('vision',\), "
                                         r"got the string 'vision': write \('vision',\) with "
                                         r"the comma"):
        experiments.track(DEFAULT, "vision")


def test_measurement_mse_of_a_sensor_the_run_did_not_simulate() -> None:
    # Before: "tuple.index(x): x not in tuple".
    tracking = experiments.track(DEFAULT)
    with pytest.raises(ValueError, match=r"^sensor must be one of the sensors this run "
                                         r"simulated, \('vision',\), got 'proprioception'$"):
        tracking.measurement_mse("proprioception")
    with pytest.raises(ValueError, match=r"got 'touch'$"):
        tracking.measurement_mse("touch")
    # The sensors the run has still work.
    assert tracking.measurement_mse("vision").shape == ()


@pytest.mark.parametrize("empty", [[], (), np.zeros(0), np.zeros((0, 2))])
def test_track_with_an_empty_p0_variance(empty) -> None:
    # Before: numpy's "zero-size array to reduction operation maximum".
    with pytest.raises(ValueError, match=r"^p0_variance must hold at least one number, got an "
                                         r"empty array of shape \(0,( \d)?\)$"):
        experiments.track(DEFAULT, p0_variance=empty)


def test_steady_state_with_the_position_unobserved_says_not_detectable() -> None:
    # Before: "max_doublings = 200 was too few ...; allow more doubling steps", which
    # no number of doublings would cure.
    with pytest.raises(ValueError, match=r"^\(A, C\) must be detectable .*got C = "
                                         r"\[\[0.0, 1.0, 0.0\]\], which cannot see the state "
                                         r"direction\(s\) \[\[1.0, 0.0, 0.0\]\]") as error:
        steady_state(DEFAULT.A, [[0.0, 1.0, 0.0]], DEFAULT.Q, [[1.0]])
    assert "doubling" not in str(error.value)


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("dt", "0.01", r"^dt must be a number > 0 s, got '0.01': text \(write the number "
                       r"without quotes\)$"),
        ("duration", "10", r"^duration must be a number > 0 s, got '10': text"),
        ("sigma_v", "1.5", r"^sigma_v must be a number > 0 cm, got '1.5': text"),
        ("seed", "5", r"^seed must be a whole number >= 0, got '5'$"),
        ("dt", True, r"^dt must be a number > 0 s, got True: a boolean"),
        ("sigma_p", np.True_, r"^sigma_p must be a number > 0 cm, got np.True_: a boolean"),
        ("jerk_std", 1400 + 0j, r"^jerk_std must be a number > 0 cm/s³, got \(1400\+0j\): a "
                                r"complex number \(the imaginary part would be lost\)$"),
        ("z0", (0.0, True, 0.0), r"^z0 must be a numeric array, got \(0.0, True, 0.0\): a "
                                 r"boolean"),
    ],
)
def test_scenario_refuses_text_booleans_and_complex_numbers(field: str, value: object,
                                                            message: str) -> None:
    # Before: Scenario(dt="0.01") raised TypeError from a comparison deep inside.
    with pytest.raises(ValueError, match=message):
        dataclasses.replace(DEFAULT, **{field: value})
    with pytest.raises(ValueError, match=message):
        Scenario(**{field: value})


@pytest.mark.parametrize(
    ("sensors", "message"),
    [
        (None, r"^sensors must be a non-empty sequence of names from \('vision', "
               r"'proprioception'\), e\.g\. \('vision',\), got None$"),
        (7, r"^sensors must be a non-empty sequence of names .* got 7$"),
        ((1, 2), r"^sensors must be distinct names from \('vision', 'proprioception'\), "
                 r"got \(1, 2\)$"),
        ((["vision"],), r"^sensors must be distinct names from .* got \(\['vision'\],\)$"),
    ],
)
def test_observation_matrix_refuses_what_is_not_a_sequence_of_names(sensors, message) -> None:
    # Before: observation_matrix(None) raised "object of type 'NoneType' has no len()".
    with pytest.raises(ValueError, match=message):
        model.observation_matrix(sensors)


def test_observation_matrix_takes_any_sequence_of_names() -> None:
    expected = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    np.testing.assert_array_equal(model.observation_matrix(["vision", "proprioception"]),
                                  expected)
    np.testing.assert_array_equal(model.observation_matrix(s for s in model.SENSORS), expected)
    assert model.sensor_names(["vision"]) == ("vision",)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        # Before: transition_matrix(True) was Δt = 1 s.
        (lambda: model.transition_matrix(True), r"^dt must be a number > 0 s, got True: a boolean"),
        (lambda: model.jerk_input_matrix(np.True_), r"^dt must be a number > 0 s, got np.True_"),
        (lambda: model.process_noise_covariance(0.01, False),
         r"^jerk_std must be a number >= 0 cm/s³, got False: a boolean"),
        (lambda: model.diagonal_covariance(1.0, size=True), r"^size must be a whole number"),
        (lambda: experiments.track(DEFAULT, sigmas=[True]),
         r"^sigmas must be a numeric array, got \[True\]: a boolean"),
        (lambda: experiments.track(DEFAULT, p0_variance=np.array([True, False])),
         r"^p0_variance must be a numeric array, got array\(\[ True, False\]\): a boolean"),
        (lambda: experiments.track(DEFAULT, runs=True), r"^runs must be a whole number >= 1, "
                                                        r"got True$"),
        (lambda: DEFAULT.delay_steps(True), r"^delay must be a number >= 0 s, got True"),
    ],
)
def test_booleans_are_not_numbers(call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: model.transition_matrix(np.complex128(0.01)),
         r"^dt must be a number > 0 s, got np.complex128\(0.01\+0j\): a complex number"),
        (lambda: experiments.track(DEFAULT, sigmas=np.array([1.5 + 0j])),
         r"^sigmas must be a numeric array, got array\(\[1.5\+0.j\]\): a complex number "
         r"\(the imaginary part would be lost\)$"),
        (lambda: experiments.track(DEFAULT, p0_variance=[1.0, 2j]),
         r"^p0_variance must be a numeric array, got \[1.0, 2j\]: a complex number"),
        (lambda: model.measurement_noise_covariance(np.array([1.5, 2.0], dtype=complex)),
         r"^sigmas must be a numeric array, got .*: a complex number"),
        (lambda: prediction.open_loop(DEFAULT, np.array([0, 0, 1j]), np.eye(3), 0.1),
         r"^estimate must be a numeric array, got .*: a complex number"),
    ],
)
def test_complex_input_is_refused_not_truncated(call, message: str) -> None:
    # Before: np.asarray(..., dtype=float) dropped the imaginary part with a warning.
    with pytest.raises(ValueError, match=message):
        call()


def test_open_loop_with_a_batch_of_covariances_gives_one_std_curve_each() -> None:
    # Before: position_stds took covariances[:, 0, 0] and returned shape (batch, 3).
    scales = np.array([0.0, 1.0, 4.0, 9.0])
    starts = scales[:, None, None] * np.eye(3)
    loop = prediction.open_loop(DEFAULT, np.zeros(3), starts, 0.1)
    assert loop.covariances.shape == (4, 11, 3, 3)
    assert loop.position_stds.shape == (4, 11)
    for i, start in enumerate(starts):
        single = prediction.open_loop(DEFAULT, np.zeros(3), start, 0.1)
        assert single.position_stds.shape == (11,)
        np.testing.assert_allclose(loop.position_stds[i], single.position_stds, rtol=1e-14)
    np.testing.assert_allclose(loop.position_stds[:, 0], np.sqrt(scales), rtol=1e-15)
    with pytest.raises(ValueError, match=r"^loop must hold one prediction .* got a batch with "
                                         r"covariances of shape \(4, 11, 3, 3\)"):
        prediction.amplitude_crossing(loop, 10.0)


@pytest.mark.parametrize("delay", [np.float32(0.1), np.float32(0.05), np.float32(0.2),
                                   np.float16(0.1), 0.1, np.float64(0.3)])
def test_delay_of_a_whole_number_of_steps_in_float32_is_accepted(delay) -> None:
    # Before: np.float32(0.1) was refused with a message that itself said "(10 steps)".
    assert DEFAULT.delay_steps(delay) == round(float(delay) / DEFAULT.dt)
    tracking = experiments.track(DEFAULT)
    assert experiments.delay_and_compensate(tracking, delay).steps == round(float(delay) / 0.01)
    loop = prediction.open_loop(DEFAULT, np.zeros(3), np.eye(3), delay)
    assert loop.times.shape == (round(float(delay) / 0.01) + 1,)


@pytest.mark.parametrize(
    ("delay", "message"),
    [
        (0.1000001, r"^delay must be a whole number of time steps dt = 0.01 s, got "
                    r"0.1000001 s \(10.00001 steps\), the nearest whole numbers of steps being "
                    r"0.1 s and 0.11 s$"),
        (np.float32(0.104), r"got 0.104 s \(10.40000021 steps\)"),
        (0.004, r"got 0.004 s \(0.4 steps\), the nearest whole numbers of steps being 0 s and "
                r"0.01 s$"),
    ],
)
def test_delay_that_is_not_a_whole_number_of_steps_says_how_many_it_is(delay,
                                                                      message: str) -> None:
    with pytest.raises(ValueError, match=message):
        DEFAULT.delay_steps(delay)


def test_a_float32_time_step_accepts_float32_times() -> None:
    scenario = Scenario(dt=np.float32(0.01), duration=np.float32(10.0), delay=np.float32(0.1))
    assert scenario.n_steps == 1000
    assert scenario.delay_steps(np.float32(0.1)) == 10


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: experiments.track("DEFAULT"),
         r"^scenario must be a Scenario \(e\.g\. scenario\.DEFAULT\), got str 'DEFAULT'$"),
        (lambda: prediction.open_loop(None, np.zeros(3), np.eye(3), 0.1),
         r"^scenario must be a Scenario \(e\.g\. scenario\.DEFAULT\), got NoneType None$"),
        (lambda: experiments.delay_and_compensate(DEFAULT, 0.1),
         r"^tracking must be a Tracking \(from track\(\)\), got Scenario"),
        (lambda: experiments.delay_and_compensate(experiments.track(DEFAULT), 0.1).mse(["late"]),
         r"^which must be one of \('delayed', 'predicted'\), got \['late'\]$"),
    ],
)
def test_wrong_kind_of_object_is_named(call, message: str) -> None:
    # Before: AttributeError ("'str' object has no attribute 'sigma_v'") or TypeError
    # ("unhashable type: 'list'").
    with pytest.raises(ValueError, match=message):
        call()


def test_bias_model_entry_points_check_the_scenario() -> None:
    from lqe_helpers import bias_model

    for call in (lambda: bias_model.step_accelerations(0.01),
                 lambda: bias_model.unit_noise("DEFAULT"),
                 lambda: bias_model.track_with_input(None)):
        with pytest.raises(ValueError, match=r"^scenario must be a Scenario"):
            call()
