"""The settled filter as a fixed low-pass (issue 17 §3): a closed-form case, the engine,
noise-free tracking runs and the Monte Carlo MSEs."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lqe_helpers import experiments, lowpass, metrics, model, smoothing
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.steady_state import steady_state

VISION = model.observation_matrix(("vision",))


def random_walk_filter(q: float, r: float) -> tuple[float, float]:
    """Closed form of the 1-state filter A = C = 1: prior variance P and gain K.

    P = P − P²/(P + r) + q gives P² = q (P + r), so P = (q + √(q² + 4 q r)) / 2.
    """
    prior = (q + np.sqrt(q * q + 4 * q * r)) / 2
    return prior, prior / (prior + r)


@pytest.mark.parametrize(("q", "r"), [(0.01, 1.0), (1.0, 1.0), (4.0, 0.25)])
def test_one_state_filter_against_its_closed_form(q: float, r: float) -> None:
    dt = 0.01
    _, K = random_walk_filter(q, r)
    lp = lowpass.steady_lowpass([[1.0]], [[1.0]], [[q]], [[r]], dt)
    np.testing.assert_allclose(lp.gain, [[K]], rtol=1e-10)
    np.testing.assert_allclose(lp.poles, [1 - K], rtol=1e-10)
    np.testing.assert_allclose(lp.time_constants, [-dt / np.log(1 - K)], rtol=1e-9)
    frequencies = np.array([0.1, 1.0, 10.0, 40.0])
    expected = K / (1 - (1 - K) * np.exp(-2j * np.pi * frequencies * dt))
    response = lowpass.position_response(lp, frequencies)
    np.testing.assert_allclose(response.response, expected, rtol=1e-10)
    np.testing.assert_allclose(response.lead, np.angle(expected) / (2 * np.pi * frequencies),
                               rtol=1e-10)
    assert np.all(response.lead < 0)  # a smoother of a random walk lags
    # Noise: the sum of the squared impulse response K (1 − K)^i times r.
    np.testing.assert_allclose(lowpass.noise_variance(lp), K**2 * r / (1 - (1 - K) ** 2),
                               rtol=1e-10)


def test_one_state_filter_is_the_exponential_smoother_with_alpha_k() -> None:
    # The settled random-walk filter is exactly the tutorial's exponentially weighted
    # moving average: its frequency response is the smoother's gain and lag on a sine.
    dt, frequency = 0.01, 0.5
    _, K = random_walk_filter(0.05, 2.25)
    lp = lowpass.steady_lowpass([[1.0]], [[1.0]], [[0.05]], [[2.25]], dt)
    times = np.arange(4000) * dt
    smoothed = smoothing.exponential_smoother(np.sin(2 * np.pi * frequency * times), K)
    fit = metrics.fit_sinusoid(times[2000:], smoothed[2000:], frequency)
    response = lowpass.position_response(lp, frequency)
    np.testing.assert_allclose(fit.amplitude, response.gain[0], rtol=1e-9)
    np.testing.assert_allclose(fit.lead, response.lead[0], rtol=1e-7)


def test_closed_loop_matrix_is_the_engines_settled_transition() -> None:
    lp = lowpass.steady_lowpass(DEFAULT.A, VISION, DEFAULT.Q, [[2.25]], DEFAULT.dt)
    result = kalman_filter(np.zeros((600, 1)), DEFAULT.A, VISION, DEFAULT.Q, [[2.25]],
                           np.zeros(3), DEFAULT.P0)
    settled = (np.eye(3) - result.gains[-1] @ VISION) @ DEFAULT.A
    np.testing.assert_allclose(lp.closed_loop, settled, rtol=1e-9, atol=1e-12)
    assert np.all(np.abs(lp.poles) < 1) and np.all(lp.time_constants > 0)


@pytest.mark.parametrize("sigma_v", [1.5, 4.5])
def test_frequency_response_is_the_settled_noise_free_tracking_run(sigma_v: float) -> None:
    scenario = DEFAULT
    clean = experiments.track(scenario, sigmas=[sigma_v], noise=np.zeros((scenario.n_steps, 1)))
    settled = 500  # 5 s: the start-up from z0 has died out to 1e-8 cm
    fit = metrics.fit_sinusoid(scenario.times[settled:], clean.positions[settled:],
                               scenario.frequency)
    lp = lowpass.steady_lowpass(scenario.A, VISION, scenario.Q, [[sigma_v**2]], scenario.dt)
    response = lowpass.position_response(lp, scenario.frequency)
    np.testing.assert_allclose(scenario.amplitude * response.gain, fit.amplitude, rtol=1e-8)
    np.testing.assert_allclose(response.lead, fit.lead, rtol=1e-5)


def test_gain_at_half_a_hertz_explains_notebook_01s_overshoot() -> None:
    # 01 prints 10.19 cm and +7.4 ms (fit after the 1 s burn-in) at σ_v = 1.5 cm.
    lp = lowpass.steady_lowpass(DEFAULT.A, VISION, DEFAULT.Q, [[1.5**2]], DEFAULT.dt)
    response = lowpass.position_response(lp, DEFAULT.frequency)
    assert round(float(DEFAULT.amplitude * response.gain[0]), 2) == 10.19
    assert round(float(1000 * response.lead[0]), 1) == 7.5  # settled; 7.4 with the start-up


@pytest.mark.parametrize("sigma_v", [1.5, 4.5])
def test_predicted_mse_lies_in_the_monte_carlo_interval(sigma_v: float) -> None:
    # A longer trial with 3 s skipped, so the start-up has died out.
    scenario = dataclasses.replace(DEFAULT, duration=20.0, burn_in=3.0)
    lp = lowpass.steady_lowpass(scenario.A, VISION, scenario.Q, [[sigma_v**2]], scenario.dt)
    predicted = lowpass.sinusoid_mse(lp, scenario.amplitude, scenario.frequency)
    runs = experiments.track(scenario, sigmas=[sigma_v], runs=scenario.mc_runs)
    clean = experiments.track(scenario, sigmas=[sigma_v], noise=np.zeros((scenario.n_steps, 1)))
    total = metrics.mean_ci95(runs.mse())
    noise_part = metrics.mean_ci95(metrics.mse(runs.positions - clean.positions,
                                               np.zeros(scenario.n_steps),
                                               scenario.burn_in_steps))
    assert total.low <= float(predicted.total) <= total.high
    assert noise_part.low <= float(predicted.noise) <= noise_part.high
    # What is left of the start-up after 3 s: 2e-5 of the systematic part at σ_v = 4.5 cm.
    np.testing.assert_allclose(predicted.systematic, clean.mse(), rtol=1e-4)


def test_variance_exponent_runs_from_near_one_to_five_sixths() -> None:
    sigmas = np.geomspace(0.01, 1000, 21)
    exponents = lowpass.variance_exponent(DEFAULT.A, VISION, DEFAULT.Q,
                                          (sigmas**2)[:, None, None])
    assert np.all(np.diff(exponents) < 0)
    assert 5 / 6 < exponents[-1] < 5 / 6 + 0.003
    assert exponents[0] > 0.9
    # Against a finite ratio: halving R at σ_v = 1.5 cm multiplies the variance by
    # 2^(−exponent) up to the exponent's drift over the halving.
    at = float(lowpass.variance_exponent(DEFAULT.A, VISION, DEFAULT.Q, [[2.25]]))
    ratio = steady_state(DEFAULT.A, VISION, DEFAULT.Q, np.array([[[1.125]], [[2.25]]]))
    halved = ratio.estimate_covariance[0, 0, 0] / ratio.estimate_covariance[1, 0, 0]
    assert halved == pytest.approx(2 ** -at, rel=2e-3)
    assert halved == pytest.approx(0.5548, abs=1e-4)  # 03's "a little more than half"


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: lowpass.steady_lowpass(DEFAULT.A, VISION, DEFAULT.Q, [[1.0]], 0.0),
         r"^dt must be a finite number > 0 s, got 0.0$"),
        (lambda: lowpass.position_response("filter", 0.5),
         r"^lowpass must be a LowPass \(from steady_lowpass\(\)\), got str 'filter'$"),
        (lambda: lowpass.position_response(
            lowpass.steady_lowpass(DEFAULT.A, VISION, DEFAULT.Q, [[1.0]], 0.01), 50.0),
         r"^frequency must be below the Nyquist limit 1/\(2 dt\) = 50 Hz, got 50 Hz$"),
        (lambda: lowpass.position_response(
            lowpass.steady_lowpass(DEFAULT.A, VISION, DEFAULT.Q, [[1.0]], 0.01), -1.0),
         r"^frequency must be > 0 Hz"),
        (lambda: lowpass.variance_exponent(DEFAULT.A, VISION, DEFAULT.Q, [[1.0]], step=1.0),
         r"^step must be <= 0.1"),
        (lambda: lowpass.variance_exponent(DEFAULT.A, VISION, DEFAULT.Q, [[-1.0]]),
         r"^R must be positive definite"),
    ],
)
def test_bad_input_names_the_parameter(call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()
