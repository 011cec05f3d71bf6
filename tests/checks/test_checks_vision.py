"""Checks of notebook 01: the worked answers pass, realistic wrong answers fail saying why.

The wrong answers are written here as a student would write them (the task's own code with
one slip), independently of the mistakes :mod:`lqe_helpers.checks` computes to recognise
them. The worked filter is the test oracle ``reference_loops`` (outside the package).
"""

from __future__ import annotations

import sys
import time

import numpy as np
import pytest
import reference_loops as reference
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, experiments, metrics, model, scenario, simulation
from lqe_helpers.checks import CheckFailed
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.student_code import calling


@pytest.fixture
def quick(monkeypatch) -> float:
    """A short time limit for a student's function (s), so an endless loop ends soon."""
    monkeypatch.setattr(calling, "TIME_LIMIT", 0.3)
    return 0.3


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
    line = assert_passes(capsys, checks.check_filter, student_filter)
    assert line == ("✓ student_filter matches eq. (5) on 6 random models (1–4 states, 1–3 "
                    "sensors, 15 steps) and on the butterfly's whole trial (1000 steps) to "
                    "1e-9, each call given at most 5 s")


@pytest.mark.parametrize("late", [15, 50, 100])
def test_check_filter_catches_a_filter_that_goes_wrong_after_the_random_models_steps(
        late: int) -> None:
    """issue 23: the check ran 15 steps only, so a filter wrong from step 15 on (here: the
    gain frozen, "it has settled") passed 01 and notebooks 02–05 blamed it later. (Frozen
    after about 200 steps, the gain has settled to 1e-9 and the filter is right.)"""
    def my_filter(y, A, C, Q, R, z0, P0):
        z, P, rows = np.asarray(z0, dtype=float), P0, []
        for j, y_j in enumerate(y):
            if j < late:
                K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
            z = A @ z + K @ (y_j - C @ A @ z)
            P = A @ (P - K @ C @ P) @ A.T + Q
            rows.append(z.copy())
        return np.array(rows)

    message = assert_fails(f"my_filter does not match eq. (5) on the butterfly's whole trial "
                           f"(the vision-only model of the tasks, the scenario's 1000 "
                           f"readings). The first {late} estimates are right, then row {late} "
                           f"differs", checks.check_filter, my_filter)
    assert "something changes after" in message and "third line" not in message


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

    message = assert_fails("broken raised KeyError: 'P' (in broken, line ",
                           checks.check_filter, broken)
    assert "`raise KeyError(\"P\")`), on a model with k = 3 states and m = 1 sensor" in message
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


def test_check_filter_stops_an_endless_loop_at_once(quick) -> None:

    def my_filter(y, A, C, Q, R, z0, P0):
        rows, j = [], 0
        while j < len(y):          # j is never increased
            rows.append(z0)
        return np.array(rows)

    start = time.monotonic()
    message = assert_fails(f"my_filter did not return within {quick:g} s (in my_filter, line",
                           checks.check_filter, my_filter)
    assert "rows.append(z0)" in message or "while j < len(y)" in message
    assert time.monotonic() - start < 6 * quick      # the first model only, not all six


def test_check_filter_reports_an_error_whose_message_cannot_be_shown() -> None:
    class Odd(Exception):
        def __str__(self):
            raise RuntimeError("no text")

    def my_filter(y, A, C, Q, R, z0, P0):
        raise Odd()

    assert_fails("my_filter raised Odd: (its message could not be shown",
                 checks.check_filter, my_filter)


@pytest.mark.parametrize(("stop", "phrase"), [
    (SystemExit, "my_filter called exit() (SystemExit)"),
    (KeyboardInterrupt, "my_filter was interrupted (KeyboardInterrupt)"),
])
def test_check_filter_reports_exit_and_interrupt_as_one_line(stop, phrase) -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        raise stop

    assert_fails(phrase, checks.check_filter, my_filter)


def test_check_filter_refuses_complex_estimates_even_with_zero_imaginary_part() -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        return student_filter(y, A, C, Q, R, z0, P0) + 0j

    assert_fails("my_filter returned complex numbers (dtype complex128)", checks.check_filter,
                 my_filter)


def test_check_filter_refuses_a_filter_that_patches_the_engine() -> None:
    """A function that swaps the engine for its own answer gets no ✓, now or later."""
    import lqe_helpers.filter as engine

    checks_module = sys.modules["lqe_helpers.checks.filter_models"]
    original = engine.kalman_filter

    def my_filter(y, A, C, Q, R, z0, P0):
        wrong = student_filter(y, A, C, Q, 2.0 * R, z0, P0)

        def fake(*args, **kwargs):
            return type("Fake", (), {"estimates": wrong, "gains": None})()

        engine.kalman_filter = fake
        checks_module.kalman_filter = fake
        return wrong

    for _ in range(2):
        assert_fails("my_filter replaced lqe_helpers.checks.filter_models.kalman_filter, "
                     "lqe_helpers.filter.kalman_filter (now restored)", checks.check_filter,
                     my_filter)
        assert engine.kalman_filter is original
        assert checks_module.kalman_filter is original


# ------------------------------------------------------------------------------------------
# check_vision_trial (Task 2)
# ------------------------------------------------------------------------------------------

TRUTH = DEFAULT.truth[:, 0]
NOISE = DEFAULT.unit_noise(sensors=("vision",))
BURN = DEFAULT.burn_in_steps
C_VISION = np.array([[1.0, 0.0, 0.0]])
# The set-up cell's values: a student's vision_trial reads them, it calls no pack function.
A_SET, Q_SET, P0_SET = DEFAULT.A, DEFAULT.Q, DEFAULT.P0


#: Task 1's function as the notebook names it: vision_trial calls it by that name.
my_filter = student_filter


def task2(slip: str = ""):
    """Task 2's vision_trial as a student writes it (the notebook's worked code), one ``slip``.

    Its filter is a student's loop (``my_filter``, that is ``student_filter``), as the
    notebook's my_filter is.
    """
    def vision_trial(sigma_v):
        scale = {"sigma squared in y": sigma_v**2, "no sigma in y": 1.0,
                 "always 1.5": 1.5}.get(slip, sigma_v)
        if slip == "truth not a column":
            y = TRUTH + scale * NOISE                               # (n, n)
        elif slip == "flat":
            y = TRUTH + scale * NOISE[:, 0]                         # (n,)
        else:
            y = TRUTH[:, None] + scale * NOISE
        if slip == "own rng":          # random numbers of the student's own
            y = TRUTH[:, None] + sigma_v * np.random.default_rng(7).standard_normal(NOISE.shape)
        if slip == "own normal":
            y = TRUTH[:, None] + np.random.default_rng(0).normal(0.0, sigma_v, NOISE.shape)
        if slip == "metres":
            y = y / 100
        R = np.array([[{"R = sigma": sigma_v, "R = sigma^4": sigma_v**4,
                        "always 1.5": 1.5**2}.get(slip, sigma_v**2)]])
        estimates = my_filter(y, A_SET, C_VISION, Q_SET, R, np.zeros(3), P0_SET)
        if slip == "positions only":
            return y, estimates[:, 0]
        if slip == "estimates only":
            return estimates
        if slip == "swapped":
            return estimates, y
        if slip == "no return":
            return None
        if slip == "engine":
            return y, experiments.track(DEFAULT, sigmas=[sigma_v]).result.estimates
        return y, estimates
    return vision_trial


def test_check_vision_trial_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_vision_trial, task2())
    assert "vision_trial at σ_v = 1.5 and 4.5 cm" in line and "to 1e-9" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("truth not a column", "truth + σ_v · noise broadcasts to (n, n); the readings are "
                           "truth[:, None] + σ_v · noise, shape (n, 1)"),
    ("flat", "the first array vision_trial(1.5) returns (the readings y) is flat, shape "
             "(1000,)"),
    ("sigma squared in y", "the first array vision_trial(1.5) returns (the readings y) is not "
                           "right: the readings were made with σ_v² instead of σ_v"),
    ("no sigma in y", "the readings were made without σ_v (truth + noise)"),
    ("R = sigma", "the second array vision_trial(1.5) returns (the estimates) is not right: "
                  "R holds σ_v (cm) where its variance σ_v² (cm²) belongs"),
    ("R = sigma^4", "R holds σ_v⁴"),
    ("always 1.5", "vision_trial(4.5) returns (the readings y) is not right: they are the "
                   "readings of σ_v = 1.5 cm"),
    ("positions only", "holds one number per reading (the positions only?)"),
    ("swapped", "vision_trial(1.5) returns the estimates first and the readings second"),
    ("estimates only", "vision_trial(1.5) must return two things, the readings y and the "
                       "estimates"),
    ("no return", "got None (nothing): does it end with `return y, estimates`?"),
    ("engine", "vision_trial runs the pack's own lqe_helpers.experiments.track"),
    ("metres", "vision_trial(1.5) returns (the readings y) is not right: they are in metres"),
    ("own rng", "the first array vision_trial(1.5) returns (the readings y) has noise of the "
                "right size, σ_v, but not the given draw: it looks like random numbers of "
                "your own"),
    ("own normal", "(the readings y) has noise of the right size, σ_v, but not the given draw"),
])
def test_check_vision_trial_names_the_cause_of_wrong_science(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_vision_trial, task2(slip))


def test_check_vision_trial_catches_r_as_sigma_that_only_arithmetic_checks_would_pass() -> None:
    """The bug of issue 15: R = [[σ_v]] gives estimates consistent with themselves only."""
    y, wrong = task2("R = sigma")(4.5)
    right = reference.lqe_filter(y, DEFAULT.A, C_VISION, DEFAULT.Q, np.array([[4.5**2]]),
                                 np.zeros(3), DEFAULT.P0)
    assert abs(metrics.mse(wrong[:, 0], TRUTH, BURN) / metrics.mse(right[:, 0], TRUTH, BURN)
               - 1) > 0.1                                      # about 18 % off
    assert_fails("R holds σ_v", checks.check_vision_trial, task2("R = sigma"))


def test_check_vision_trial_without_a_function_or_before_it_is_written() -> None:
    assert_fails("check_vision_trial needs your function vision_trial itself",
                 checks.check_vision_trial, task2()(1.5))

    def vision_trial(sigma_v):
        raise NotImplementedError("Replace this line with your code")

    assert_fails("vision_trial is not written yet", checks.check_vision_trial, vision_trial)


def test_check_vision_needs_no_student_function_and_leaves_the_engine_alone() -> None:
    """Number checks call no student code; the engine's draw is the scenario's own."""
    noise = DEFAULT.unit_noise(sensors=("vision",))
    y = simulation.measure(TRUTH, noise, [4.5])
    assert np.array_equal(y, TRUTH[:, None] + 4.5 * NOISE)
    assert model.observation_matrix(("vision",)).tolist() == C_VISION.tolist()


def test_vision_trial_with_a_wrong_my_filter_is_not_told_my_filter_passed() -> None:
    """helper review: the hint said "my_filter passed its check" to a student whose
    my_filter (Q left out) had not; it now says what to do in both cases."""
    def forgetful_filter(y, A, C, Q, R, z0, P0):
        return student_filter(y, A, C, np.zeros_like(Q), R, z0, P0)

    namespace = {"my_filter": forgetful_filter, "np": np, "TRUTH": TRUTH, "NOISE": NOISE,
                 "A": A_SET, "C": C_VISION, "Q": Q_SET, "P0": P0_SET}
    exec("def vision_trial(sigma_v):\n"  # a notebook's namespace, as a kernel has
         "    y = TRUTH[:, None] + sigma_v * NOISE\n"
         "    return y, my_filter(y, A, C, Q, np.array([[sigma_v**2]]), np.zeros(3), P0)\n",
         namespace)
    with pytest.raises(CheckFailed) as failure:
        checks.check_vision_trial(namespace["vision_trial"])
    assert "if my_filter passed its check (Task 1)" in str(failure.value)
    assert "if not, make it pass first" in str(failure.value)
