"""The fixed-gain filter against a plain loop and the LQE, and its tuner (issue 23 §5)."""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import experiments, filter, fixed_gain, metrics
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.steady_state import steady_state

TRUTH, BURN = DEFAULT.truth[:, 0], DEFAULT.burn_in_steps


def fixed_gain_loop(y: np.ndarray, A: np.ndarray, C: np.ndarray, K: np.ndarray,
                    z0: np.ndarray) -> np.ndarray:
    """ẑ ← A ẑ + K (y_j − C A ẑ), one reading at a time; y (n, m) → (n, k)."""
    z, out = np.array(z0, dtype=float), []
    for reading in y:
        predicted = A @ z
        z = predicted + K @ (reading - C @ predicted)
        out.append(z)
    return np.array(out)


def test_fixed_gain_filter_matches_a_loop_for_runs_and_a_grid_of_gains() -> None:
    rng = np.random.default_rng(3)
    A = np.eye(3) + 0.1 * rng.normal(size=(3, 3))
    C = rng.normal(size=(2, 3))
    y = rng.normal(size=(4, 50, 2))
    gains = 0.3 * rng.normal(size=(5, 3, 2))
    z0 = rng.normal(size=3)
    out = fixed_gain.fixed_gain_filter(y, A, C, gains[:, None], z0)
    assert out.shape == (5, 4, 50, 3)
    for g in range(5):
        np.testing.assert_allclose(fixed_gain.fixed_gain_filter(y, A, C, gains[g], z0),
                                   out[g], rtol=1e-12, atol=1e-12)
        for r in range(4):
            np.testing.assert_allclose(out[g, r], fixed_gain_loop(y[r], A, C, gains[g], z0),
                                       rtol=1e-10, atol=1e-10)


def test_with_the_settled_gain_it_is_the_lqe_started_at_its_steady_state() -> None:
    tracking = experiments.track(DEFAULT, runs=3)
    model = tracking.model
    settled = steady_state(model.A, model.C, model.Q, model.R)
    lqe = filter.kalman_filter(tracking.measurements, model.A, model.C, model.Q, model.R,
                               model.z0, settled.covariance)
    assert np.max(np.abs(lqe.gains - settled.gain)) < 1e-9 * np.max(np.abs(settled.gain))
    np.testing.assert_allclose(
        fixed_gain.fixed_gain_filter(tracking.measurements, model.A, model.C, settled.gain,
                                     model.z0),
        lqe.estimates, rtol=1e-8, atol=1e-9)


def test_the_tuned_gain_is_a_local_optimum_at_least_as_good_as_the_lqe_on_its_runs() -> None:
    tracking = experiments.track(DEFAULT, runs=20)
    model = tracking.model
    settled = steady_state(model.A, model.C, model.Q, model.R)
    tuned = fixed_gain.tune_fixed_gain(tracking.measurements, model.A, model.C, model.z0,
                                       TRUTH, settled.gain, BURN)
    assert tuned.mse.mean() <= tracking.mse().mean()
    assert tuned.mse.mean() <= tuned.start_mse.mean()
    assert not np.allclose(tuned.gain, settled.gain, rtol=1e-3)

    def mean_mse(gain: np.ndarray) -> float:
        estimates = fixed_gain.fixed_gain_filter(tracking.measurements, model.A, model.C,
                                                 gain, model.z0)
        return float(metrics.mse(estimates[..., 0], TRUTH, BURN).mean())

    assert mean_mse(tuned.gain) == pytest.approx(tuned.mse.mean(), rel=1e-12)
    for index in np.ndindex(tuned.gain.shape):
        for factor in (0.99, 1.01):
            nudged = tuned.gain.copy()
            nudged[index] *= factor
            assert mean_mse(nudged) >= tuned.mse.mean() * (1 - 1e-9), (index, factor)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"K": np.ones((3, 2))}, r"K must have shape \(\.\.\., k, m\) = \(\.\.\., 3, 1\)"),
    ({"z0": np.zeros(2)}, r"z0 must have shape \(3,\)"),
    ({"C": np.ones((1, 2))}, r"C must have shape \(m, k\)"),
])
def test_fixed_gain_filter_names_the_bad_input(kwargs, message) -> None:
    inputs = {"y": np.zeros((5, 1)), "A": np.eye(3), "C": np.array([[1.0, 0.0, 0.0]]),
              "K": np.ones((3, 1)), "z0": np.zeros(3)} | kwargs
    with pytest.raises(ValueError, match=message):
        fixed_gain.fixed_gain_filter(**inputs)


def test_tune_fixed_gain_refuses_a_zero_entry_in_the_start() -> None:
    with pytest.raises(ValueError, match=r"start must be a .* non-zero, got"):
        fixed_gain.tune_fixed_gain(np.zeros((2, 5, 1)), np.eye(3), np.array([[1.0, 0, 0]]),
                                   np.zeros(3), np.zeros(5), np.array([[1.0], [0.0], [1.0]]))
