"""The filter with a known input (B, u) equals filterpy's predict(u=...)/update.

Mapping (see ``kalman_filter``'s docstring): ``u_j`` is the input over the step that
ends at ``y_j`` and ``z0`` the estimate one step before ``y_0``. So filterpy starts
from ``x = A z0 + B u_0`` and ``P = P0``; then for each j it runs ``update(y_j)``,
which gives our ``estimates[j]``, ``gains[j]`` and ``estimate_covariances[j]``, and
``predict(u=u_{j+1})``, whose P is our ``covariances[j]``.
"""

from __future__ import annotations

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from lqe_helpers.filter import kalman_filter


def random_covariance(rng: np.random.Generator, size: int, floor: float = 0.0) -> np.ndarray:
    """A random symmetric positive (semi)definite matrix with eigenvalues >= floor."""
    root = rng.normal(size=(size, size))
    return root @ root.T + floor * np.eye(size)


def random_model(seed: int, k: int, m: int, p: int) -> dict[str, np.ndarray]:
    """A random stable-ish linear model with an input, and its initial estimate."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(k, k))
    A *= 0.98 / max(1.0, np.max(np.abs(np.linalg.eigvals(A))))
    return {
        "A": A,
        "B": rng.normal(size=(k, p)),
        "C": rng.normal(size=(m, k)),
        "Q": random_covariance(rng, k) * 0.1,
        "R": random_covariance(rng, m, floor=0.5),
        "P0": random_covariance(rng, k, floor=0.1),
        "z0": rng.normal(size=k),
    }


def filterpy_run(model: dict[str, np.ndarray], y: np.ndarray, u: np.ndarray,
                 R: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """One unbatched run through filterpy, recorded in our FilterResult's layout."""
    A, B, C = model["A"], model["B"], model["C"]
    k, m, p = A.shape[0], C.shape[0], B.shape[1]
    kf = KalmanFilter(dim_x=k, dim_z=m, dim_u=p)
    kf.F, kf.B, kf.H, kf.Q = A, B, C, model["Q"]
    kf.R = model["R"] if R is None else R
    kf.P = model["P0"].copy()
    kf.x = (A @ model["z0"] + B @ u[0])[:, None]
    out: dict[str, list[np.ndarray]] = {
        "estimates": [], "gains": [], "estimate_covariances": [], "covariances": []}
    n = y.shape[0]
    for j in range(n):
        kf.update(y[j][:, None])
        out["estimates"].append(kf.x[:, 0].copy())
        out["gains"].append(kf.K.copy())
        out["estimate_covariances"].append(kf.P.copy())
        # The input of the next step; after the last measurement it cannot change P.
        following = u[j + 1] if j + 1 < n else np.zeros(p)
        kf.predict(u=following[:, None])
        out["covariances"].append(kf.P.copy())
    return {name: np.stack(values) for name, values in out.items()}


def assert_matches(ours, theirs: dict[str, np.ndarray]) -> None:
    for name, expected in theirs.items():
        np.testing.assert_allclose(getattr(ours, name), expected, rtol=1e-9, atol=1e-9,
                                   err_msg=name)


@pytest.mark.parametrize(("seed", "k", "m", "p"),
                         [(0, 3, 1, 1), (1, 3, 2, 1), (2, 2, 1, 2), (3, 4, 2, 3)])
def test_unbatched_run_equals_filterpy(seed: int, k: int, m: int, p: int) -> None:
    model = random_model(seed, k, m, p)
    rng = np.random.default_rng(100 + seed)
    n = 40
    y = rng.normal(size=(n, m)) * 3.0
    u = rng.normal(size=(n, p)) * 2.0
    ours = kalman_filter(y, model["A"], model["C"], model["Q"], model["R"], model["z0"],
                         model["P0"], B=model["B"], u=u)
    assert_matches(ours, filterpy_run(model, y, u))


@pytest.mark.parametrize("seed", [4, 5])
def test_batched_runs_equal_filterpy_run_by_run(seed: int) -> None:
    """u batched like y (runs, n, p): every run matches its own filterpy run."""
    model = random_model(seed, 3, 2, 1)
    rng = np.random.default_rng(200 + seed)
    runs, n = 4, 30
    y = rng.normal(size=(runs, n, 2))
    u = rng.normal(size=(runs, n, 1)) * 5.0
    ours = kalman_filter(y, model["A"], model["C"], model["Q"], model["R"], model["z0"],
                         model["P0"], B=model["B"], u=u)
    assert ours.estimates.shape == (runs, n, 3)
    for r in range(runs):
        expected = filterpy_run(model, y[r], u[r])
        np.testing.assert_allclose(ours.estimates[r], expected["estimates"], rtol=1e-9,
                                   atol=1e-9)
        np.testing.assert_allclose(ours.gains[r], expected["gains"], rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(ours.covariances[r], expected["covariances"], rtol=1e-9,
                                   atol=1e-9)


def test_sweep_over_R_with_runs_equals_filterpy() -> None:
    """Gains that differ along a batch axis (the swept path) with inputs per run."""
    model = random_model(6, 3, 1, 1)
    rng = np.random.default_rng(306)
    runs, n = 3, 25
    sigmas = np.array([0.5, 2.0])
    R = (sigmas**2)[:, None, None] * np.ones((1, 1))          # (S, 1, 1)
    y = rng.normal(size=(runs, 1, n, 1))                       # (runs, 1, n, m)
    u = rng.normal(size=(runs, 1, n, 1))
    ours = kalman_filter(y, model["A"], model["C"], model["Q"], R, model["z0"], model["P0"],
                         B=model["B"], u=u)
    assert ours.estimates.shape == (runs, sigmas.size, n, 3)
    for r in range(runs):
        for s in range(sigmas.size):
            expected = filterpy_run(model, y[r, 0], u[r, 0], R=R[s])
            np.testing.assert_allclose(ours.estimates[r, s], expected["estimates"],
                                       rtol=1e-9, atol=1e-9)
            np.testing.assert_allclose(ours.gains[r, s], expected["gains"], rtol=1e-9,
                                       atol=1e-9)


def test_one_input_shared_by_every_run() -> None:
    """An unbatched u broadcasts against batched y."""
    model = random_model(7, 3, 1, 1)
    rng = np.random.default_rng(407)
    y = rng.normal(size=(3, 20, 1))
    u = rng.normal(size=(20, 1))
    ours = kalman_filter(y, model["A"], model["C"], model["Q"], model["R"], model["z0"],
                         model["P0"], B=model["B"], u=u)
    for r in range(3):
        expected = filterpy_run(model, y[r], u)
        np.testing.assert_allclose(ours.estimates[r], expected["estimates"], rtol=1e-9,
                                   atol=1e-9)


def test_zero_input_is_the_filter_without_input() -> None:
    model = random_model(8, 3, 2, 2)
    y = np.random.default_rng(508).normal(size=(2, 30, 2))
    with_zero = kalman_filter(y, model["A"], model["C"], model["Q"], model["R"], model["z0"],
                              model["P0"], B=model["B"], u=np.zeros((2, 30, 2)))
    without = kalman_filter(y, model["A"], model["C"], model["Q"], model["R"], model["z0"],
                            model["P0"])
    np.testing.assert_allclose(with_zero.estimates, without.estimates, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(with_zero.gains, without.gains)


def test_input_shifts_the_estimate_by_its_own_response() -> None:
    """Linearity: an input adds a data-independent response to the estimates."""
    model = random_model(9, 3, 1, 1)
    rng = np.random.default_rng(609)
    y = rng.normal(size=(2, 30, 1))
    u = rng.normal(size=(30, 1))
    args = (model["A"], model["C"], model["Q"], model["R"], model["z0"], model["P0"])
    driven = kalman_filter(y, *args, B=model["B"], u=u).estimates
    free = kalman_filter(y, *args).estimates
    response = driven - free
    np.testing.assert_allclose(response[0], response[1], rtol=0, atol=1e-12)
    assert np.max(np.abs(response)) > 1e-3
