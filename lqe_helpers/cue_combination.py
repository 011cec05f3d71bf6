"""Reliability-weighted cue combination: how independent senses of one quantity combine.

Several sensors reading the same position with independent Gaussian noise σ_i are,
together, worth one sensor reading their reliability-weighted mean. The weights are
the reliabilities 1/σ_i² normalised to sum to one, and that one sensor's noise is
σ_eq = (Σ 1/σ_i²)^(−1/2). A Kalman filter fusing such senses splits every gain in
exactly these proportions (its gain is P Cᵀ R⁻¹ with identical rows of C).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from . import validation


def _sigmas(sigmas: Sequence[float] | np.ndarray) -> np.ndarray:
    sigmas = validation.finite_array("sigmas", sigmas, min_ndim=1)
    if sigmas.shape[-1] == 0 or np.any(sigmas <= 0):
        raise ValueError(
            f"sigmas must be one or more noise levels, each > 0 cm, got "
            f"{np.ravel(sigmas)[:6].tolist()} (shape {sigmas.shape})")
    return sigmas


def reliability_weights(sigmas: Sequence[float] | np.ndarray) -> np.ndarray:
    """Each sense's weight ``(1/σ_i²) / Σ_k (1/σ_k²)`` in the combined estimate.

    Parameters
    ----------
    sigmas : array_like, shape (..., m)
        Noise standard deviations of m senses in cm, each > 0; leading axes are batch
        axes (a sweep over σ_p, say).

    Returns
    -------
    ndarray, shape (..., m)
        Weights in [0, 1] summing to one along the last axis.
    """
    relative = _relative_reliabilities(_sigmas(sigmas))
    return relative / relative.sum(axis=-1, keepdims=True)


def combined_sigma(sigmas: Sequence[float] | np.ndarray) -> np.ndarray:
    """Noise σ_eq = (Σ_i 1/σ_i²)^(−1/2) (cm) of the reliability-weighted mean of the senses.

    Parameters
    ----------
    sigmas : array_like, shape (..., m)
        Noise standard deviations of m senses in cm, each > 0.

    Returns
    -------
    ndarray, shape (...)
        Never above the smallest σ_i: adding a sense never makes the combination worse.
    """
    sigmas = _sigmas(sigmas)
    smallest = sigmas.min(axis=-1)
    return smallest / np.sqrt(np.sum(_relative_reliabilities(sigmas), axis=-1))


def _relative_reliabilities(sigmas: np.ndarray) -> np.ndarray:
    """Reliabilities ``1/σ_i²`` in units of the largest, ``(σ_min/σ_i)²`` in (0, 1].

    The same ratios as ``1/σ²`` without its overflow for σ near 1e-300 cm or underflow
    to 0/0 for σ near 1e200 cm.
    """
    return (sigmas.min(axis=-1, keepdims=True) / sigmas) ** 2
