"""Checks of notebook 06: F, G and Q of the bias model; the worked answer passes, slips fail."""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import bias_model, checks

# --- check_bias_model ------------------------------------------------------------------------

DT, SIGMA_A = 0.01, 20.0


def bias_matrices(*, mistake=""):
    F = bias_model.transition_matrix(DT).copy()
    G = bias_model.input_matrix(DT).copy()
    sigma = SIGMA_A if mistake != "sigma" else np.sqrt(SIGMA_A)
    if mistake == "bias added":
        F[:2, 2] *= -1
    if mistake == "G no half":
        G[0, 0] = DT**2
    if mistake == "G flat":
        G = G[:, 0]
        return F, G, sigma**2 * np.outer(G, G)
    Q = sigma**2 * G @ G.T
    if mistake == "Q identity":
        Q = SIGMA_A**2 * np.eye(3)
    return F, G, Q


def test_check_bias_model_passes_the_worked_solution(capsys):
    assert_passes(capsys, checks.check_bias_model, *bias_matrices(), DT, SIGMA_A)


@pytest.mark.parametrize(("mistake", "phrase"), [
    ("bias added", "adds the bias"),
    ("G no half", "G[0] holds Δt²"),
    ("G flat", "make it a column"),
    ("sigma", "uses σ_a where its square belongs"),
    ("Q identity", "is not pushed through G"),
])
def test_check_bias_model_names_each_typical_mistake(mistake, phrase):
    assert_fails(phrase, checks.check_bias_model, *bias_matrices(mistake=mistake), DT, SIGMA_A)


def test_check_bias_model_names_a_bad_argument():
    F, G, Q = bias_matrices()
    assert_fails("F must be the transition matrix, an array of shape (3, 3), got None",
                 checks.check_bias_model, None, G, Q, DT, SIGMA_A)
    assert_fails("dt must be a number > 0 s, got NaN", checks.check_bias_model, F, G, Q,
                 np.nan, SIGMA_A)
    assert_fails("Q must be the process noise covariance, an array of shape (3, 3), got values "
                 "too large to square", checks.check_bias_model, F, G, Q * 1e300, DT, SIGMA_A)
