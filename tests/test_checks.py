"""The feedback checks: worked answers pass, typical wrong answers fail with their own message.

The wrong answers below are written here as a student would write them, independently of
the mistakes that :mod:`lqe_helpers.checks` computes privately to recognise them.
"""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, metrics, model, reference, scenario, simulation
from lqe_helpers.checks import CheckFailed

# ------------------------------------------------------------------------------------------
# helpers
# ------------------------------------------------------------------------------------------




def test_check_failed_is_an_assertion_error() -> None:
    assert issubclass(CheckFailed, AssertionError)


# ------------------------------------------------------------------------------------------
# check_filter
# ------------------------------------------------------------------------------------------


def student_filter(y, A, C, Q, R, z0, P0, *, mistake: str = ""):
    """A student's eq. (5), optionally with one mistake."""
    z = np.array(z0, dtype=float)
    P = np.array(P0, dtype=float)
    if mistake == "C transposed":
        C = C.T
    if mistake == "sigma for R":
        R = np.sqrt(R)                    # R "back to σ" (R is diagonal only by luck)
    rows = []
    for j in range(len(y)):
        if mistake == "P before K":
            P = A @ (P - P @ C.T @ np.linalg.inv(C @ P @ C.T + R) @ C @ P) @ A.T + Q
        if mistake == "textbook":
            P = A @ P @ A.T + Q
        if mistake == "R alone":
            K = P @ C.T @ np.linalg.inv(R)
        else:
            K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
        if mistake == "innovation against z":
            z = A @ z + K @ (y[j] - C @ z)
        elif mistake == "no prediction":
            z = z + K @ (y[j] - C @ z)
        else:
            z = A @ z + K @ (y[j] - C @ A @ z)
        if mistake == "no Q":
            P = A @ (P - K @ C @ P) @ A.T
        elif mistake == "no A in P":
            P = P - K @ C @ P + Q
        elif mistake == "textbook":
            P = (np.eye(len(z)) - K @ C) @ P
        elif mistake != "P before K":
            P = A @ (P - K @ C @ P) @ A.T + Q
        rows.append(A @ z if mistake == "prediction" else z.copy())
    if mistake == "z0 first":
        return np.array([np.asarray(z0, dtype=float), *rows])
    if mistake == "z0 first, n rows":
        return np.array([np.asarray(z0, dtype=float), *rows[:-1]])
    if mistake == "returns P too":
        return np.array(rows), P
    if mistake == "list":
        return rows
    if mistake == "columns":
        return np.array(rows).T
    return np.array(rows)


def test_check_filter_passes_the_worked_solution(capsys) -> None:
    line = assert_passes(capsys, checks.check_filter, reference.lqe_filter)
    assert line == ("✓ lqe_filter matches eq. (5) on 6 random models (1–4 states, 1–3 "
                    "sensors, 15 steps) to 1e-9")


def test_check_filter_passes_a_student_filter_with_inv(capsys) -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        return student_filter(y, A, C, Q, R, z0, P0)

    assert "my_filter matches eq. (5)" in assert_passes(capsys, checks.check_filter, my_filter)


FILTER_MISTAKES = {
    "C transposed": "C is used transposed",
    "sigma for R": "R is used as if it held standard deviations",
    "R alone": "K is computed with R alone",
    "innovation against z": "compared with C ẑ, the previous estimate",
    "no prediction": "the prediction step is missing",
    "no Q": "Q is left out of the covariance update",
    "P before K": "P is updated before K is computed",
    "no A in P": "the covariance update leaves out A … Aᵀ",
    "textbook": "the textbook predict-then-update order",
    "prediction": "each row is the prediction A ẑ for the next step",
    "z0 first, n rows": "the rows are one step late",
    "z0 first": "returned 16 rows for 15 measurements (its first row is z0)",
    "returns P too": "returned a tuple of 2 items",
    "list": "returned a Python list",
    "columns": "the result is transposed",
}


@pytest.mark.parametrize("mistake", FILTER_MISTAKES)
def test_check_filter_names_each_typical_mistake(mistake: str) -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        return student_filter(y, A, C, Q, R, z0, P0, mistake=mistake)

    message = assert_fails(FILTER_MISTAKES[mistake], checks.check_filter, my_filter)
    # One message per mistake: no other mistake's phrase appears in it.
    others = [p for m, p in FILTER_MISTAKES.items() if m != mistake and p in message]
    assert not others, message


def test_check_filter_messages_give_no_code() -> None:
    """Messages describe the mistake in words and symbols, never as Python."""
    for mistake in FILTER_MISTAKES:
        def my_filter(y, A, C, Q, R, z0, P0, mistake=mistake):
            return student_filter(y, A, C, Q, R, z0, P0, mistake=mistake)

        with pytest.raises(CheckFailed) as info:
            checks.check_filter(my_filter)
        for code in ("np.", "linalg", "inv(", "@", ".T", "matrix_power", "append"):
            assert code not in str(info.value), (mistake, str(info.value))


def test_check_filter_rejects_a_hard_coded_answer() -> None:
    s = scenario.DEFAULT
    y = simulation.measure(s.truth[:, 0], s.unit_noise(sensors=("vision",)), [s.sigma_v])
    scenario_estimates = reference.lqe_filter(y, s.A, model.observation_matrix(), s.Q,
                                              model.measurement_noise_covariance([s.sigma_v]),
                                              np.zeros(3), s.P0)

    def my_filter(y, A, C, Q, R, z0, P0):
        return scenario_estimates

    assert_fails("returned an array of shape (1000, 3)", checks.check_filter, my_filter)

    # Hard-coding the right shape does not help either: the numbers are checked.
    def right_shape(y, A, C, Q, R, z0, P0):
        return np.resize(scenario_estimates, (len(y), A.shape[0]))

    assert_fails("does not match eq. (5)", checks.check_filter, right_shape)


def test_check_filter_says_not_written_yet() -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        raise NotImplementedError

    assert_fails("my_filter is not written yet", checks.check_filter, my_filter)


def test_check_filter_reports_other_errors_with_the_model() -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        return y[:, 0] if A.shape[0] == 1 else reference.lqe_filter(y, A, C, Q, R, z0, P0)

    def broken(y, A, C, Q, R, z0, P0):
        raise KeyError("P")

    message = assert_fails("broken raised KeyError: 'P' — on a model with k = 3 states and "
                           "m = 1 sensor", checks.check_filter, broken)
    assert "(y (15, 1), A (3, 3), C (1, 3)" in message
    assert_fails("returned an array of shape (15,)", checks.check_filter, my_filter)


def test_check_filter_rejects_a_filter_that_changes_its_inputs() -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        z = z0
        rows = []
        for y_j in y:
            K = P0 @ C.T @ np.linalg.inv(C @ P0 @ C.T + R)
            z += K @ (y_j - C @ A @ z) + (A @ z - z)     # updates z0 in place
            P0[...] = A @ (P0 - K @ C @ P0) @ A.T + Q
            rows.append(z.copy())
        return np.array(rows)

    assert_fails("changed its input", checks.check_filter, my_filter)


def test_check_filter_recognises_one_array_stored_n_times() -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        z, P, rows = np.array(z0, dtype=float), np.array(P0, dtype=float), []
        for y_j in y:
            K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
            z[:] = A @ z + K @ (y_j - C @ A @ z)         # changes the stored array too
            P = A @ (P - K @ C @ P) @ A.T + Q
            rows.append(z)
        return np.array(rows)

    assert_fails("the same array was stored at every step", checks.check_filter, my_filter)


def test_check_filter_accepts_other_correct_forms(capsys) -> None:
    """Joseph form of the update and solve instead of inv: equal up to rounding."""
    def my_filter(y, A, C, Q, R, z0, P0):
        z, P, rows = z0, P0, []
        identity = np.eye(len(z0))
        for y_j in y:
            K = np.linalg.solve(C @ P @ C.T + R, C @ P).T
            z = A @ z + K @ (y_j - C @ A @ z)
            P_plus = (identity - K @ C) @ P @ (identity - K @ C).T + K @ R @ K.T
            P = A @ P_plus @ A.T + Q
            rows.append(z)
        return np.array(rows)

    assert_passes(capsys, checks.check_filter, my_filter)


def test_check_filter_needs_a_function() -> None:
    assert_fails("needs your function my_filter itself", checks.check_filter, np.zeros(3))


def test_check_filter_gives_a_generic_hint_for_an_unknown_mistake() -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        return student_filter(y, A, C, 2.0 * Q, R, z0, P0)     # Q doubled: no usual mistake

    assert_fails("The first estimate is right, then row 1 differs",
                 checks.check_filter, my_filter)


# ------------------------------------------------------------------------------------------
# check_fusion
# ------------------------------------------------------------------------------------------

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


# ------------------------------------------------------------------------------------------
# check_compensation
# ------------------------------------------------------------------------------------------


def student_compensate(estimates, A, delay_steps, *, mistake: str = ""):
    """A student's eq. (7), optionally with one mistake."""
    n, k = estimates.shape
    d = delay_steps
    ahead = np.linalg.matrix_power(A, d)
    if mistake == "A**d":
        ahead = A ** d
    elif mistake == "A*d":
        ahead = A * d
    elif mistake == "power d-1":
        ahead = np.linalg.matrix_power(A, d - 1)
    elif mistake == "no A":
        ahead = np.eye(k)
    fill = 0.0 if mistake == "zeros before" else np.nan
    out = np.full((n, k), fill)
    if mistake == "no shift":
        return estimates @ ahead.T
    if mistake == "shift d+1":
        for j in range(d + 1, n):
            out[j] = ahead @ estimates[j - d - 1]
        return out
    if mistake == "only existing rows":
        return estimates[: n - d] @ ahead.T
    if mistake == "slice from the end":
        out[d:] = estimates[:-d] @ ahead.T       # empty when d = 0
        return out
    if mistake == "row times matrix":
        out[d:] = estimates[: n - d] @ ahead
        return out
    if mistake == "estimates before":
        out[:d] = estimates[:d]
    for j in range(d, n):
        out[j] = ahead @ estimates[j - d]
    return out


def test_check_compensation_passes_the_worked_solution(capsys) -> None:
    line = assert_passes(capsys, checks.check_compensation, reference.compensate)
    assert "compensate matches eq. (7)" in line


COMPENSATION_MISTAKES = {
    "A**d": "A^δ is computed entry by entry",
    "A*d": "A is multiplied by the number δ (A·δ)",
    "power d-1": "one power of A too few",
    "no A": "A is not used",
    "no shift": "there is no shift",
    "shift d+1": "your row j uses the estimate ẑ_(j−δ−1)",
    "zeros before": "rows before j = δ hold zeros",
    "estimates before": "rows before j = δ hold the estimates ẑ_j themselves",
    "only existing rows": "only the rows that exist",
    "slice from the end": "slices that count from the end",
    "row times matrix": "A^δ is applied from the wrong side",
}


@pytest.mark.parametrize("mistake", COMPENSATION_MISTAKES)
def test_check_compensation_names_each_typical_mistake(mistake: str) -> None:
    def compensate(estimates, A, delay_steps):
        return student_compensate(estimates, A, delay_steps, mistake=mistake)

    message = assert_fails(COMPENSATION_MISTAKES[mistake], checks.check_compensation,
                           compensate)
    others = [p for m, p in COMPENSATION_MISTAKES.items() if m != mistake and p in message]
    assert not others, message


def test_check_compensation_rejects_a_hard_coded_answer() -> None:
    s = scenario.DEFAULT
    fixed = reference.compensate(s.truth, s.A, 10)

    def compensate(estimates, A, delay_steps):
        return fixed

    assert_fails("returned an array of shape (1000, 3)", checks.check_compensation, compensate)


def test_check_compensation_rejects_changing_the_estimates_in_place() -> None:
    def compensate(estimates, A, delay_steps):
        estimates[:] = reference.compensate(estimates, A, delay_steps)
        return estimates

    assert_fails("changed its input estimates or A in place", checks.check_compensation,
                 compensate)


def test_check_compensation_says_not_written_yet() -> None:
    def compensate(estimates, A, delay_steps):
        raise NotImplementedError

    assert_fails("compensate is not written yet", checks.check_compensation, compensate)


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


# ------------------------------------------------------------------------------------------
# check_mse
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def tracking() -> dict[str, np.ndarray]:
    """Positions of the pack's scenario: truth, one run, and 20 Monte Carlo runs."""
    s = scenario.DEFAULT
    truth = s.truth[:, 0]
    noise = s.unit_noise(runs=20, sensors=("vision",))
    y = simulation.measure(truth, noise, [s.sigma_v])
    from lqe_helpers.filter import kalman_filter

    estimates = kalman_filter(y, s.A, model.observation_matrix(), s.Q,
                              model.measurement_noise_covariance([s.sigma_v]),
                              np.zeros(3), s.P0).estimates[..., 0]
    return {"truth": truth, "runs": estimates, "one": estimates[0], "burn": s.burn_in_steps}


def test_check_mse_passes_the_worked_solution(capsys, tracking) -> None:
    truth, one, runs, burn = (tracking[k] for k in ("truth", "one", "runs", "burn"))
    value = float(metrics.mse(one, truth, burn))
    line = assert_passes(capsys, checks.check_mse, value, one, truth, burn)
    assert "skipping the first 100 samples" in line and "rtol 1e-6" in line
    line = assert_passes(capsys, checks.check_mse, metrics.mse(runs, truth, burn), runs,
                         truth, burn)
    assert line.startswith("✓ 20 MSEs (one per run)")
    line = assert_passes(capsys, checks.check_mse, float(np.mean(metrics.mse(runs, truth))),
                         runs, truth)
    assert line.startswith("✓ mean MSE over 20 runs")
    # Within the stated tolerance, not beyond it.
    assert_passes(capsys, checks.check_mse, value * (1 + 5e-7), one, truth, burn)
    assert_fails("does not match", checks.check_mse, value * (1 + 1e-4), one, truth, burn)


def test_check_mse_names_each_typical_mistake(tracking) -> None:
    truth, one, burn = tracking["truth"], tracking["one"], tracking["burn"]
    error = one - truth
    cases = {
        "root mean squared error": np.sqrt(np.mean(error[burn:] ** 2)),
        "were not skipped": np.mean(error ** 2),
        "sum of the squared errors": np.sum(error[burn:] ** 2),
        "the errors are not squared": np.mean(error[burn:]),
        "mean absolute error": np.mean(np.abs(error[burn:])),
        "MSE after skipping 1 sample, but burn_in_steps = 100": np.mean(error[1:] ** 2),
    }
    for phrase, value in cases.items():
        assert_fails(phrase, checks.check_mse, value, one, truth, burn)


def test_check_mse_of_a_compensated_estimate_with_nan_rows(capsys, tracking) -> None:
    """Question (e): z* has NaN before δ; the burn-in skips them."""
    truth, one, burn = tracking["truth"], tracking["one"], tracking["burn"]
    compensated = np.concatenate([np.full(10, np.nan), one[:-10]])
    value = float(metrics.mse(compensated, truth, burn))
    assert_passes(capsys, checks.check_mse, value, compensated, truth, burn)
    assert_fails("root mean squared error", checks.check_mse, np.sqrt(value), compensated,
                 truth, burn)
    assert_fails("got NaN or inf at sample 0", checks.check_mse, value, compensated, truth)


def test_check_mse_wants_positions(tracking) -> None:
    states = np.stack([tracking["one"]] * 3, axis=-1)
    assert_fails("It expects positions (cm)", checks.check_mse, 1.0, states,
                 np.stack([tracking["truth"]] * 3, axis=-1))


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


# ------------------------------------------------------------------------------------------
# check_paired_difference
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def paired() -> tuple[np.ndarray, np.ndarray]:
    """Per-run MSEs of two filters on the same noise: strongly correlated."""
    rng = np.random.default_rng(12)
    shared = rng.gamma(20.0, 0.05, size=300)
    return shared + 0.05 + 0.02 * rng.normal(size=300), shared + 0.02 * rng.normal(size=300)


def test_check_paired_difference_passes_the_worked_solution(capsys, paired) -> None:
    first, second = paired
    line = assert_passes(capsys, checks.check_paired_difference,
                         metrics.mean_ci95(first - second), first, second)
    assert "over 300 runs" in line


def test_check_paired_difference_names_each_typical_mistake(paired) -> None:
    first, second = paired
    n = first.size
    right = metrics.mean_ci95(first - second)
    t = metrics.t_critical_95(n - 1)
    s = float(np.std(first - second, ddof=1))
    half_unpaired = t * np.sqrt((np.var(first, ddof=1) + np.var(second, ddof=1)) / n)

    def around(half: float) -> metrics.Interval:
        return metrics.Interval(right.mean, right.mean - half, right.mean + half, n)

    a, b = metrics.mean_ci95(first), metrics.mean_ci95(second)
    cases = [
        ("the sign is reversed", metrics.mean_ci95(second - first)),
        ("treats the two MSEs as independent samples (unpaired)", around(half_unpaired)),
        ("combines the two MSEs' separate intervals",
         metrics.Interval(a.mean - b.mean, a.low - b.high, a.high - b.low, n)),
        ("uses the standard deviation of the differences", around(t * s)),
        ("the normal 1.96", around(1.959963984540054 * s / np.sqrt(n))),
        ("interval is a pair of numbers", (right.low, right.high)),
        ("interval is a number", right.mean),
        ("interval is over 299 runs", metrics.mean_ci95((first - second)[1:])),
    ]
    for phrase, interval in cases:
        assert_fails(phrase, checks.check_paired_difference, interval, first, second)
