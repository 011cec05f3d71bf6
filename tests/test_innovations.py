"""Innovations and NIS (issue 17 §2) against filterpy, chi-square theory and notebook 04."""

from __future__ import annotations

import numpy as np
import pytest
import reference_loops as reference

from lqe_helpers import experiments, metrics, model, simulation
from lqe_helpers.filter import FilterResult, kalman_filter
from lqe_helpers.scenario import DEFAULT

FUSED = ("vision", "proprioception")


def filterpy_innovations(y: np.ndarray, A, C, Q, R, z0, P0) -> tuple[np.ndarray, np.ndarray]:
    """filterpy's residual ``kf.y`` and its covariance ``kf.S`` after each update."""
    run = reference.filterpy_run(y, A, C, Q, R, z0, P0)
    return run["innovations"], run["innovation_covariances"]


@pytest.mark.parametrize(("k", "m"), [(1, 1), (3, 1), (3, 2), (4, 3)])
def test_innovations_match_filterpy(k: int, m: int) -> None:
    rng = np.random.default_rng(10 * k + m)
    A = np.eye(k) + 0.2 * rng.normal(size=(k, k))
    C = rng.normal(size=(m, k))
    X, Y, Z = rng.normal(size=(k, k)), rng.normal(size=(m, m)), rng.normal(size=(k, k))
    Q, R, P0 = 0.1 * X @ X.T + 0.01 * np.eye(k), Y @ Y.T + np.eye(m), Z @ Z.T + np.eye(k)
    z0 = rng.normal(size=k)
    y = 2.0 * rng.normal(size=(3, 40, m))
    result = kalman_filter(y, A, C, Q, R, z0, P0)
    ours = metrics.innovations(y, result, A, C, z0)
    assert ours.values.shape == (3, 40, m) and ours.covariances.shape == (3, 40, m, m)
    for run in range(3):
        values, covariances = filterpy_innovations(y[run], A, C, Q, R, z0, P0)
        np.testing.assert_allclose(ours.values[run], values, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ours.covariances[run], covariances, rtol=1e-9, atol=1e-11)


def test_innovations_with_a_known_input_match_a_hand_loop() -> None:
    rng = np.random.default_rng(3)
    A, C, B = DEFAULT.A, np.array([[1.0, 0.0, 0.0]]), model.jerk_input_matrix(0.01)
    u = rng.normal(size=(25, 1))
    y = rng.normal(size=(25, 1))
    z0 = np.array([1.0, 2.0, 3.0])
    result = kalman_filter(y, A, C, DEFAULT.Q, [[2.0]], z0, np.eye(3), B=B, u=u)
    ours = metrics.innovations(y, result, A, C, z0, B=B, u=u)
    z = z0
    for j in range(25):
        expected = y[j] - C @ (A @ z + B @ u[j])
        np.testing.assert_allclose(ours.values[j], expected, rtol=1e-12, atol=1e-12)
        z = result.estimates[j]


def test_nis_is_the_normalised_square_by_hand() -> None:
    values = np.array([[1.0, 2.0], [0.5, -1.0]])
    covariances = np.array([[[2.0, 0.5], [0.5, 1.0]], [[1.0, 0.0], [0.0, 4.0]]])
    expected = [values[i] @ np.linalg.inv(covariances[i]) @ values[i] for i in range(2)]
    np.testing.assert_allclose(metrics.nis(metrics.Innovations(values, covariances)), expected,
                               rtol=1e-14)


def test_log_likelihood_is_the_sum_of_gaussian_log_densities() -> None:
    from scipy import stats

    values = np.array([[1.0, 2.0], [0.5, -1.0], [0.0, 0.3]])
    covariances = np.array([[[2.0, 0.5], [0.5, 1.0]], [[1.0, 0.0], [0.0, 4.0]], np.eye(2)])
    innovations = metrics.Innovations(values, covariances)
    expected = sum(stats.multivariate_normal(np.zeros(2), covariances[j]).logpdf(values[j])
                   for j in (1, 2))
    assert metrics.innovation_log_likelihood(innovations, 1) == pytest.approx(expected,
                                                                                rel=1e-12)


def test_nis_band_is_the_chi_square_band_of_the_mean() -> None:
    from scipy import stats

    low, high = metrics.nis_band(2, 900)
    assert low == pytest.approx(stats.chi2.ppf(0.025, 1800) / 900, rel=1e-9)
    assert high == pytest.approx(stats.chi2.ppf(0.975, 1800) / 900, rel=1e-9)
    low, high = metrics.nis_band(1, 1)  # one step of one sensor
    assert (low, high) == pytest.approx((stats.chi2.ppf(0.025, 1), stats.chi2.ppf(0.975, 1)))


def model_consistent_innovations(assumed_sigma_p: float, runs: int = 200
                                 ) -> metrics.Innovations:
    """Two senses on a truth drawn from the filter's own motion model (random jerk)."""
    rng = np.random.default_rng(11)
    A, Q = DEFAULT.A, DEFAULT.Q
    z0, P0 = np.zeros(3), np.eye(3)
    states = simulation.simulate_model_states(rng, A, Q, z0, P0, 500, runs)
    C = model.observation_matrix(FUSED)
    true_R = model.measurement_noise_covariance([1.5, 1.5])
    y = states @ C.T + rng.normal(size=(runs, 500, 2)) @ np.linalg.cholesky(true_R).T
    assumed_R = model.measurement_noise_covariance([1.5, assumed_sigma_p])
    result = kalman_filter(y, A, C, Q, assumed_R, z0, P0)
    return metrics.innovations(y, result, A, C, z0)


def test_nis_mean_equals_the_number_of_sensors_for_a_correct_model() -> None:
    test = metrics.nis_test(model_consistent_innovations(1.5))
    assert test.expected == 2 and test.samples == 200 * 500
    assert test.consistent, test
    # Every step is χ²_2 (mean 2, variance 4): the mean is within 3 standard errors of 2.
    assert abs(test.mean - 2) < 3 * np.sqrt(4 / test.samples)
    # About 95 % of the runs' own means lie in the band of one run (binomial 3σ: ±4.6 %).
    low, high = metrics.nis_band(2, 500)
    inside = np.mean((test.run_means >= low) & (test.run_means <= high))
    assert abs(inside - 0.95) < 3 * np.sqrt(0.95 * 0.05 / 200)


@pytest.mark.parametrize(("assumed", "side"), [(0.5, "above"), (4.5, "below")])
def test_nis_leaves_the_band_when_a_sense_is_misjudged(assumed: float, side: str) -> None:
    test = metrics.nis_test(model_consistent_innovations(assumed))
    assert not test.consistent
    assert (test.mean > test.high) if side == "above" else (test.mean < test.low)


def butterfly_nis(true_sigma_p: float, assumed_sigma_p: float) -> metrics.NISTest:
    tracking = experiments.track(DEFAULT, FUSED, sigmas=[1.5, true_sigma_p],
                                 assumed_sigmas=[1.5, assumed_sigma_p], runs=DEFAULT.mc_runs)
    innovations = metrics.innovations(tracking.measurements, tracking.result, DEFAULT.A,
                                      model.observation_matrix(FUSED), np.asarray(DEFAULT.z0))
    return metrics.nis_test(innovations, DEFAULT.burn_in_steps)


@pytest.mark.parametrize(("true", "assumed", "low", "high"),
                         [(4.5, 1.5, 9.0, 10.5),     # notebook 04's overtrust: NIS ≈ 9.8
                          (1.5, 4.5, 1.0, 1.2),      # the reverse: NIS ≈ 1.10
                          (4.5, 13.5, 1.0, 1.2)])    # notebook 04's undertrust: NIS ≈ 1.10
def test_nis_of_notebook_04s_misjudged_proprioception(true, assumed, low, high) -> None:
    test = butterfly_nis(true, assumed)
    assert low < test.mean < high
    assert not test.consistent
    # So far out that every single run's own mean is outside one run's band.
    run_low, run_high = metrics.nis_band(2, DEFAULT.n_steps - DEFAULT.burn_in_steps)
    assert np.all((test.run_means < run_low) | (test.run_means > run_high))


def test_nis_with_the_right_sigma_p_on_the_sine_path() -> None:
    # The right R, but the butterfly's jerk is a smooth cosine, not the model's random
    # jerk: per run NIS is consistent (about 94 % of runs inside one run's band), while
    # the grand mean over 270 000 steps sits about 1 % below 2, outside its narrow band.
    test = butterfly_nis(4.5, 4.5)
    assert test.mean < test.low and 1.97 < test.mean < 2.0
    run_low, run_high = metrics.nis_band(2, DEFAULT.n_steps - DEFAULT.burn_in_steps)
    inside = np.mean((test.run_means >= run_low) & (test.run_means <= run_high))
    assert 0.90 < inside <= 0.98


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda r, y: metrics.innovations(y, "result", DEFAULT.A, [[1, 0, 0]], np.zeros(3)),
         r"^result must be a FilterResult \(from kalman_filter\(\)\), got str 'result'$"),
        (lambda r, y: metrics.innovations(y[:5], r, DEFAULT.A, [[1, 0, 0]], np.zeros(3)),
         r"^y must have trailing shape \(n, m\) = \(10, 1\) like result, got shape \(5, 1\)$"),
        (lambda r, y: metrics.innovations(y, r, np.eye(2), [[1, 0, 0]], np.zeros(3)),
         r"^A must have shape \(3, 3\)"),
        (lambda r, y: metrics.innovations(y, r, DEFAULT.A, [[1, 0, 0]], np.zeros(2)),
         r"^z0 must have trailing length k = 3, got shape \(2,\)$"),
        (lambda r, y: metrics.innovations(y, FilterResult(r.estimates, r.gains, r.covariances,
                                                          r.estimate_covariances),
                                          DEFAULT.A, [[1, 0, 0]], np.zeros(3)),
         r"^result must come from kalman_filter\(\)"),
        (lambda r, y: metrics.nis(r), r"^innovations must be an Innovations"),
        (lambda r, y: metrics.nis_band(0, 10), r"^sensors must be a whole number >= 1, got 0$"),
        (lambda r, y: metrics.nis_band(1, 10, level=1.0), r"^level must be in \(0, 1\)"),
    ],
)
def test_bad_input_names_the_parameter(call, message: str) -> None:
    y = np.ones((10, 1))
    result = kalman_filter(y, DEFAULT.A, [[1, 0, 0]], DEFAULT.Q, [[1.0]], np.zeros(3), np.eye(3))
    with pytest.raises(ValueError, match=message):
        call(result, y)
