"""Checks of notebook 03, question (c): C and R for vision and proprioception."""

from __future__ import annotations

import numpy as np

from .machinery import MATRIX_RTOL, CheckFailed, argument_array, passed, positive_number

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback


def check_fusion(C: np.ndarray, R: np.ndarray, sigma_v: float, sigma_p: float) -> None:
    """Check C and R for vision and proprioception (Tutorial eqs. (3), (6)).

    Expected: ``C = [[1, 0, 0], [1, 0, 0]]`` (both senses read the position of the state
    [p, v, a]; vision is row 0, proprioception row 1) and ``R = diag(σ_v², σ_p²)`` in
    cm², each within :data:`MATRIX_RTOL`.

    Parameters
    ----------
    C : array_like, shape (2, 3)
        The student's observation matrix.
    R : array_like, shape (2, 2)
        The student's sensor noise covariance (cm²).
    sigma_v, sigma_p : float
        The noise standard deviations (cm) the student used, > 0.

    Raises
    ------
    CheckFailed
        With the mistake named: wrong shape, transposed C, a row not reading position,
        standard deviations instead of variances, off-diagonal terms, swapped rows, ...
    """
    sigma_v = positive_number(sigma_v, "sigma_v", "cm")
    sigma_p = positive_number(sigma_p, "sigma_p", "cm")
    C = argument_array(C, "C", "the observation matrix, an array of shape (2, 3)")
    R = argument_array(R, "R", "the noise covariance (cm²), an array of shape (2, 2)")
    _check_fusion_C(C)
    _check_fusion_R(R, sigma_v, sigma_p)
    passed(f"C (2 × 3) reads the position p for vision and for proprioception, and "
           f"R = diag(σ_v², σ_p²) = diag({sigma_v**2:g}, {sigma_p**2:g}) cm² (2 × 2)")


def _check_fusion_C(C: np.ndarray) -> None:
    position = np.array([1.0, 0.0, 0.0])
    if C.shape == (3, 2):
        raise CheckFailed(
            "C has shape (3, 2): it is transposed. C has one row per sensor (vision, "
            "proprioception) and one column per state (p, v, a): shape (2, 3)")
    if C.shape in ((3,), (1, 3)):
        raise CheckFailed(
            f"C has shape {C.shape}: one row only. With two senses C needs one row per "
            f"sensor, vision and proprioception: shape (2, 3)")
    if C.shape != (2, 3):
        raise CheckFailed(
            f"C must have shape (2, 3): one row per sensor (vision, proprioception), one "
            f"column per state (p, v, a); got shape {C.shape}")
    labels = ("vision", "proprioception")
    for row, label in enumerate(labels):
        if np.allclose(C[row], position, rtol=0, atol=MATRIX_RTOL):
            continue
        read = [s for s, c in zip(("position p", "velocity v", "acceleration a"), C[row],
                                  strict=True) if c != 0]
        reads = " and ".join(read) if read else "nothing (all zeros)"
        raise CheckFailed(
            f"C's row {row} ({label}) is {C[row].tolist()}, which reads {reads}. "
            f"{label.capitalize()} measures the position only: its row must pick out p "
            f"from the state [p, v, a], with weight 1")


def _check_fusion_R(R: np.ndarray, sigma_v: float, sigma_p: float) -> None:
    variances = np.array([sigma_v**2, sigma_p**2])
    if R.ndim < 2 and R.size == 2:
        raise CheckFailed(
            f"R has shape {R.shape}: a vector. R is a 2 × 2 covariance matrix with the "
            f"two variances on its diagonal")
    if R.shape != (2, 2):
        raise CheckFailed(
            f"R must have shape (2, 2), one row and column per sensor, got shape {R.shape}")

    def same(a: np.ndarray, b: np.ndarray) -> bool:
        return bool(np.allclose(a, b, rtol=MATRIX_RTOL, atol=0.0))

    expected = np.diag(variances)
    if same(R, expected):
        return
    off = R[0, 1] != 0 or R[1, 0] != 0
    diag = np.diag(R)
    if off:
        raise CheckFailed(
            f"R has off-diagonal entries ({R[0, 1]:g}, {R[1, 0]:g}). Vision and "
            f"proprioception are independent (Tutorial eq. (6)): their covariances, the "
            f"off-diagonal entries, are 0")
    if same(diag, np.array([sigma_v, sigma_p])):
        raise CheckFailed(
            f"R holds the standard deviations σ_v = {sigma_v:g} and σ_p = {sigma_p:g} cm. "
            f"R is a covariance: its diagonal holds variances, in cm²")
    if same(diag, variances[::-1]):
        raise CheckFailed(
            "R's rows are swapped: row 0 must be vision's variance and row 1 "
            "proprioception's, in the same order as the rows of C")
    if same(diag, np.array([sigma_v, sigma_p]) ** 4):
        raise CheckFailed("R's diagonal holds σ⁴: the variances σ² were squared again")
    raise CheckFailed(
        f"R's diagonal is {diag.tolist()} cm²; for σ_v = {sigma_v:g} cm and σ_p = "
        f"{sigma_p:g} cm it must hold their variances")
