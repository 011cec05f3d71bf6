"""Input checks shared by the public API.

Every check raises :class:`ValueError` whose message names the parameter, the value
received and what is allowed, e.g. ``"sigma_v must be > 0 cm, got -1.5"``.
"""

from __future__ import annotations

import numpy as np

#: Relative tolerance for "symmetric" and "positive semidefinite" checks.
MATRIX_RTOL = 1e-8


def _describe(value: object) -> str:
    """Short text for a received value: the value itself, or the shape of an array."""
    array = np.asarray(value) if not isinstance(value, np.ndarray) else value
    if array.ndim == 0 or array.size <= 4:
        return repr(value if not isinstance(value, np.ndarray) else array.tolist())
    return f"an array of shape {array.shape}"


def positive(name: str, value: float, unit: str = "") -> float:
    """Return ``value`` as a float if it is finite and > 0, else raise ``ValueError``."""
    unit_text = f" {unit}" if unit else ""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number > 0{unit_text}, got {value!r}") from None
    if not np.isfinite(number) or number <= 0:
        raise ValueError(f"{name} must be a finite number > 0{unit_text}, got {value!r}")
    return number


def non_negative(name: str, value: float, unit: str = "") -> float:
    """Return ``value`` as a float if it is finite and >= 0, else raise ``ValueError``."""
    unit_text = f" {unit}" if unit else ""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number >= 0{unit_text}, got {value!r}") from None
    if not np.isfinite(number) or number < 0:
        raise ValueError(f"{name} must be a finite number >= 0{unit_text}, got {value!r}")
    return number


def count(name: str, value: int, minimum: int = 0, maximum: int | None = None) -> int:
    """Return ``value`` if it is a whole number in ``[minimum, maximum]``."""
    allowed = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be a whole number {allowed}, got {value!r}")
    if value < minimum or (maximum is not None and value > maximum):
        raise ValueError(f"{name} must be a whole number {allowed}, got {value!r}")
    return int(value)


def finite_array(name: str, value: object, min_ndim: int = 0) -> np.ndarray:
    """Return ``value`` as a float array with at least ``min_ndim`` axes and no NaN/inf."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a numeric array, got {value!r}") from None
    if array.ndim < min_ndim:
        raise ValueError(
            f"{name} must have at least {min_ndim} axes, got shape {array.shape}"
        )
    if not np.all(np.isfinite(array)):
        bad = int(np.size(array) - np.count_nonzero(np.isfinite(array)))
        raise ValueError(
            f"{name} must contain only finite numbers, got {bad} NaN or infinite "
            f"value(s) in {_describe(array)}"
        )
    return array


def square_matrix(name: str, value: object, size: int | None = None) -> np.ndarray:
    """Return a finite ``(..., n, n)`` array; ``size`` fixes n if given."""
    array = finite_array(name, value, min_ndim=2)
    n, m = array.shape[-2:]
    if n != m or (size is not None and n != size):
        wanted = f"({size}, {size})" if size is not None else "(n, n)"
        raise ValueError(
            f"{name} must have trailing shape {wanted}, got shape {array.shape}"
        )
    return array


def covariance(name: str, value: object, size: int | None = None,
               definite: bool = False) -> np.ndarray:
    """Return a symmetric positive semidefinite (or definite) ``(..., n, n)`` array.

    Symmetry and a semidefinite matrix's eigenvalue sign are checked relative to the
    largest absolute entry, with tolerance :data:`MATRIX_RTOL`; definiteness by the
    existence of a Cholesky factor.
    """
    array = square_matrix(name, value, size)
    scale = np.max(np.abs(array), axis=(-2, -1), keepdims=True)
    scale = np.where(scale > 0, scale, 1.0)
    asymmetry = np.max(np.abs(array - np.swapaxes(array, -1, -2)) / scale)
    if asymmetry > MATRIX_RTOL:
        raise ValueError(
            f"{name} must be symmetric, got {_describe(array)} with relative "
            f"asymmetry {asymmetry:.3g}"
        )
    if definite:
        # Cholesky succeeds exactly for (numerically) positive definite matrices, however
        # different the scales of their entries (R = diag(10⁶, 10⁻⁶) is fine).
        try:
            np.linalg.cholesky(array)
        except np.linalg.LinAlgError:
            raise ValueError(
                f"{name} must be positive definite, got {_describe(array)} (no Cholesky "
                f"factor exists)"
            ) from None
        return array
    eigenvalues = np.linalg.eigvalsh(array) / scale[..., 0]
    smallest = float(np.min(eigenvalues)) if eigenvalues.size else 0.0
    if smallest < -MATRIX_RTOL:
        raise ValueError(
            f"{name} must be positive semidefinite, got {_describe(array)} with an "
            f"eigenvalue of {smallest:.3g} times its largest entry"
        )
    return array


def batch_shape(name: str, array: np.ndarray, core_ndim: int) -> tuple[int, ...]:
    """Leading (batch) axes of ``array`` once its ``core_ndim`` trailing axes are removed."""
    return array.shape[: array.ndim - core_ndim]


def broadcast_batches(**shapes: tuple[int, ...]) -> tuple[int, ...]:
    """Broadcast named batch shapes, raising ``ValueError`` that lists them if they clash."""
    try:
        return np.broadcast_shapes(*shapes.values())
    except ValueError:
        listed = ", ".join(f"{name} {shape}" for name, shape in shapes.items())
        raise ValueError(
            f"leading batch axes must broadcast against each other, got {listed}"
        ) from None
