"""The experiment builders the notebooks and explorers share."""

from __future__ import annotations

import dataclasses

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


# --- filter_model: the one builder of the model a filter assumes ---

def _hand_built(dt: float, jerk_std: float, sigmas: list[float], p0: float) -> dict:
    """Tutorial eqs. (3)-(6) and Lesson 0.5 eq. (9) written out for the butterfly."""
    g = np.array([[dt**3 / 6], [dt**2 / 2], [dt]])
    return {
        "A": np.array([[1.0, dt, dt**2 / 2], [0.0, 1.0, dt], [0.0, 0.0, 1.0]]),
        "C": np.array([[1.0, 0.0, 0.0]] * len(sigmas)),
        "Q": jerk_std**2 * g @ g.T,
        "R": np.diag(np.square(sigmas)),
        "z0": np.zeros(3),
        "P0": p0 * np.eye(3),
    }


@pytest.mark.parametrize(("sensors", "sigmas", "p0"),
                         [(("vision",), None, None), (FUSED, [1.5, 4.5], 1e5)])
def test_filter_model_equals_the_matrices_written_out(sensors, sigmas, p0) -> None:
    built = experiments.filter_model(DEFAULT, sensors, sigmas, p0)
    expected = _hand_built(DEFAULT.dt, DEFAULT.process_jerk_std,
                           sigmas or [DEFAULT.sigma_v], p0 or DEFAULT.p0_variance)
    for name, matrix in expected.items():
        np.testing.assert_allclose(getattr(built, name), matrix, rtol=1e-12, atol=0,
                                   err_msg=name)
    assert built.B is None
    for name in expected:
        assert not getattr(built, name).flags.writeable, name


def test_filter_model_sweeps_sigma_and_p0_together() -> None:
    built = experiments.filter_model(DEFAULT, FUSED, [[1.5, 0.5], [1.5, 50.0]],
                                     np.array([[1.0], [1e5]]))
    assert built.R.shape == (2, 2, 2) and built.P0.shape == (2, 1, 3, 3)
    np.testing.assert_array_equal(built.R[1], np.diag([2.25, 2500.0]))
    with pytest.raises(ValueError, match="sigmas"):
        experiments.filter_model(DEFAULT, FUSED, [[1.5, 0.5]] * 3, np.ones(2))


def test_the_tracking_keeps_the_model_its_filter_assumed() -> None:
    tracking = experiments.track(DEFAULT, FUSED, sigmas=[1.5, 4.5], assumed_sigmas=[1.5, 1.5],
                                 p0_variance=10.0)
    assumed = experiments.filter_model(DEFAULT, FUSED, [1.5, 1.5], 10.0)
    for name in ("A", "C", "Q", "R", "z0", "P0"):
        np.testing.assert_array_equal(getattr(tracking.model, name), getattr(assumed, name))
    rerun = tracking.model.filter(tracking.measurements)
    np.testing.assert_array_equal(rerun.estimates, tracking.result.estimates)


def test_steady_state_of_the_model_is_where_the_filter_settles() -> None:
    tracking = experiments.track(DEFAULT, FUSED, sigmas=[1.5, 4.5])
    settled = tracking.model.steady_state()
    # Independent of the doubling algorithm: 1 000 steps of the filter's own recursion.
    np.testing.assert_allclose(settled.estimate_covariance,
                               tracking.result.estimate_covariances[-1], rtol=1e-9)
    np.testing.assert_allclose(settled.gain, tracking.result.gains[-1], rtol=1e-9)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [({"scenario": "DEFAULT"}, r"^scenario must be a Scenario"),
     ({"sensors": "vision"}, r"^sensors must be a non-empty sequence"),
     ({"sigmas": [1.5, 1.5]}, r"^sigmas must have one σ per sensor \('vision',\)"),
     ({"sigmas": [0.0]}, r"^sigmas must all be > 0 cm"),
     ({"sigmas": [True]}, r"^sigmas must be a numeric array, got \[True\]: a boolean"),
     ({"p0_variance": -1.0}, r"^p0_variance must be > 0 cm², got -1.0")],
)
def test_filter_model_refuses_bad_input_by_name(arguments, message) -> None:
    call = {"scenario": DEFAULT, **arguments}
    with pytest.raises(ValueError, match=message):
        experiments.filter_model(call.pop("scenario"), **call)


# --- results that draw themselves ---

def test_tracking_figure_draws_this_run_its_readings_and_the_runs_compared() -> None:
    import matplotlib.pyplot as plt

    vision = experiments.track(DEFAULT)
    fused = experiments.track(DEFAULT, FUSED)
    fig = fused.figure("vision + proprioception", against={"vision only": vision},
                       title="σ_v = σ_p = 1.5 cm")
    try:
        top, bottom = fig.axes
        lines = {line.get_label(): line for line in top.get_lines()}
        assert list(lines) == ["vision readings", "proprioception readings", "true position",
                               "vision only", "vision + proprioception"]
        np.testing.assert_array_equal(lines["proprioception readings"].get_ydata(),
                                      fused.measurements[:, 1])
        np.testing.assert_array_equal(lines["vision only"].get_ydata(), vision.positions)
        np.testing.assert_array_equal(lines["vision + proprioception"].get_ydata(),
                                      fused.positions)
        assert lines["vision only"].get_linestyle() == "-."  # the alternative's role
        errors = {line.get_label(): line.get_ydata() for line in bottom.get_lines()}
        np.testing.assert_allclose(errors["vision + proprioception"],
                                   fused.positions - DEFAULT.truth[:, 0])
        assert top.get_title() == "σ_v = σ_p = 1.5 cm"
    finally:
        plt.close(fig)


@pytest.mark.slow
def test_tracking_figure_equals_the_figure_drawn_from_its_arrays() -> None:
    """What notebook 01 draws today from six arrays, from the one object."""
    import matplotlib.pyplot as plt
    from explorer_checks import png

    from lqe_helpers import figures

    batch = experiments.track(DEFAULT, sigmas=[[1.5], [4.5]], runs=3)
    by_arrays = figures.tracking_comparison_figure(
        DEFAULT.times, DEFAULT.truth[:, 0], {"filtered estimate": (batch.positions[2, 1],
                                                                   "estimate")},
        readings={"vision readings": (batch.measurements[2, 1, :, 0], "vision")},
        title="σ_v = 4.5 cm")
    by_object = batch.figure(run=(2, 1), title="σ_v = 4.5 cm")
    try:
        assert png(by_object, dpi=40) == png(by_arrays, dpi=40)
    finally:
        plt.close(by_arrays)
        plt.close(by_object)


@pytest.mark.slow
def test_delayed_tracking_figure_equals_the_figure_drawn_from_its_arrays() -> None:
    """Notebook 05's Figure 1: ``delayed.figure()`` instead of six arrays."""
    import matplotlib.pyplot as plt
    from explorer_checks import png

    from lqe_helpers import figures

    delayed = experiments.delay_and_compensate(experiments.track(DEFAULT), 0.1)
    assert delayed.delay == pytest.approx(0.1)
    by_arrays = figures.delay_figure(DEFAULT.times, DEFAULT.truth[:, 0],
                                     delayed.delayed_measurements[:, 0],
                                     delayed.delayed_estimates[:, 0],
                                     delayed.predictions[:, 0], 0.1)
    by_object = delayed.figure()
    try:
        assert png(by_object, dpi=40) == png(by_arrays, dpi=40)
        assert by_object.axes[0].get_title() == "Vision delayed by d = 0.1 s: the whole trial"
    finally:
        plt.close(by_arrays)
        plt.close(by_object)


def test_result_figures_refuse_what_they_cannot_draw() -> None:
    batch = experiments.track(DEFAULT, runs=3)
    with pytest.raises(ValueError, match=r"run must pick one run of the leading axes \(3,\)"):
        batch.figure()
    with pytest.raises(ValueError, match="run must pick one run"):
        batch.figure(run=7)
    other = experiments.track(dataclasses.replace(DEFAULT, seed=7))
    with pytest.raises(ValueError, match="against must map labels to at most 2 Trackings of "
                                         "this scenario"):
        experiments.track(DEFAULT).figure(against={"other seed": other})
    with pytest.raises(ValueError, match="against must map"):
        experiments.track(DEFAULT).figure(against={"a": "not a tracking"})
    with pytest.raises(ValueError, match="delay must be > 0 s"):
        experiments.delay_and_compensate(experiments.track(DEFAULT), 0.0).figure()
    with pytest.raises(ValueError, match="run must pick one run"):
        experiments.delay_and_compensate(batch, 0.1).figure()


def test_innovations_are_each_reading_minus_the_filters_prediction_of_it() -> None:
    """Against a hand loop: e_j = y_j − C A ẑ_{j−1} (ẑ_{−1} = z0), S_j = C P_j Cᵀ + R."""
    scenario = dataclasses.replace(DEFAULT, duration=0.5, burn_in=0.1)
    tracking = experiments.track(scenario, ("vision", "proprioception"), sigmas=[1.5, 4.5])
    innovations = tracking.innovations()
    fm = tracking.model
    previous = fm.z0
    for j, y_j in enumerate(tracking.measurements):
        expected = y_j - fm.C @ fm.A @ previous
        np.testing.assert_allclose(innovations.values[j], expected, rtol=0, atol=1e-12)
        previous = tracking.result.estimates[j]
    np.testing.assert_allclose(innovations.covariances[0], fm.C @ fm.P0 @ fm.C.T + fm.R,
                               rtol=1e-12)


@pytest.mark.parametrize(("sensors", "sigmas"), [(("vision",), None),
                                                 (("vision", "proprioception"), [1.5, 4.5])])
def test_readings_are_the_truth_plus_sigma_times_the_draw_and_tracks_measurements(sensors, sigmas):
    """experiments.readings: eq. (3) on the scenario's draw, written out here, and the
    same y that track filters (03's and 04's given readings, without a model to copy)."""
    expected_sigmas = np.array(sigmas if sigmas is not None
                               else [DEFAULT.sigma_v])
    by_hand = (DEFAULT.truth[:, 0][:, None]
               + expected_sigmas[None, :] * DEFAULT.unit_noise(sensors=sensors))
    y = experiments.readings(DEFAULT, sensors, sigmas)
    np.testing.assert_allclose(y, by_hand, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(y, experiments.track(DEFAULT, sensors, sigmas).measurements)


@pytest.mark.parametrize(("arguments", "message"), [
    ((DEFAULT, ("vision",), [[1.5], [4.5]]), "sigmas must be one σ per sensor"),
    ((DEFAULT, ("vision",), [-1.0]), "sigmas"),
    (("DEFAULT",), "scenario"),
])
def test_readings_refuse_bad_input_by_name(arguments, message) -> None:
    with pytest.raises(ValueError, match=message):
        experiments.readings(*arguments)
