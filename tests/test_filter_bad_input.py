"""Every bad-input path of kalman_filter names the parameter, the value and the rule."""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers.filter import kalman_filter

GOOD = {
    "y": np.zeros((10, 1)),
    "A": np.eye(3),
    "C": np.array([[1.0, 0.0, 0.0]]),
    "Q": np.eye(3),
    "R": np.array([[2.25]]),
    "z0": np.zeros(3),
    "P0": np.eye(3),
}


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"y": np.zeros(10)}, r"y must have at least 2 axes, got shape \(10,\)"),
        ({"y": np.zeros((0, 1))},
         r"y must hold at least one number, got an empty array of shape \(0, 1\)"),
        ({"y": np.array([[1.0], [np.nan]])}, "y must contain only finite numbers, got 1 NaN"),
        ({"y": np.array([[1.0], [np.inf]])}, "y must contain only finite numbers"),
        ({"A": np.eye(3)[:2]}, r"A must have trailing shape \(n, n\), got shape \(2, 3\)"),
        ({"A": np.stack([np.eye(3)] * 2)}, r"A must have shape \(k, k\), got shape \(2, 3, 3\)"),
        ({"C": np.array([[1.0, 0.0]])}, r"C must have shape \(m, k\) = \(1, 3\)"),
        ({"Q": -np.eye(3)}, "Q must be positive semidefinite"),
        ({"Q": np.triu(np.ones((3, 3)))}, "Q must be symmetric"),
        ({"R": np.array([[0.0]])}, "R must be positive definite"),
        ({"R": np.array([[-2.25]])}, "R must be positive definite"),
        ({"R": np.eye(2)}, r"R must have trailing shape \(1, 1\), got shape \(2, 2\)"),
        ({"z0": np.zeros(2)}, r"z0 must have trailing length k = 3, got shape \(2,\)"),
        ({"z0": np.array([0.0, np.nan, 0.0])}, "z0 must contain only finite"),
        ({"P0": np.diag([1.0, -1.0, 1.0])}, "P0 must be positive semidefinite"),
        ({"P0": np.eye(2)}, r"P0 must have trailing shape \(3, 3\)"),
        ({"P0": "big"}, "P0 must be a numeric array, got 'big'"),
        (
            {"y": np.zeros((4, 10, 1)), "R": np.stack([np.eye(1)] * 3)},
            r"leading batch axes must broadcast against each other, got y \(4,\), R \(3,\)",
        ),
        ({"B": np.ones((3, 1))}, "B and u must be given together"),
        ({"u": np.ones((10, 1))}, "B and u must be given together"),
        ({"B": np.ones((2, 1)), "u": np.ones((10, 1))}, r"B must have shape \(3, p\)"),
        (
            {"B": np.ones((3, 1)), "u": np.ones((9, 1))},
            r"u must have trailing shape \(n, p\) = \(10, 1\) to match y and B, got shape \(9, 1\)",
        ),
        (
            {"B": np.ones((3, 2)), "u": np.ones((10, 1))},
            r"u must have trailing shape \(n, p\) = \(10, 2\) to match y and B, "
            r"got shape \(10, 1\)",
        ),
        (
            {"B": np.ones((3, 1)), "u": np.full((10, 1), np.nan)},
            "u must contain only finite numbers, got 10 NaN",
        ),
        (
            {"y": np.zeros((2, 10, 1)), "B": np.ones((3, 1)), "u": np.ones((4, 10, 1))},
            r"leading batch axes must broadcast against each other, got y \(2,\), .*u \(4,\)",
        ),
    ],
)
def test_bad_input(change: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        kalman_filter(**{**GOOD, **change})
