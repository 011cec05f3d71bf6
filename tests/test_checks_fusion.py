"""Checks of notebook 03: C and R for two senses; the worked answer passes, slips fail."""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, model

C_FUSED = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])


def test_check_fusion_passes_the_worked_solution(capsys) -> None:
    C = model.observation_matrix(("vision", "proprioception"))
    R = model.measurement_noise_covariance([1.5, 4.5])
    line = assert_passes(capsys, checks.check_fusion, C, R, 1.5, 4.5)
    assert "diag(2.25, 20.25) cm²" in line


@pytest.mark.parametrize(("C", "R", "phrase"), [
    (C_FUSED.T, np.diag([2.25, 20.25]), "it is transposed"),
    (C_FUSED[:1], np.diag([2.25, 20.25]), "one row only"),
    (np.array([[1.0, 0, 0], [0, 1.0, 0]]), np.diag([2.25, 20.25]),
     "row 1 (proprioception) is [0.0, 1.0, 0.0], which reads velocity v"),
    (C_FUSED, np.diag([1.5, 4.5]), "R holds the standard deviations"),
    (C_FUSED, np.diag([20.25, 2.25]), "R's rows are swapped"),
    (C_FUSED, np.array([[2.25, 6.75], [6.75, 20.25]]), "R has off-diagonal entries"),
    (C_FUSED, np.array([2.25, 20.25]), "R has shape (2,): a vector"),
    (C_FUSED, np.diag([2.25, 20.25, 1.0]), "R must have shape (2, 2)"),
])
def test_check_fusion_names_each_typical_mistake(C, R, phrase: str) -> None:
    assert_fails(phrase, checks.check_fusion, C, R, 1.5, 4.5)


@pytest.mark.parametrize(("C", "R", "sigma_v", "phrase"), [
    (None, np.diag([2.25, 20.25]), 1.5,
     "C must be the observation matrix, an array of shape (2, 3), got None"),
    (C_FUSED, None, 1.5,
     "R must be the noise covariance (cm²), an array of shape (2, 2), got None"),
    (1e200 * C_FUSED, np.diag([2.25, 20.25]), 1.5, "got values too large to square"),
    (C_FUSED, np.diag([2.25, 20.25]) + 0j, 1.5, "R must be the noise covariance (cm²), an array "
                                                "of shape (2, 2), got complex numbers"),
    (C_FUSED, np.diag([2.25, np.nan]), 1.5, "got NaN (not a number) or an infinite value at "
                                            "index (1, 1)"),
    (C_FUSED, np.diag([2.25, 20.25]), True, "sigma_v must be a number > 0 cm, got True (a "
                                            "boolean)"),
    (C_FUSED, np.diag([2.25, 20.25]), 1e300, "sigma_v must be a number > 0 cm, got values too "
                                             "large to square"),
])
def test_check_fusion_names_a_bad_argument(C, R, sigma_v, phrase: str) -> None:
    assert_fails(phrase, checks.check_fusion, C, R, sigma_v, 4.5)
