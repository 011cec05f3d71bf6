"""The filter of Tutorial eq. (5) against independent references."""

from __future__ import annotations

import numpy as np
import pytest
import reference_loops as reference
from hypothesis import given, settings
from hypothesis import strategies as st

from lqe_helpers import model, simulation
from lqe_helpers.filter import kalman_filter
from lqe_helpers.steady_state import steady_state


def random_model(rng: np.random.Generator, k: int, m: int) -> dict[str, np.ndarray]:
    """A random observable model with well-conditioned covariances."""
    A = np.eye(k) + 0.3 * rng.normal(size=(k, k))
    C = rng.normal(size=(m, k))
    X = rng.normal(size=(k, k))
    Q = 0.2 * X @ X.T + 0.01 * np.eye(k)
    Y = rng.normal(size=(m, m))
    R = Y @ Y.T + 0.5 * np.eye(m)
    Z = rng.normal(size=(k, k))
    P0 = Z @ Z.T + np.eye(k)
    return {"A": A, "C": C, "Q": Q, "R": R, "z0": rng.normal(size=k), "P0": P0}


def filterpy_reference(y: np.ndarray, A, C, Q, R, z0, P0):
    """Tutorial eq. (5) with filterpy (``reference_loops.filterpy_run``): estimates, gains,
    covariances and estimate covariances."""
    run = reference.filterpy_run(y, A, C, Q, R, z0, P0)
    return (run["estimates"], run["gains"], run["covariances"], run["estimate_covariances"])


@pytest.mark.parametrize(("k", "m"), [(1, 1), (2, 1), (3, 1), (3, 2), (4, 3)])
def test_matches_filterpy_unbatched(k: int, m: int) -> None:
    rng = np.random.default_rng(100 * k + m)
    params = random_model(rng, k, m)
    y = rng.normal(size=(60, m)) * 3
    ours = kalman_filter(y, **params)
    est, gains, covs, est_covs = filterpy_reference(y, **params)
    np.testing.assert_allclose(ours.estimates, est, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ours.gains, gains, rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(ours.covariances, covs, rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(ours.estimate_covariances, est_covs, rtol=1e-9, atol=1e-11)


def test_matches_filterpy_batched_runs_and_sweeps() -> None:
    rng = np.random.default_rng(7)
    k, m, n = 3, 2, 40
    params = random_model(rng, k, m)
    y = rng.normal(size=(5, 1, n, m))           # 5 runs
    R = np.stack([params["R"], 4 * params["R"], 0.25 * params["R"]])  # a sweep of 3 R's
    z0 = rng.normal(size=(5, 1, k))              # per-run initial estimates
    ours = kalman_filter(y, params["A"], params["C"], params["Q"], R, z0, params["P0"])
    assert ours.estimates.shape == (5, 3, n, k)
    assert ours.gains.shape == (5, 3, n, k, m)
    assert ours.covariances.shape == (5, 3, n, k, k)
    for run in range(5):
        for s in range(3):
            est, gains, covs, _ = filterpy_reference(
                y[run, 0], params["A"], params["C"], params["Q"], R[s], z0[run, 0], params["P0"])
            np.testing.assert_allclose(ours.estimates[run, s], est, rtol=1e-9, atol=1e-9)
            np.testing.assert_allclose(ours.gains[run, s], gains, rtol=1e-9, atol=1e-11)
            np.testing.assert_allclose(ours.covariances[run, s], covs, rtol=1e-9, atol=1e-11)


def test_batched_p0_sweep_matches_separate_calls() -> None:
    rng = np.random.default_rng(8)
    params = random_model(rng, 3, 1)
    y = rng.normal(size=(4, 1, 30, 1))
    P0s = np.stack([np.eye(3), 1e3 * np.eye(3)])
    batched = kalman_filter(y, params["A"], params["C"], params["Q"], params["R"],
                            params["z0"], P0s)
    for run in range(4):
        for s in range(2):
            single = kalman_filter(y[run, 0], params["A"], params["C"], params["Q"],
                                   params["R"], params["z0"], P0s[s])
            np.testing.assert_allclose(batched.estimates[run, s], single.estimates,
                                       rtol=1e-12, atol=1e-12)


def test_hand_derived_scalar_case() -> None:
    """k = m = 1, A = C = 1: the gain and estimate can be worked out by hand."""
    q, r, p0, z0 = 0.5, 2.0, 1.0, 0.0
    y = np.array([[1.0], [3.0]])
    out = kalman_filter(y, [[1.0]], [[1.0]], [[q]], [[r]], [z0], [[p0]])
    k1 = p0 / (p0 + r)                         # 1/3
    z1 = z0 + k1 * (1.0 - z0)                  # 1/3
    p1 = (p0 - k1 * p0) + q                    # 2/3 + 1/2 = 7/6
    k2 = p1 / (p1 + r)                         # (7/6)/(19/6) = 7/19
    z2 = z1 + k2 * (3.0 - z1)
    np.testing.assert_allclose(out.gains[:, 0, 0], [1 / 3, 7 / 19], rtol=1e-14)
    np.testing.assert_allclose(out.estimates[:, 0], [1 / 3, z2], rtol=1e-14)
    np.testing.assert_allclose(out.covariances[:, 0, 0], [7 / 6, (7 / 6) * (1 - 7 / 19) + q],
                               rtol=1e-14)


def test_long_run_reaches_riccati_fixed_point_and_scipy_agrees() -> None:
    from scipy.linalg import solve_discrete_are

    dt = 0.01
    A = model.transition_matrix(dt)
    Q = model.process_noise_covariance(dt, 1400.0)
    C = model.observation_matrix(("vision", "proprioception"))
    R = model.measurement_noise_covariance([1.5, 4.5])
    out = kalman_filter(np.zeros((3000, 2)), A, C, Q, R, np.zeros(3), np.eye(3))
    fixed = steady_state(A, C, Q, R)
    np.testing.assert_allclose(out.covariances[-1], fixed.covariance, rtol=1e-8)
    np.testing.assert_allclose(out.gains[-1], fixed.gain, rtol=1e-8)
    np.testing.assert_allclose(out.estimate_covariances[-1], fixed.estimate_covariance,
                               rtol=1e-8)
    # scipy solves the control-form DARE; the filter's is its dual (Aᵀ, Cᵀ).
    np.testing.assert_allclose(fixed.covariance, solve_discrete_are(A.T, C.T, Q, R), rtol=1e-8)


def test_filter_is_consistent_on_truth_from_its_own_model() -> None:
    """Normalised estimation error squared averages to the state dimension."""
    rng = np.random.default_rng(11)
    dt = 0.05
    A = model.transition_matrix(dt)
    Q = model.process_noise_covariance(dt, 30.0) + 1e-6 * np.eye(3)
    C = model.observation_matrix()
    R = model.measurement_noise_covariance([1.5])
    z0, P0 = np.zeros(3), np.diag([4.0, 4.0, 4.0])
    runs, n = 400, 200
    truth = simulation.simulate_model_states(rng, A, Q, z0, P0, n, runs)
    y = truth[..., :1] + 1.5 * rng.standard_normal((runs, n, 1))
    out = kalman_filter(y, A, C, Q, R, z0, P0)
    error = truth - out.estimates
    nees = np.einsum("...i,...ij,...j->...", error,
                     np.linalg.inv(out.estimate_covariances), error)
    # Runs are independent but the steps of one run are not, so the grand mean's
    # standard error comes from the spread of the per-run means (about 0.03 here, not
    # the sqrt(6 / (runs n)) ~ 0.009 of independent chi-square(3) values).
    standard_error = nees.mean(axis=1).std(ddof=1) / np.sqrt(runs)
    assert abs(nees.mean() - 3.0) < 4 * standard_error
    # And per time step (runs = 400): mean within 5 standard errors of 3 at every step.
    per_step = nees.mean(axis=0)
    assert np.all(np.abs(per_step - 3.0) < 5 * np.sqrt(6 / runs))


@settings(deadline=None)
@given(
    p0=st.floats(min_value=1e-6, max_value=1e10),
    sigma_v=st.floats(min_value=1e-3, max_value=1e3),
    sigma_p=st.floats(min_value=1e-3, max_value=1e3),
    jerk=st.floats(min_value=0.0, max_value=1e4),
    two_sensors=st.booleans(),
)
@pytest.mark.slow
def test_covariances_stay_symmetric_psd(p0, sigma_v, sigma_p, jerk, two_sensors) -> None:
    dt = 0.01
    sensors = ("vision", "proprioception") if two_sensors else ("vision",)
    sigmas = [sigma_v, sigma_p][: len(sensors)]
    A = model.transition_matrix(dt)
    Q = model.process_noise_covariance(dt, jerk)
    out = kalman_filter(np.zeros((200, len(sensors))), A, model.observation_matrix(sensors), Q,
                        model.measurement_noise_covariance(sigmas), np.zeros(3), p0 * np.eye(3))
    for name in ("covariances", "estimate_covariances"):
        P = getattr(out, name)
        assert P.shape == (200, 3, 3)
        np.testing.assert_array_equal(P, P.mT, err_msg=name)
        scale = np.max(np.abs(P), axis=(-2, -1))
        smallest = np.linalg.eigvalsh(P)[..., 0]
        assert np.all(smallest >= -1e-9 * scale), (name, smallest.min())
    # The position variance after a measurement never exceeds the best sensor's variance
    # (the filter can only gain from measuring), at every step, even with two sensors
    # under a prior 10¹⁶ times wider than them.
    posterior = out.estimate_covariances[:, 0, 0]
    assert np.all(posterior <= min(sigmas) ** 2 * (1 + 1e-9))


@settings(deadline=None)
@given(runs=st.integers(1, 3), n=st.integers(1, 12), k=st.integers(1, 4), m=st.integers(1, 3),
       seed=st.integers(0, 2**32 - 1))
def test_output_shapes(runs: int, n: int, k: int, m: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    params = random_model(rng, k, m)
    out = kalman_filter(rng.normal(size=(runs, n, m)), **params)
    assert out.estimates.shape == (runs, n, k)
    assert out.gains.shape == (runs, n, k, m)
    assert out.covariances.shape == (runs, n, k, k)
    assert out.estimate_covariances.shape == (runs, n, k, k)


def test_same_seed_gives_bit_identical_output() -> None:
    def run(seed: int) -> np.ndarray:
        rng = np.random.default_rng(seed)
        noise = simulation.unit_noise(rng, 500, 2, runs=3)
        y = simulation.measure(np.sin(np.arange(500) * 0.01) * 10, noise, [1.5, 4.5])
        dt = 0.01
        return kalman_filter(y, model.transition_matrix(dt), model.observation_matrix(
            ("vision", "proprioception")), model.process_noise_covariance(dt, 1400.0),
            model.measurement_noise_covariance([1.5, 4.5]), np.zeros(3), np.eye(3)).estimates

    first, second = run(5), run(5)
    assert first.tobytes() == second.tobytes()
    assert run(6).tobytes() != first.tobytes()


def test_converged_gain_shortcut_changes_nothing_measurable() -> None:
    """Once P reaches its fixed point the remaining gains repeat; compare with filterpy."""
    dt = 0.01
    A = model.transition_matrix(dt)
    Q = model.process_noise_covariance(dt, 1400.0)
    C = model.observation_matrix()
    R = model.measurement_noise_covariance([1.5])
    rng = np.random.default_rng(3)
    y = 10 * np.sin(np.arange(2000) * dt * np.pi)[:, None] + 1.5 * rng.normal(size=(2000, 1))
    ours = kalman_filter(y, A, C, Q, R, np.zeros(3), np.eye(3))
    est, gains, _, _ = filterpy_reference(y, A, C, Q, R, np.zeros(3), np.eye(3))
    np.testing.assert_allclose(ours.estimates, est, rtol=0, atol=1e-9)
    np.testing.assert_allclose(ours.gains, gains, rtol=1e-12, atol=0)


@pytest.mark.parametrize("period", [3, 4, 8, 16])
def test_a_cycling_covariance_is_not_taken_for_converged(period: int) -> None:
    """An unobserved, noise-free mode rotating by 2π/period each step makes P cycle.

    P then equals itself ``period`` steps back without ever settling; the filter
    must keep computing it (checked against filterpy, step by step).
    """
    angle = 2 * np.pi / period
    rotation = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    A = np.eye(3)
    A[1:, 1:] = rotation
    C = np.array([[1.0, 0.0, 0.0]])
    Q = np.diag([1.0, 0.0, 0.0])
    R = np.array([[1.0]])
    P0 = np.diag([1.0, 4.0, 1.0])
    y = np.random.default_rng(period).normal(size=(200, 1))
    ours = kalman_filter(y, A, C, Q, R, np.zeros(3), P0)
    est, gains, covs, est_covs = filterpy_reference(y, A, C, Q, R, np.zeros(3), P0)
    np.testing.assert_allclose(ours.estimate_covariances, est_covs, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(ours.covariances, covs, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(ours.gains, gains, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(ours.estimates, est, rtol=1e-9, atol=1e-9)
    # The cycle is real: the unobserved variances swap between 4 and 1 (for period 4).
    assert np.ptp(ours.estimate_covariances[-period:, 1, 1]) > 1.0
