"""Checks of notebook 02: P0 and the convergence time; worked answers pass, slips fail."""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, metrics, model

# ------------------------------------------------------------------------------------------
# check_initial_covariance
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("variance", [1.0, 1e5])
def test_check_initial_covariance_passes_the_worked_solution(capsys, variance) -> None:
    line = assert_passes(capsys, checks.check_initial_covariance,
                         model.diagonal_covariance(variance), variance)
    assert line == f"✓ P0 = {variance:g} · I (3 × 3, diagonal) cm²"


@pytest.mark.parametrize(("P0", "phrase"), [
    (np.sqrt(1e5) * np.eye(3), "a standard deviation"),
    (1e5, "P0 is a single number"),
    (np.full(3, 1e5), "P0 is a vector of 3 numbers"),
    (1e5 * np.eye(2), "P0 must be 3 × 3"),
    (np.full((3, 3), 1e5), "every entry of P0 is 100000"),
    (np.diag([1e5, 1e5, 1.0]), "P0's diagonal entries differ"),
    (1e10 * np.eye(3), "the variance was squared again"),
])
def test_check_initial_covariance_names_each_typical_mistake(P0, phrase: str) -> None:
    assert_fails(phrase, checks.check_initial_covariance, P0, 1e5)


@pytest.mark.parametrize(("P0", "variance", "phrase"), [
    (None, 1e5, "P0 must be the initial covariance, a 3 × 3 matrix (cm², cm²/s², cm²/s⁴), "
                "got None"),
    ([[1e5, 0, 0], [0, 1e5, 0], [0, 0, 1e5]], 1e5, "got a Python list, not a NumPy array"),
    (np.eye(3) * (1e5 + 0j), 1e5, "got complex numbers (dtype complex128)"),
    (np.eye(3) * 1e5, "1e5", "variance must be a number > 0 cm², got text ('1e5')"),
    (np.eye(3) * 1e5, -1.0, "variance must be a number > 0 cm², got -1"),
])
def test_check_initial_covariance_names_a_bad_argument(P0, variance, phrase) -> None:
    assert_fails(phrase, checks.check_initial_covariance, P0, variance)


# ------------------------------------------------------------------------------------------
# check_convergence_time
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def squared_errors() -> np.ndarray:
    """Squared errors of 200 runs that decay from 30 to 1 cm² with time constant 0.3 s."""
    rng = np.random.default_rng(11)
    t = np.arange(500) * 0.01
    level = 1.0 + 29.0 * np.exp(-t / 0.3)
    return level * rng.normal(size=(200, 500)) ** 2


def test_check_convergence_time_passes_the_worked_solution(capsys, squared_errors) -> None:
    curve = squared_errors.mean(axis=0)
    value = float(metrics.convergence_time(curve, 0.01))
    assert 0.5 < value < 2.0
    line = assert_passes(capsys, checks.check_convergence_time, value, curve, 0.01)
    assert "within 2 × its second-half level" in line
    line = assert_passes(capsys, checks.check_convergence_time, value, squared_errors, 0.01)
    assert "the Monte Carlo mean squared error" in line


def test_check_convergence_time_names_each_typical_mistake(squared_errors) -> None:
    curve = squared_errors.mean(axis=0)
    dt = 0.01
    steps = int(metrics.convergence_time(curve, dt) / dt + 0.5)
    per_run = metrics.convergence_time(squared_errors, dt)
    band = curve <= 2.0 * curve[250:].mean()
    assert np.argmax(band) < steps          # the curve enters the band, then leaves it again
    cases = [
        ("your convergence time is in samples", steps, curve),
        ("that of a single run (the first)", per_run[0], squared_errors),
        ("mean of the runs' convergence times", float(per_run.mean()), squared_errors),
        ("one convergence time per run", per_run, squared_errors),
        ("first time the curve enters the band", np.argmax(band) * dt, curve),
        ("last sample outside the band", (steps - 1) * dt, curve),
    ]
    for phrase, value, errors in cases:
        assert_fails(phrase, checks.check_convergence_time, value, errors, dt)
