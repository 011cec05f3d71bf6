"""Matrices of a filter's model from inputs already checked (internal to lqe_helpers).

The formulas behind :func:`lqe_helpers.model.process_noise_covariance` and
:func:`lqe_helpers.bias_model.process_noise_covariance` (Lesson 0.5 eq. (9)),
:func:`lqe_helpers.model.observation_matrix` (Tutorial eq. (3)),
:func:`lqe_helpers.model.measurement_noise_covariance` (Tutorial eq. (6)) and
:func:`lqe_helpers.model.diagonal_covariance`. Those public functions check their
inputs and call these; so do the one builder of the filter's model
(:func:`lqe_helpers.experiments.filter_model`, ``bias_model.filter_model``) and the
runs (``experiments.track``, ``bias_model.unbiased_run``) after checking
their own inputs, so that a value (σ_v from a slider, say) is checked once on its way
to the filter, at the public entry it came through. Nothing here checks anything: call
these only with values a public entry has checked.
"""

from __future__ import annotations

import numpy as np


def input_noise_covariance(g: np.ndarray, sigma: float) -> np.ndarray:
    """``G σ² Gᵀ``: what an input's noise of σ adds each step (Lesson 0.5 eq. (9)), (k, k).

    ``g`` (k, 1) is the input matrix, ``sigma`` the input's standard deviation (>= 0),
    both already checked.
    """
    return sigma**2 * (g @ g.T)


def observation(n_sensors: int) -> np.ndarray:
    """C of ``n_sensors`` sensors that each read the position (Tutorial eq. (3)), (m, 3)."""
    return np.tile([1.0, 0.0, 0.0], (n_sensors, 1))


def noise_covariance(sigmas: np.ndarray) -> np.ndarray:
    """``R = diag(σ²)`` of independent sensors (Tutorial eq. (6)), shape (..., m, m).

    ``sigmas`` (cm), shape (..., m): finite and > 0, already checked.
    """
    return (sigmas**2)[..., :, None] * np.eye(sigmas.shape[-1])


def scaled_identity(variance: np.ndarray, size: int) -> np.ndarray:
    """``variance · I`` of dimension ``size``, shape (..., size, size); inputs already checked."""
    return variance[..., None, None] * np.eye(size)
