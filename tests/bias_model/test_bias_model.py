"""The biased-input model of Lesson 0.5 and the experiment of notebook 06."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
from explorer_checks import pngs, same_png

from lqe_helpers import bias_model, experiments, metrics, simulation
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT

DEFAULT_BIAS = bias_model.DEFAULT_BIAS


@pytest.mark.parametrize("dt", [0.01, 0.1, 0.5])
def test_matrices_are_lesson_eq_5(dt: float) -> None:
    F = bias_model.transition_matrix(dt)
    G = bias_model.input_matrix(dt)
    np.testing.assert_array_equal(
        F, [[1.0, dt, -dt**2 / 2], [0.0, 1.0, -dt], [0.0, 0.0, 1.0]])
    np.testing.assert_array_equal(G, [[dt**2 / 2], [dt], [0.0]])


def test_one_step_is_lesson_eq_2() -> None:
    """F ẑ + G a_r written out: the bias estimate is removed from the reading."""
    dt, (p, v, b), reading = 0.02, (3.0, -4.0, 7.0), 12.5
    z = bias_model.transition_matrix(dt) @ [p, v, b] + bias_model.input_matrix(dt)[:, 0] * reading
    np.testing.assert_allclose(z, [p + dt * v + dt**2 / 2 * (reading - b),
                                   v + dt * (reading - b),
                                   b], rtol=1e-14)


def test_process_noise_is_lesson_eq_9() -> None:
    dt, sigma_a = 0.01, 20.0
    Q = bias_model.process_noise_covariance(dt, sigma_a)
    G = bias_model.input_matrix(dt)
    np.testing.assert_allclose(Q, G @ G.T * sigma_a**2, rtol=1e-15)
    assert Q[0, 0] == pytest.approx(sigma_a**2 * dt**4 / 4)
    assert Q[1, 1] == pytest.approx(sigma_a**2 * dt**2)
    # The bias is not driven by the signal's noise, and one noise drives p and v.
    np.testing.assert_array_equal(Q[2], 0.0)
    np.testing.assert_array_equal(Q[:, 2], 0.0)
    assert np.linalg.matrix_rank(Q) == 1


def test_noise_free_unbiased_dead_reckoning_follows_the_path() -> None:
    """With the step-mean acceleration the model integrates the sinusoid exactly."""
    accelerations = bias_model.step_accelerations(DEFAULT)
    start = bias_model.initial_state(DEFAULT, 0.0)
    track = bias_model.dead_reckoning(accelerations, start, DEFAULT.dt)
    np.testing.assert_allclose(track[:, 1], DEFAULT.truth[:, 1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(track[:, 0], DEFAULT.truth[:, 0], rtol=0, atol=1e-3)
    np.testing.assert_array_equal(track[:, 2], 0.0)


def test_step_accelerations_average_the_true_acceleration() -> None:
    """Mean of a(t) over each step, checked against a fine midpoint quadrature."""
    fine = 200
    offsets = (np.arange(fine) + 0.5) / fine * DEFAULT.dt
    times = DEFAULT.times[:, None] - DEFAULT.dt + offsets[None, :]
    a = simulation.sinusoid_states(times.ravel(), DEFAULT.amplitude,
                                   DEFAULT.frequency)[:, 2].reshape(times.shape)
    np.testing.assert_allclose(bias_model.step_accelerations(DEFAULT), a.mean(axis=1),
                               rtol=0, atol=1e-6)


@pytest.mark.parametrize("bias", [-35.0, 0.5, 20.0])
def test_uncorrected_bias_drifts_as_half_b_t_squared(bias: float) -> None:
    accelerations = bias_model.step_accelerations(DEFAULT)
    start = bias_model.initial_state(DEFAULT, 0.0)
    clean = bias_model.dead_reckoning(accelerations, start, DEFAULT.dt)
    biased = bias_model.dead_reckoning(accelerations + bias, start, DEFAULT.dt)
    elapsed = DEFAULT.times + DEFAULT.dt
    expected = bias * elapsed**2 / 2
    drift = bias_model.bias_drift(DEFAULT, bias)
    np.testing.assert_allclose(drift, expected, rtol=1e-12)
    np.testing.assert_allclose(biased[:, 0] - clean[:, 0], drift, rtol=1e-9, atol=1e-9)
    # Knowing the bias removes it exactly.
    corrected = bias_model.dead_reckoning(accelerations + bias, start, DEFAULT.dt,
                                          bias_estimate=bias)
    np.testing.assert_allclose(corrected[:, :2], clean[:, :2], rtol=0, atol=1e-9)


def step_by_step_dead_reckoning(readings, start, dt, bias_estimate=0.0):
    """The recursion z_j = F z_{j−1} + G u_j one step at a time (the former implementation)."""
    readings, start = np.asarray(readings, float), np.asarray(start, float)
    F = bias_model.transition_matrix(dt)
    G = bias_model.input_matrix(dt)[:, 0]
    batch = np.broadcast_shapes(readings.shape[:-1], start.shape[:-1])
    n_steps = readings.shape[-1]
    z = np.empty((*batch, 3))
    z[..., :2] = start[..., :2]
    z[..., 2] = bias_estimate
    readings = np.broadcast_to(readings, (*batch, n_steps))
    out = np.empty((*batch, n_steps, 3))
    for j in range(n_steps):
        z = z @ F.T + readings[..., j, None] * G
        out[..., j, :] = z
    return out


@pytest.mark.parametrize("seed", range(6))
def test_dead_reckoning_equals_the_step_by_step_recursion(seed: int) -> None:
    """Running sums give the recursion's values, to 1e-9 relative on random inputs."""
    rng = np.random.default_rng(seed)
    n_steps = int(rng.integers(1, 1500))
    dt = float(10.0 ** rng.uniform(-3, -0.5))
    shapes = [((n_steps,), (3,)), ((4, n_steps), (2,)), ((n_steps,), (5, 3)),
              ((2, 1, n_steps), (3, 2)), ((3, n_steps), (3, 2)), ((n_steps,), (2,))]
    readings_shape, start_shape = shapes[seed]
    readings = rng.normal(20.0, 300.0, readings_shape)
    start = rng.normal(0.0, 50.0, start_shape)
    bias_estimate = float(rng.normal(0.0, 30.0))
    fast = bias_model.dead_reckoning(readings, start, dt, bias_estimate)
    slow = step_by_step_dead_reckoning(readings, start, dt, bias_estimate)
    assert fast.shape == slow.shape
    # Relative to each quantity's largest size: where p or v crosses zero, both ways of
    # summing round differently in the last digits of a much larger running sum.
    for column, name in enumerate(("p", "v", "b̂")):
        scale = float(np.max(np.abs(slow[..., column])))
        np.testing.assert_allclose(fast[..., column], slow[..., column], rtol=1e-9,
                                   atol=1e-9 * scale, err_msg=name)
    np.testing.assert_array_equal(fast[..., 2], bias_estimate)


def test_filter_model_is_the_one_track_with_input_uses() -> None:
    """Lesson 0.5 eqs. (5) and (9), vision reading the position, P0 spanning the path."""
    scenario = dataclasses.replace(DEFAULT, amplitude=4.0, frequency=1.5)
    model = bias_model.unbiased_run(scenario, sigma_a=30.0, sigma_v=2.5,
                                    bias_prior_std=40.0).model
    dt = scenario.dt
    np.testing.assert_array_equal(model.A, [[1, dt, -dt**2 / 2], [0, 1, -dt], [0, 0, 1]])
    np.testing.assert_array_equal(model.B, [[dt**2 / 2], [dt], [0]])
    np.testing.assert_allclose(model.Q, 900.0 * model.B @ model.B.T, rtol=1e-15)
    np.testing.assert_array_equal(model.C, [[1.0, 0.0, 0.0]])
    np.testing.assert_array_equal(model.R, [[6.25]])
    np.testing.assert_array_equal(model.z0, np.zeros(3))
    np.testing.assert_allclose(model.P0, np.diag([16.0, (4.0 * 2 * np.pi * 1.5) ** 2, 1600.0]),
                               rtol=1e-15)
    assert not model.P0.flags.writeable
    tracking = bias_model.track_with_input(scenario, bias=5.0, sigma_a=30.0, sigma_v=2.5,
                                           bias_prior_std=40.0)
    direct = kalman_filter(tracking.measurements, model.A, model.C, model.Q, model.R, model.z0,
                           model.P0, B=model.B, u=tracking.readings[:, None])
    np.testing.assert_allclose(tracking.result.estimates, direct.estimates, rtol=1e-9,
                               atol=1e-9)
    np.testing.assert_array_equal(tracking.result.estimate_covariances,
                                  direct.estimate_covariances)
    for name, value in (("sigma_a", 0.0), ("sigma_v", -1.0), ("bias_prior_std", 0.0)):
        arguments = {"sigma_a": 30.0, "sigma_v": 2.5, "bias_prior_std": 40.0, name: value}
        with pytest.raises(ValueError, match=name):
            bias_model.unbiased_run(scenario, **arguments)


def _biased_filter_by_hand(scenario, bias: float, sigma_a: float, sigma_v: float,
                           noise: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Estimates of the filter fed the biased signal itself, assembled from the lesson."""
    dt = scenario.dt
    readings = bias_model.step_accelerations(scenario) + bias + sigma_a * noise[..., 1]
    y = scenario.truth[:, :1] + sigma_v * noise[..., :1]
    F = np.array([[1, dt, -dt**2 / 2], [0, 1, -dt], [0, 0, 1]])
    G = np.array([[dt**2 / 2], [dt], [0]])
    P0 = np.diag([scenario.amplitude**2, scenario.peak_speed**2, 50.0**2])
    result = kalman_filter(y, F, np.array([[1.0, 0.0, 0.0]]), sigma_a**2 * G @ G.T,
                           np.array([[sigma_v**2]]), np.zeros(3), P0, B=G,
                           u=readings[..., None])
    return result.estimates, readings


def close_to(estimates: np.ndarray, expected: np.ndarray) -> None:
    """Estimates [p̂, v̂, b̂] agree to 1e-9, relative to each state's largest size."""
    for column, name in enumerate(("p", "v", "b")):
        scale = float(np.max(np.abs(expected[..., column])))
        np.testing.assert_allclose(estimates[..., column], expected[..., column], rtol=1e-9,
                                   atol=1e-9 * scale, err_msg=name)


@pytest.mark.parametrize(("bias", "sigma_a", "sigma_v"),
                         [(20.0, 20.0, 1.5), (-55.0, 300.0, 4.5), (0.0, 1.0, 0.5),
                          (60.0, 1000.0, 6.0)])
@pytest.mark.slow
def test_unbiased_run_at_a_bias_is_the_filter_fed_that_biased_signal(bias, sigma_a,
                                                                     sigma_v) -> None:
    """The linear-in-bias shortcut, against the filter run on the biased signal, to 1e-9."""
    noise = bias_model.unit_noise(DEFAULT, runs=4)
    run = bias_model.unbiased_run(DEFAULT, sigma_a, sigma_v, runs=4, noise=noise)
    shortcut = run.at_bias(bias)
    estimates, readings = _biased_filter_by_hand(DEFAULT, bias, sigma_a, sigma_v, noise)
    close_to(shortcut.result.estimates, estimates)
    np.testing.assert_allclose(shortcut.readings, readings, rtol=1e-12, atol=1e-12)
    # ... and equal to what notebook 06 calls, run by run.
    notebook = bias_model.track_with_input(DEFAULT, bias, sigma_a, sigma_v, runs=4, noise=noise)
    close_to(shortcut.result.estimates, notebook.result.estimates)
    np.testing.assert_array_equal(shortcut.dead_reckoning, notebook.dead_reckoning)
    np.testing.assert_array_equal(shortcut.truth, notebook.truth)
    assert shortcut.result.estimates.shape == (4, DEFAULT.n_steps, 3)
    assert shortcut.result.gains.shape == (4, DEFAULT.n_steps, 3, 1)
    single = bias_model.unbiased_run(DEFAULT, sigma_a, sigma_v, noise=noise[0]).at_bias(bias)
    close_to(single.result.estimates, estimates[0])
    assert single.result.estimate_covariances.shape == (DEFAULT.n_steps, 3, 3)


def test_unit_response_is_the_filter_of_a_constant_unit_input_alone() -> None:
    run = bias_model.unbiased_run(DEFAULT)
    model = run.model
    alone = model.filter(np.zeros((DEFAULT.n_steps, 1)), np.ones((DEFAULT.n_steps, 1)))
    np.testing.assert_allclose(run.unit_response, alone.estimates, rtol=1e-12, atol=1e-12)
    # Its bias estimate learns the unit step: b̂ → 1 (the bias the filter must remove).
    assert abs(run.unit_response[-1, 2] - 1.0) < 0.05
    with pytest.raises(ValueError, match="bias must be a finite number"):
        run.at_bias(float("inf"))


@pytest.mark.slow
def test_dead_reckoning_spread_matches_monte_carlo_and_power_law() -> None:
    sigma_a = 20.0
    spread = bias_model.dead_reckoning_spread(DEFAULT, sigma_a)
    elapsed = DEFAULT.times + DEFAULT.dt
    # Continuous-time limit of eq. (9): σ_a √(Δt/3) t^{3/2}, good to 1 % after 0.5 s.
    late = elapsed > 0.5
    np.testing.assert_allclose(spread[late],
                               sigma_a * np.sqrt(DEFAULT.dt / 3) * elapsed[late] ** 1.5,
                               rtol=0.01)
    noise = bias_model.unit_noise(DEFAULT, runs=2000)[..., 1]
    accelerations = bias_model.step_accelerations(DEFAULT)
    readings = bias_model.acceleration_readings(accelerations, 0.0, sigma_a, noise)
    runs = bias_model.dead_reckoning(readings, bias_model.initial_state(DEFAULT, 0.0),
                                     DEFAULT.dt)
    spread_mc = np.std(runs[:, :, 0] - bias_model.dead_reckoning(
        accelerations, bias_model.initial_state(DEFAULT, 0.0), DEFAULT.dt)[:, 0], axis=0)
    # 2000 runs: the sample std is within about 3 × 1.6 % of the true one.
    np.testing.assert_allclose(spread_mc[[99, 499, 999]], spread[[99, 499, 999]], rtol=0.06)


def test_readings_add_bias_and_scaled_noise() -> None:
    accelerations = np.array([1.0, -2.0, 3.0])
    noise = np.array([[0.5, -1.0, 2.0], [0.0, 0.0, 1.0]])
    readings = bias_model.acceleration_readings(accelerations, np.array([10.0, -5.0]),
                                                np.array([2.0, 3.0]), noise)
    np.testing.assert_array_equal(readings, [[12.0, 6.0, 17.0], [-4.0, -7.0, 1.0]])


def test_unit_noise_shares_vision_and_adds_an_independent_stream() -> None:
    noise = bias_model.unit_noise(DEFAULT, runs=50)
    assert noise.shape == (50, DEFAULT.n_steps, 2)
    sensors = DEFAULT.unit_noise(runs=50)
    np.testing.assert_array_equal(noise[..., 0], sensors[..., 0])
    # Not a copy of either sensor's stream, and uncorrelated with both (5 standard
    # errors of a correlation estimated from 50 000 pairs).
    for column in range(2):
        correlation = np.corrcoef(noise[..., 1].ravel(), sensors[..., column].ravel())[0, 1]
        assert abs(correlation) < 5 / np.sqrt(noise[..., 1].size)
    # Run 0 of a batch is the single run; run r does not depend on the batch size.
    np.testing.assert_array_equal(noise[0], bias_model.unit_noise(DEFAULT))
    np.testing.assert_array_equal(noise[:7], bias_model.unit_noise(DEFAULT, runs=7))


def test_true_and_initial_states() -> None:
    states = bias_model.true_states(DEFAULT, 20.0)
    np.testing.assert_array_equal(states[:, :2], DEFAULT.truth[:, :2])
    np.testing.assert_array_equal(states[:, 2], 20.0)
    start = bias_model.initial_state(DEFAULT, -3.0)
    omega = 2 * np.pi * DEFAULT.frequency
    np.testing.assert_allclose(start, [DEFAULT.amplitude * np.sin(-omega * DEFAULT.dt),
                                       DEFAULT.amplitude * omega * np.cos(-omega * DEFAULT.dt),
                                       -3.0])


@pytest.fixture(scope="module")
def monte_carlo():
    return bias_model.track_with_input(DEFAULT, runs=300)


def test_experiment_wires_signal_vision_and_dead_reckoning(monte_carlo) -> None:
    single = bias_model.track_with_input(DEFAULT)
    noise = bias_model.unit_noise(DEFAULT)
    accelerations = bias_model.step_accelerations(DEFAULT)
    np.testing.assert_allclose(single.readings, accelerations + 20.0 + 20.0 * noise[:, 1])
    np.testing.assert_allclose(single.measurements[:, 0],
                               DEFAULT.truth[:, 0] + DEFAULT.sigma_v * noise[:, 0])
    np.testing.assert_allclose(
        single.dead_reckoning,
        bias_model.dead_reckoning(single.readings, bias_model.initial_state(DEFAULT, 20.0),
                                  DEFAULT.dt))
    # Run 0 of the Monte Carlo batch is the single run.
    np.testing.assert_allclose(monte_carlo.result.estimates[0], single.result.estimates,
                               rtol=0, atol=1e-10)


def test_bias_estimate_converges_and_its_band_is_honest(monte_carlo) -> None:
    errors = monte_carlo.bias_estimates - DEFAULT_BIAS
    stds = monte_carlo.bias_stds[0]
    # The filter's σ of b̂ shrinks from its prior (50 cm/s²) to about 0.7 cm/s².
    assert stds[-1] < 1.0 < 5.0 < stds[49]
    # Empirical RMS error over 300 runs agrees with the filter's own σ (after 1 s,
    # where the model is right and the start-up error is gone) within 15 %.
    rms = np.sqrt(np.mean(errors**2, axis=0))
    np.testing.assert_allclose(rms[[199, 499, 999]], stds[[199, 499, 999]], rtol=0.15)
    # About 95 % of runs lie inside ±2σ at the end.
    inside = np.mean(np.abs(errors[:, -1]) <= 2 * stds[-1])
    assert 0.9 < inside <= 1.0


def test_size_of_the_bias_only_matters_during_the_start(monte_carlo) -> None:
    """The filter is linear: the bias enters only through the initial error."""
    other = bias_model.track_with_input(DEFAULT, bias=-45.0, runs=300)
    difference = (other.result.estimates - other.truth) - (
        monte_carlo.result.estimates - monte_carlo.truth)
    # The same deterministic response in every run ...
    np.testing.assert_allclose(difference, np.broadcast_to(difference[0], difference.shape),
                               rtol=0, atol=1e-8)
    # ... that dies away: from 3 s on it is under a tenth of the filter's own σ of b̂,
    # while in the first half second it is larger than that σ.
    stds = monte_carlo.bias_stds[0]
    assert np.all(np.abs(difference[0, 300:, 2]) < 0.1 * stds[300:])
    assert np.max(np.abs(difference[0, :50, 2]) / stds[:50]) > 1.0


def test_input_beats_vision_alone_when_the_signal_is_good(monte_carlo) -> None:
    vision_only = experiments.track(DEFAULT, runs=300)
    gain = metrics.mean_ci95(monte_carlo.mse() - vision_only.mse())
    assert gain.high < 0
    noisy = bias_model.track_with_input(DEFAULT, sigma_a=1000.0, runs=300)
    loss = metrics.mean_ci95(noisy.mse() - vision_only.mse())
    assert loss.low > 0


def test_dead_reckoning_mse_dwarfs_the_filter(monte_carlo) -> None:
    assert np.all(monte_carlo.dead_reckoning_mse() > 1000 * monte_carlo.mse())


def test_sigma_v_defaults_to_the_scenario() -> None:
    scenario = dataclasses.replace(DEFAULT, sigma_v=4.5)
    tracking = bias_model.track_with_input(scenario)
    assert tracking.sigma_v == 4.5
    np.testing.assert_allclose(
        tracking.measurements[:, 0] - scenario.truth[:, 0],
        4.5 * bias_model.unit_noise(scenario)[:, 0])


def test_prior_spans_the_path_and_its_peak_speed() -> None:
    """P0 = diag(A², (A·2πf)², bias_prior_std²), for a path other than the default."""
    scenario = dataclasses.replace(DEFAULT, amplitude=4.0, frequency=1.5)
    tracking = bias_model.track_with_input(scenario, bias_prior_std=30.0)
    P0 = np.diag([16.0, (4.0 * 2 * np.pi * 1.5) ** 2, 900.0])
    direct = kalman_filter(
        tracking.measurements, bias_model.transition_matrix(scenario.dt),
        np.array([[1.0, 0.0, 0.0]]), bias_model.process_noise_covariance(scenario.dt, 20.0),
        np.array([[scenario.sigma_v**2]]), np.zeros(3), P0,
        B=bias_model.input_matrix(scenario.dt), u=tracking.readings[:, None])
    np.testing.assert_allclose(tracking.result.estimate_covariances,
                               direct.estimate_covariances, rtol=1e-12)
    np.testing.assert_allclose(tracking.result.estimates, direct.estimates, rtol=1e-12,
                               atol=1e-12)


@pytest.mark.parametrize(
    ("call", "message"),
    [(lambda: bias_model.true_states(DEFAULT, np.nan),
      "bias must be a finite number in cm/s², got nan"),
     (lambda: bias_model.initial_state(DEFAULT, "x"),
      "bias must be a finite number in cm/s², got 'x'"),
     (lambda: bias_model.track_with_input(DEFAULT, noise=np.zeros((10, 2))),
      "noise must have shape (1000, 2) (vision, acceleration), got shape (10, 2)"),
     (lambda: bias_model.track_with_input(DEFAULT, runs=2, noise=bias_model.unit_noise(DEFAULT)),
      "noise must have shape (2, 1000, 2) (vision, acceleration), got shape (1000, 2)")],
)
def test_bad_input_messages(call, message: str) -> None:
    with pytest.raises(ValueError, match=re.escape(message)):
        call()


@pytest.mark.parametrize(
    ("call", "name"),
    [(lambda: bias_model.transition_matrix(0.0), "dt"),
     (lambda: bias_model.input_matrix(-0.1), "dt"),
     (lambda: bias_model.process_noise_covariance(0.01, 0.0), "sigma_a"),
     (lambda: bias_model.true_states(DEFAULT, np.nan), "bias"),
     (lambda: bias_model.initial_state(DEFAULT, "x"), "bias"),
     (lambda: bias_model.bias_drift(DEFAULT, np.inf), "bias"),
     (lambda: bias_model.acceleration_readings(np.zeros(3), 0.0, -1.0, np.zeros(3)), "sigma_a"),
     (lambda: bias_model.acceleration_readings(np.zeros(3), 0.0, 1.0, np.zeros(4)), "noise"),
     (lambda: bias_model.acceleration_readings(np.zeros((2, 3)), 0.0, 1.0, np.zeros(3)),
      "accelerations"),
     (lambda: bias_model.acceleration_readings(np.zeros(3), np.zeros(2), 1.0,
                                               np.zeros((3, 3))), "batch"),
     (lambda: bias_model.dead_reckoning(np.zeros(5), np.zeros(4), 0.01), "start"),
     (lambda: bias_model.dead_reckoning(np.zeros(5), np.zeros(2), 0.01, np.nan),
      "bias_estimate"),
     (lambda: bias_model.track_with_input(DEFAULT, sigma_a=-2.0), "sigma_a"),
     (lambda: bias_model.track_with_input(DEFAULT, sigma_v=0.0), "sigma_v"),
     (lambda: bias_model.track_with_input(DEFAULT, bias=np.nan), "bias"),
     (lambda: bias_model.track_with_input(DEFAULT, bias_prior_std=0.0), "bias_prior_std"),
     (lambda: bias_model.track_with_input(DEFAULT, noise=np.zeros((10, 2))), "noise"),
     (lambda: bias_model.track_with_input(DEFAULT, runs=2,
                                          noise=bias_model.unit_noise(DEFAULT)), "noise")],
)
def test_bad_input_is_rejected_by_name(call, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        call()


@pytest.mark.slow
def test_learning_figure_is_notebook_06s_figure_1_from_two_results() -> None:
    """``run.learning_figure(mc)`` draws what six arrays drew, pixel for pixel."""
    from lqe_helpers import figures

    b_true = bias_model.DEFAULT_BIAS
    run = bias_model.track_with_input(DEFAULT, bias=b_true)
    mc = bias_model.track_with_input(DEFAULT, bias=b_true, runs=20)
    rms = np.sqrt(np.mean((mc.bias_estimates - b_true) ** 2, axis=0))   # by hand
    np.testing.assert_array_equal(mc.bias_rms_error(), rms)
    by_arrays = figures.bias_learning_figure(DEFAULT.times, run.bias_estimates, run.bias_stds,
                                             b_true, rms, mc.bias_stds[0])
    assert same_png(run.learning_figure(mc), by_arrays)
    other = bias_model.track_with_input(DEFAULT, bias=b_true + 1.0, runs=3)
    for wrong_run, runs in ((mc, mc), (run, run), (run, other), (run, "mc")):
        with pytest.raises(ValueError, match=r"single run|runs must be"):
            wrong_run.learning_figure(runs)


def test_signal_figure_is_notebook_06s_figure_3_from_one_result() -> None:
    """``run.signal_figure()`` draws what the run's readings, a and b drew, pixel for pixel;
    another run (another σ_a) draws another figure."""
    from lqe_helpers import figures

    run = bias_model.track_with_input(DEFAULT, bias=DEFAULT_BIAS)
    by_arrays = figures.acceleration_signal_figure(
        DEFAULT.times, run.readings, bias_model.step_accelerations(DEFAULT), DEFAULT_BIAS)
    by_object = run.signal_figure()
    noisier = bias_model.track_with_input(DEFAULT, bias=DEFAULT_BIAS, sigma_a=400.0)
    other = noisier.signal_figure()
    drawn, painted, another = pngs(by_object, by_arrays, other)
    assert drawn == painted
    assert another != painted
    with pytest.raises(ValueError, match="single run"):
        bias_model.track_with_input(DEFAULT, runs=2).signal_figure()


def _batches(biases: tuple[float, ...], sigmas: tuple[float, ...], runs: int = 3,
             ) -> tuple[dict, dict]:
    return ({b: bias_model.track_with_input(DEFAULT, bias=b, runs=runs) for b in biases},
            {s: bias_model.track_with_input(DEFAULT, sigma_v=s, runs=runs) for s in sigmas})


def test_settling_figure_is_notebook_06s_figure_6_from_the_runs() -> None:
    """``InputTracking.settling_figure(by_bias, by_sigma_v)`` draws what the notebook's
    arrays drew, pixel for pixel; other runs draw another figure."""
    from lqe_helpers import figures

    by_bias, by_sigma_v = _batches((-60.0, 20.0), (0.5, 4.5))
    by_arrays = figures.bias_settling_figure(
        DEFAULT.times,
        {f"b = {b:g} cm/s²": np.mean(batch.bias_estimates - b, axis=0)
         for b, batch in by_bias.items()},
        {f"σ_v = {s} cm": batch.bias_stds[0] for s, batch in by_sigma_v.items()})
    by_object = bias_model.InputTracking.settling_figure(by_bias, by_sigma_v)
    other = bias_model.InputTracking.settling_figure(*_batches((-60.0, 0.0), (0.5, 1.5)))
    drawn, painted, another = pngs(by_object, by_arrays, other)
    assert drawn == painted
    assert another != painted


@pytest.mark.parametrize(("change", "message"), [
    (lambda by_bias, by_sigma_v: ({}, by_sigma_v), "by_bias must map"),
    (lambda by_bias, by_sigma_v: ({21.0: by_bias[20.0]}, by_sigma_v), "by_bias must map"),
    (lambda by_bias, by_sigma_v: ({True: by_bias[20.0]}, by_sigma_v), "by_bias must map"),
    (lambda by_bias, by_sigma_v: (
        {20.0: bias_model.track_with_input(DEFAULT)}, by_sigma_v), "by_bias must map"),
    (lambda by_bias, by_sigma_v: ([by_bias[20.0]], by_sigma_v), "by_bias must map"),
    (lambda by_bias, by_sigma_v: (by_bias, {1.5: by_bias[20.0], 0.5: by_sigma_v[1.5]}),
     "by_sigma_v must map"),
    (lambda by_bias, by_sigma_v: (
        by_bias, {float(s): bias_model.track_with_input(DEFAULT, sigma_v=float(s), runs=2)
                  for s in range(1, 8)}), "by_sigma_v must map"),
    (lambda by_bias, by_sigma_v: (by_bias, {1.5: bias_model.track_with_input(
        dataclasses.replace(DEFAULT, seed=DEFAULT.seed + 1), runs=2)}),
     "by_sigma_v must hold runs of the scenario of by_bias"),
])
def test_settling_figure_refuses_bad_runs_naming_the_parameter(change, message) -> None:
    by_bias, by_sigma_v = _batches((20.0,), (1.5,), runs=2)
    with pytest.raises(ValueError, match=message):
        bias_model.InputTracking.settling_figure(*change(by_bias, by_sigma_v))
