"""Accuracy of the filter's gains at diffuse priors, against a 50-digit reference.

The reference is Tutorial eq. (5)'s textbook gain ``K = P Cᵀ (C P Cᵀ + R)⁻¹`` evaluated
with mpmath at 50 significant digits from the very same float64 inputs, so it is
exact for those inputs to far below float64 rounding.

Tolerance: 1e-12 relative error per sensor (each column of K against the largest
entry of the same column of the reference), the target of issue 10. The engine
computes the first gain from P0 exactly to rounding, and the worst error measured
over the grid below is about 4e-16, so 1e-12 leaves three orders of magnitude for
other CPUs and BLAS libraries while the former formula ``K = P⁺ Cᵀ R⁻¹`` misses it by
up to twelve orders (an error of 2.4 relative when P0 = 10¹⁰ and σ = 10⁻³).

Later steps start from a covariance the engine computed itself, stored in float64.
When P0/σ² is 10¹⁶ that covariance is nearly singular in the directions the sensors
see, and rounding it to float64 already moves the exact gain by up to
``eps · ‖P‖ ‖L⁻¹C‖²`` relative (L: Cholesky factor of R): no algorithm that keeps P
as a matrix of floats does better. Those gains are tested against the reference from
the engine's own P_j with that bound added to the 1e-12.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from lqe_helpers import model
from lqe_helpers._engine import _covariance_sequence
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT

mpmath.mp.dps = 50

#: Largest relative error of a gain column against the 50-digit reference.
GAIN_RTOL = 1e-12
#: Constant of the rounding bound ``eps · ‖P‖ ‖L⁻¹C‖²`` for gains after the first.
ROUNDING_FACTOR = 100.0

P0_SCALES = (1e-6, 1e-3, 1.0, 1e3, 1e6, 1e10)
SIGMAS = (1e-3, 1e-1, 1.0, 1e1, 1e3)


def _random_spd(rng: np.random.Generator, size: int) -> np.ndarray:
    """A well-conditioned (condition number <= 10) random covariance."""
    q, _ = np.linalg.qr(rng.standard_normal((size, size)))
    return (q * rng.uniform(1.0, 10.0, size)) @ q.T


def _models() -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """(label, A, C, Q, R-shape correlation) for 1–5 states and 1–3 sensors.

    Sensors that combine several states (dense C), two sensors reading one state,
    the pack's own models, and correlated sensor noise.
    """
    rng = np.random.default_rng(20261130)
    cases = [
        ("issue: A = I2, C = [[1, 1]]", np.eye(2), np.array([[1.0, 1.0]]),
         np.zeros((2, 2)), np.eye(1)),
        ("pack, vision", DEFAULT.A, model.observation_matrix(), DEFAULT.Q, np.eye(1)),
        ("pack, vision + proprioception", DEFAULT.A,
         model.observation_matrix(model.SENSORS), DEFAULT.Q, np.eye(2)),
    ]
    for k, m in [(1, 1), (1, 3), (2, 1), (2, 2), (2, 3), (3, 1), (3, 2), (3, 3), (4, 2),
                 (5, 1), (5, 2), (5, 3)]:
        A = np.eye(k) + 0.1 * np.triu(rng.standard_normal((k, k)), 1)
        C = rng.standard_normal((m, k))        # every sensor combines several states
        G = rng.standard_normal((k, k))
        correlation = np.eye(m) if m == 1 else _random_spd(rng, m) / 10.0
        cases.append((f"k={k}, m={m}, dense C", A, C, 1e-2 * G @ G.T, correlation))
    C = np.zeros((3, 5))
    C[:, 0] = 1.0                              # three sensors of one state
    C[2, 1] = 1.0                              # the third also reads the next one
    cases.append(("k=5, m=3, repeated rows", np.eye(5), C, np.zeros((5, 5)), np.eye(3)))
    return cases


def _reference_gain(P: np.ndarray, C: np.ndarray, R: np.ndarray) -> mpmath.matrix:
    """Textbook ``P Cᵀ (C P Cᵀ + R)⁻¹`` at 50 digits from float64 inputs."""
    P, C, R = (mpmath.matrix(x.tolist()) for x in (P, C, R))
    return P * C.T * (C * P * C.T + R) ** -1


def _column_errors(gain: np.ndarray, reference: mpmath.matrix) -> np.ndarray:
    """Relative error of each column of ``gain``: max |difference| / max |reference|."""
    k, m = gain.shape
    errors = np.empty(m)
    for j in range(m):
        difference = max(abs(mpmath.mpf(float(gain[i, j])) - reference[i, j]) for i in range(k))
        scale = max(abs(reference[i, j]) for i in range(k))
        errors[j] = float(difference / scale)
    return errors


def _cases():
    for label, A, C, Q, correlation in _models():
        rng = np.random.default_rng(len(label))
        for p0 in P0_SCALES:
            for sigma in SIGMAS:
                for shape in ("identity", "dense"):
                    P0 = p0 * (np.eye(A.shape[0]) if shape == "identity"
                               else _random_spd(rng, A.shape[0]))
                    R = sigma**2 * correlation
                    yield pytest.param(A, C, Q, R, P0, id=f"{label}, P0 {shape}·{p0:g}, "
                                                         f"σ={sigma:g}")


CASES = list(_cases())


@pytest.mark.parametrize(("A", "C", "Q", "R", "P0"), CASES)
@pytest.mark.slow
def test_first_gain_is_exact_to_rounding(A, C, Q, R, P0) -> None:
    sequence = _covariance_sequence(1, A, C, Q, R, P0)
    errors = _column_errors(sequence.gains[0], _reference_gain(P0, C, R))
    assert np.all(errors <= GAIN_RTOL), f"relative gain errors per sensor {errors}"


def test_issue_example_gain_is_exact() -> None:
    # The issue's case: K = P⁺Cᵀ R⁻¹ was off by 5e-11; the textbook gain is [1/2, 1/2]
    # times 2e10 / (2e10 + 1).
    result = kalman_filter(np.zeros((1, 1)), np.eye(2), [[1.0, 1.0]], np.zeros((2, 2)),
                           [[1.0]], np.zeros(2), 1e10 * np.eye(2))
    exact = mpmath.mpf(10) ** 10 / (2 * mpmath.mpf(10) ** 10 + 1)
    for entry in result.gains[0, :, 0]:
        assert abs(mpmath.mpf(float(entry)) - exact) / exact <= GAIN_RTOL


@pytest.mark.parametrize(("A", "C", "Q", "R", "P0"), CASES[::7])
def test_later_gains_are_exact_for_the_covariance_they_come_from(A, C, Q, R, P0) -> None:
    steps = 4
    sequence = _covariance_sequence(steps, A, C, Q, R, P0)
    whitened = np.linalg.solve(np.linalg.cholesky(R), C)
    priors = [P0, *sequence.covariances[:-1]]     # covariances[j] is P_{j+1}
    for j, prior in enumerate(priors):
        bound = GAIN_RTOL + ROUNDING_FACTOR * np.finfo(float).eps * (
            np.linalg.norm(prior, 2) * np.linalg.norm(whitened, 2) ** 2)
        errors = _column_errors(sequence.gains[j], _reference_gain(prior, C, R))
        assert np.all(errors <= bound), f"step {j}: errors {errors}, bound {bound:.3g}"


def test_the_pack_models_gains_match_the_exact_recursion_over_many_steps() -> None:
    # Where the covariance stays well conditioned (the tutorial's P0 = 10⁵ cm², σ =
    # 1.5 cm) the whole sequence is exact to 1e-12, not just each step given the last.
    C = model.observation_matrix(model.SENSORS)
    R = model.measurement_noise_covariance([1.5, 4.5])
    P0 = 1e5 * np.eye(3)
    steps = 30
    sequence = _covariance_sequence(steps, DEFAULT.A, C, DEFAULT.Q, R, P0)
    A, Cm, Q, Rm, P = (mpmath.matrix(x.tolist()) for x in (DEFAULT.A, C, DEFAULT.Q, R, P0))
    for j in range(steps):
        K = P * Cm.T * (Cm * P * Cm.T + Rm) ** -1
        assert np.all(_column_errors(sequence.gains[j], K) <= GAIN_RTOL), f"step {j}"
        P = A * (P - K * Cm * P) * A.T + Q
