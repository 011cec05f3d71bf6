"""Reliability weights and the combined noise, by hand and against the fused Kalman gain."""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import model
from lqe_helpers.cue_combination import combined_sigma, reliability_weights
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.steady_state import steady_state


def test_equal_senses_split_evenly_and_gain_root_two():
    np.testing.assert_allclose(reliability_weights([1.5, 1.5]), [0.5, 0.5])
    assert combined_sigma([1.5, 1.5]) == pytest.approx(1.5 / np.sqrt(2))


def test_question_d_values_by_hand():
    # 1/1.5² = 4/9 and 1/4.5² = 4/81: weights 9/10 and 1/10; σ_eq² = 81/40.
    np.testing.assert_allclose(reliability_weights([1.5, 4.5]), [0.9, 0.1])
    assert combined_sigma([1.5, 4.5]) == pytest.approx(np.sqrt(81 / 40))


def test_one_sense_is_itself_and_batches_broadcast():
    assert combined_sigma([2.0]) == pytest.approx(2.0)
    sigma_p = np.array([0.5, 1.5, 4.5, 100.0])
    pairs = np.stack([np.full_like(sigma_p, 1.5), sigma_p], axis=-1)
    weights = reliability_weights(pairs)
    assert weights.shape == (4, 2)
    np.testing.assert_allclose(weights.sum(axis=-1), 1.0)
    assert np.all(np.diff(weights[:, 1]) < 0)  # a noisier sense counts for less
    assert np.all(combined_sigma(pairs) < np.minimum(1.5, sigma_p))


def test_weights_are_the_fused_kalman_gain_shares():
    sigma_p = np.array([0.75, 1.5, 4.5, 30.0])
    pairs = np.stack([np.full_like(sigma_p, DEFAULT.sigma_v), sigma_p], axis=-1)
    gain = steady_state(DEFAULT.A, model.observation_matrix(("vision", "proprioception")),
                        DEFAULT.Q, model.measurement_noise_covariance(pairs)).gain
    shares = gain[..., 0, :] / gain[..., 0, :].sum(axis=-1, keepdims=True)
    np.testing.assert_allclose(shares, reliability_weights(pairs), rtol=1e-9)


@pytest.mark.parametrize("sigmas", [[], [1.0, 0.0], [-1.0], [1.0, np.inf]])
def test_bad_sigmas_are_refused(sigmas):
    with pytest.raises(ValueError, match="sigmas"):
        reliability_weights(sigmas)
    with pytest.raises(ValueError, match="sigmas"):
        combined_sigma(sigmas)
