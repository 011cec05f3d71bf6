"""The Riccati fixed point, against scipy and against running the recursion."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import solve_discrete_are

from lqe_helpers import model
from lqe_helpers.steady_state import steady_state, undetectable_modes


@pytest.mark.parametrize("sigmas", [[1.5], [4.5], [1.5, 1.5], [1.5, 4.5], [1e-3], [1e3]])
def test_matches_scipy_dare(sigmas: list[float]) -> None:
    dt = 0.01
    A = model.transition_matrix(dt)
    Q = model.process_noise_covariance(dt, 1400.0)
    C = model.observation_matrix(("vision", "proprioception")[: len(sigmas)])
    R = model.measurement_noise_covariance(sigmas)
    ours = steady_state(A, C, Q, R)
    reference = solve_discrete_are(A.T, C.T, Q, R)
    np.testing.assert_allclose(ours.covariance, reference, rtol=1e-7, atol=1e-12)
    # It is a fixed point of Tutorial eq. (5)'s covariance line.
    P = ours.covariance
    S = C @ P @ C.T + R
    again = A @ (P - P @ C.T @ np.linalg.solve(S, C @ P)) @ A.T + Q
    np.testing.assert_allclose(again, P, rtol=1e-9)
    np.testing.assert_allclose(ours.gain, P @ C.T @ np.linalg.inv(S), rtol=1e-9)


def test_two_equal_sensors_equal_one_sensor_with_half_the_variance() -> None:
    dt = 0.01
    A, Q = model.transition_matrix(dt), model.process_noise_covariance(dt, 1400.0)
    fused = steady_state(A, model.observation_matrix(("vision", "proprioception")), Q,
                         model.measurement_noise_covariance([1.5, 1.5]))
    single = steady_state(A, model.observation_matrix(), Q,
                          model.measurement_noise_covariance([1.5 / np.sqrt(2)]))
    np.testing.assert_allclose(fused.estimate_covariance, single.estimate_covariance, rtol=1e-9)


def test_batched_r_gives_one_steady_state_each() -> None:
    dt = 0.01
    A, Q = model.transition_matrix(dt), model.process_noise_covariance(dt, 1400.0)
    C = model.observation_matrix()
    R = model.measurement_noise_covariance(np.array([[0.5], [1.5], [4.5]]))
    batch = steady_state(A, C, Q, R)
    assert batch.covariance.shape == (3, 3, 3)
    for i in range(3):
        np.testing.assert_allclose(batch.covariance[i], steady_state(A, C, Q, R[i]).covariance,
                                   rtol=1e-12)
    # More sensor noise, more estimation error.
    assert np.all(np.diff(batch.estimate_covariance[:, 0, 0]) > 0)


def test_unobservable_unstable_mode_is_reported() -> None:
    A = np.diag([1.0, 1.1])  # the second state grows and nothing measures it
    with pytest.raises(ValueError, match=r"\(A, C\) must be detectable .* got C = "
                                         r"\[\[1.0, 0.0\]\], which cannot see the state "
                                         r"direction\(s\) \[\[0.0, 1.0\]\], on which A has "
                                         r"eigenvalue\(s\) \[1.1\]"):
        steady_state(A, [[1.0, 0.0]], np.eye(2), [[1.0]])


@pytest.mark.parametrize(
    ("C", "directions", "eigenvalues"),
    [
        ([[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]], [1.0]),    # velocity only: position unseen
        ([[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [1.0, 1.0]),  # acceleration
        ([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]], [1.0]),
    ],
)
def test_unobservable_position_is_reported_as_not_detectable(
        C: list, directions: list, eigenvalues: list) -> None:
    # The marginal modes of the constant-acceleration model grow without bound but
    # slowly (P doubles each doubling step, never overflows): before the check the
    # message was "allow more doubling steps", which cannot help.
    A = model.transition_matrix(0.01)
    Q = model.process_noise_covariance(0.01, 1400.0)
    R = np.eye(len(C))
    with pytest.raises(ValueError) as error:
        steady_state(A, C, Q, R)
    message = str(error.value)
    assert message.startswith("(A, C) must be detectable (C must observe every mode of A "
                              "that does not decay), got C = ")
    assert f"cannot see the state direction(s) {directions}" in message
    assert f"eigenvalue(s) {eigenvalues} of modulus >= 1" in message
    assert "doubling" not in message


@pytest.mark.parametrize(
    ("A", "C", "detectable"),
    [
        (np.diag([1.0, 1.1]), [[0.0, 1.0]], False),   # the marginal state is unseen
        (np.diag([0.5, 1.1]), [[0.0, 1.0]], True),    # the unseen state decays
        (np.diag([0.5, 0.9]), [[0.0, 0.0]], True),    # nothing seen, everything decays
        ([[0.0, -1.0], [1.0, 0.0]], [[0.0, 0.0]], False),  # a rotation, |λ| = 1, unseen
        ([[0.0, -1.0], [1.0, 0.0]], [[1.0, 0.0]], True),   # a rotation seen through x
        (model.transition_matrix(1e-4), [[1.0, 0.0, 0.0]], True),  # tiny Δt, position seen
    ],
)
def test_detectability_matches_the_pbh_rank_test(A, C, detectable: bool) -> None:
    # Independent check: Popov–Belevitch–Hautus, rank [A − λI; C] = k for every
    # eigenvalue with |λ| >= 1 (exact eigenvalues here: diagonal, rotation, Jordan 1).
    A, C = np.asarray(A, float), np.asarray(C, float)
    k = A.shape[0]
    pbh = all(np.linalg.matrix_rank(np.vstack([A - lam * np.eye(k), C]), tol=1e-9) == k
              for lam in np.linalg.eigvals(A) if abs(lam) >= 1 - 1e-6)
    assert pbh == detectable
    directions, eigenvalues = undetectable_modes(A, C)
    assert (directions.shape[1] == 0) == detectable
    assert (eigenvalues.size == 0) == detectable


def test_running_out_of_doublings_is_not_reported_as_no_fixed_point() -> None:
    A = model.transition_matrix(0.01)
    Q = model.process_noise_covariance(0.01, 1400.0)
    C, R = model.observation_matrix(), model.measurement_noise_covariance([1.5])
    with pytest.raises(ValueError, match=r"max_doublings = 2 was too few to reach "
                                         r"rtol = 1e-13: the last relative change of P was "
                                         r"\d") as error:
        steady_state(A, C, Q, R, max_doublings=2)
    assert "no finite fixed point" not in str(error.value)
    # Enough doublings for the same problem converge.
    assert np.all(np.isfinite(steady_state(A, C, Q, R, max_doublings=60).covariance))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"R": [[-1.0]]}, "R must be positive definite"),
        ({"Q": [[1.0, 2.0, 0], [0, 1.0, 0], [0, 0, 1.0]]}, "Q must be symmetric"),
        ({"C": [[1.0, 0.0]]}, r"C must have shape \(m, 3\)"),
        ({"max_doublings": 0}, "max_doublings must be a whole number >= 1, got 0"),
    ],
)
def test_bad_input(kwargs: dict, message: str) -> None:
    args = {"A": model.transition_matrix(0.01), "C": [[1.0, 0.0, 0.0]],
            "Q": model.process_noise_covariance(0.01, 1.0), "R": [[1.0]]}
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        steady_state(**args)
