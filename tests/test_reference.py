"""The test oracle ``reference_loops`` (readable eq. (5) and (7)) against independent results.

Tolerance of "the fast engine equals the reference": every estimate within
1e-10 × (the largest |estimate| of the run, at least 1), i.e. relative to the run's scale,
``assert_allclose(engine, reference, rtol=1e-10, atol=1e-10 · scale)``.
"""

from __future__ import annotations

import ast
import inspect
import textwrap

import numpy as np
import pytest
import reference_loops as reference

from lqe_helpers import model, prediction, scenario, simulation
from lqe_helpers.filter import kalman_filter

ENGINE_RTOL = 1e-10


def random_model(rng: np.random.Generator, k: int, m: int) -> dict[str, np.ndarray]:
    """A random model with well-conditioned covariances (drawn here, not by the checks)."""
    A = np.eye(k) + 0.3 * rng.normal(size=(k, k))
    X, Y, Z = rng.normal(size=(k, k)), rng.normal(size=(m, m)), rng.normal(size=(k, k))
    return {"A": A, "C": rng.normal(size=(m, k)), "Q": 0.2 * X @ X.T + 0.01 * np.eye(k),
            "R": Y @ Y.T + 0.5 * np.eye(m), "z0": rng.normal(size=k),
            "P0": Z @ Z.T + np.eye(k)}


def assert_engine_equals_reference(y: np.ndarray, **params: np.ndarray) -> None:
    ours = reference.lqe_filter(y, **params)
    engine = kalman_filter(y, **params).estimates
    scale = max(1.0, float(np.max(np.abs(ours))))
    assert ours.shape == engine.shape == (y.shape[0], params["A"].shape[0])
    np.testing.assert_allclose(engine, ours, rtol=ENGINE_RTOL, atol=ENGINE_RTOL * scale)


@pytest.mark.parametrize(("k", "m"), [(1, 1), (2, 1), (2, 2), (3, 1), (3, 2), (3, 3),
                                      (4, 1), (4, 3)])
def test_engine_equals_reference_on_random_models(k: int, m: int) -> None:
    rng = np.random.default_rng(1000 + 10 * k + m)
    params = random_model(rng, k, m)
    y = 3.0 * rng.normal(size=(80, m))
    assert_engine_equals_reference(y, **params)


@pytest.mark.parametrize("sensors", [("vision",), ("vision", "proprioception")])
@pytest.mark.parametrize("p0_variance", [1.0, 1e5])
def test_engine_equals_reference_on_the_pack_scenario(sensors: tuple[str, ...],
                                                      p0_variance: float) -> None:
    s = scenario.DEFAULT
    sigmas = np.array([s.sigma_v, s.sigma_p])[: len(sensors)]
    y = simulation.measure(s.truth[:, 0], s.unit_noise(sensors=sensors), sigmas)
    assert y.shape == (s.n_steps, len(sensors))
    assert_engine_equals_reference(
        y, A=s.A, C=model.observation_matrix(sensors), Q=s.Q,
        R=model.measurement_noise_covariance(sigmas), z0=np.asarray(s.z0),
        P0=model.diagonal_covariance(p0_variance))


def test_reference_equals_filterpy() -> None:
    """An independent oracle: filterpy, started from the prior mean A·z0 with covariance P0."""
    rng = np.random.default_rng(31)
    params = random_model(rng, 3, 2)
    y = 2.0 * rng.normal(size=(40, 2))
    expected = reference.filterpy_run(y, **params)["estimates"]
    np.testing.assert_allclose(reference.lqe_filter(y, **params), expected,
                               rtol=1e-10, atol=1e-10)


def test_reference_hand_derived_scalar_case() -> None:
    """k = m = 1 with A = 2, C = 1: two steps worked out by hand."""
    a, q, r, p0, z0 = 2.0, 0.5, 2.0, 1.0, 1.0
    y = np.array([[3.0], [5.0]])
    k1 = p0 / (p0 + r)                           # 1/3
    z1 = a * z0 + k1 * (3.0 - a * z0)            # 2 + 1/3
    p1 = a * (p0 - k1 * p0) * a + q              # 4 · 2/3 + 1/2 = 19/6
    k2 = p1 / (p1 + r)                           # 19/31
    z2 = a * z1 + k2 * (5.0 - a * z1)
    out = reference.lqe_filter(y, [[a]], [[1.0]], [[q]], [[r]], [z0], [[p0]])
    np.testing.assert_allclose(out, [[z1], [z2]], rtol=1e-14)


def test_reference_filter_is_a_short_readable_loop() -> None:
    """The oracle stays a plain loop: about 15 lines of code, one per line of eq. (5)."""
    source = textwrap.dedent(inspect.getsource(reference.lqe_filter))
    body = ast.parse(source).body[0].body
    code = [node for node in body
            if not (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant))]
    lines = sum(node.end_lineno - node.lineno + 1 for node in code)
    assert lines <= 15
    loop = next(node for node in code if isinstance(node, ast.For))
    assert len(loop.body) == 5                  # S, K, ẑ, P, store


def test_reference_filter_refuses_bad_shapes() -> None:
    rng = np.random.default_rng(3)
    params = random_model(rng, 3, 1)
    with pytest.raises(ValueError, match=r"y must have shape \(n, m\).*got shape \(10,\)"):
        reference.lqe_filter(np.zeros(10), **params)
    with pytest.raises(ValueError, match=r"C must have shape \(1, 3\).*got shape \(3, 1\)"):
        reference.lqe_filter(np.zeros((10, 1)), **{**params, "C": params["C"].T})
    with pytest.raises(ValueError, match=r"z0 must have shape \(3,\)"):
        reference.lqe_filter(np.zeros((10, 1)), **{**params, "z0": np.zeros(2)})


def test_compensate_equals_predict_ahead() -> None:
    """Both give out[j] = A^δ ẑ_(j−δ) with NaN rows j < δ: compared row for row."""
    rng = np.random.default_rng(4)
    s = scenario.DEFAULT
    estimates = rng.normal(size=(50, 3)) * [10.0, 30.0, 100.0]
    for delay in (0, 1, 10, 49):
        ours = reference.compensate(estimates, s.A, delay)
        theirs = prediction.predict_ahead(estimates, s.A, delay)
        assert ours.shape == estimates.shape
        assert np.all(np.isnan(ours[:delay])) and np.all(np.isfinite(ours[delay:]))
        np.testing.assert_allclose(ours, theirs, rtol=1e-13, atol=1e-12, equal_nan=True)


def test_compensate_hand_derived() -> None:
    """A = [[1, 1], [0, 1]] (position += velocity): A² = [[1, 2], [0, 1]]."""
    A = np.array([[1.0, 1.0], [0.0, 1.0]])
    estimates = np.array([[0.0, 1.0], [1.0, 2.0], [3.0, -1.0], [5.0, 0.5]])
    out = reference.compensate(estimates, A, 2)
    expected = np.array([[np.nan, np.nan], [np.nan, np.nan],
                         [0.0 + 2 * 1.0, 1.0],       # A² ẑ_0
                         [1.0 + 2 * 2.0, 2.0]])      # A² ẑ_1
    np.testing.assert_array_equal(out, expected)
    np.testing.assert_array_equal(reference.compensate(estimates, A, 0), estimates)


def test_compensate_refuses_bad_input() -> None:
    with pytest.raises(ValueError, match=r"delay_steps must be a whole number in \[0, 3\]"):
        reference.compensate(np.zeros((4, 2)), np.eye(2), 4)
    with pytest.raises(ValueError, match="delay_steps must be a whole number"):
        reference.compensate(np.zeros((4, 2)), np.eye(2), 1.5)
    with pytest.raises(ValueError, match=r"A must have trailing shape \(2, 2\)"):
        reference.compensate(np.zeros((4, 2)), np.eye(3), 1)
    with pytest.raises(ValueError, match=r"estimates must have shape \(n, k\)"):
        reference.compensate(np.zeros((2, 4, 2)), np.eye(2), 1)


def test_the_package_holds_no_readable_worked_answer() -> None:
    """The loops answer tasks of 01 and 05: nothing in lqe_helpers imports or holds them."""
    from pathlib import Path

    package = Path(__file__).resolve().parents[1] / "lqe_helpers"
    assert not (package / "reference.py").exists()
    for path in package.rglob("*.py"):
        text = path.read_text("utf-8")
        assert "import reference_loops" not in text, path
        assert "lqe_helpers.reference" not in text and "import reference\n" not in text, path


@pytest.mark.slow
def test_the_student_pack_holds_no_worked_answer_of_01_or_05() -> None:
    """Neither the oracle, nor the checks' tests, nor the worked notebooks' saved functions."""
    from pathlib import Path

    from lqe_helpers.authoring import student_pack

    root = Path(__file__).resolve().parents[1]
    assert (root / "notebooks" / "my_functions" / "my_filter.py").is_file()
    files = student_pack.pack_contents(root)
    assert not [name for name in files if "my_functions" in name or "reference_loops" in name
                or name.endswith(("/test_checks_vision.py", "/test_checks_delay.py"))]
    worked_lines = ("z = A @ z + K @ (y_j - C @ A @ z)",
                    "z_star[j] = A_delta @ estimates[j - delay_steps]")
    for name, data in files.items():
        text = data.decode("utf-8", errors="replace")
        assert not [line for line in worked_lines if line in text], name
