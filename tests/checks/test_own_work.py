"""Issue 23 §1 and §3: no pack answer passes for the student's, and a ✓ only on what the
current task cell made.

Each case runs a notebook's own cells up to a task (``cell_runner``: IPython's cell events
fired at a fake shell, no kernel), then a task cell with the loophole, then the notebook's
check cell. Where the loophole gives the right values, the same cells without the record
(as in plain Python, and as every check behaved before) pass: the refusal is what stops it.
"""

from __future__ import annotations

import contextlib
import dataclasses
import inspect
import io
import subprocess
import sys

import nbformat
import numpy as np
import pytest
from cell_runner import NOTEBOOKS, CellRunner, cells_up_to, quiet, saved_functions, task_comment
from check_outcomes import assert_fails
from test_checks_background import eyes_closed

from lqe_helpers import _engine, bias_model, checks, experiments, prediction
from lqe_helpers.checks import CheckFailed, own_work
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.student_code import outside, task_runs


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """A notebook folder holding the worked notebooks' saved functions, as the working folder."""
    saved_functions(tmp_path)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def run_task(notebook: str, check: str, code: str | None, *,
             watch: bool = True, comment: bool = True,
             before_check: str = "", earlier: tuple[str, ...] = (),
             ) -> tuple[BaseException | None, str]:
    """The notebook's cells before ``check``'s task (then the cells ``earlier``, as a
    student's own), the task cell (its comment unless not ``comment``, then ``code``; None:
    the worked code), then the check cell (after ``before_check``, a cell run between).
    Returns the check cell's error and what it printed."""
    before, task, check_cell = cells_up_to(notebook, check)
    runner = CellRunner(watch=watch)
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            for source in [*before, *earlier]:
                error = runner.run(source)
                assert error is None, (source[:200], error)
            error = runner.run(task if code is None
                               else (task_comment(task) if comment else "") + code)
        assert error is None, error
        if before_check:
            runner.run(before_check)
        with contextlib.redirect_stdout(io.StringIO()) as printed:
            error = runner.run(check_cell)
        return error, printed.getvalue()
    finally:
        runner.close()


# ------------------------------------------------------------------------------------------
# §1, top-level and one-trial tasks: the pack's answer computed in the task cell
# ------------------------------------------------------------------------------------------

LOOPHOLES = {
    "00 Task 1, A from the pack": (
        "00_background_model", "check_transition_matrix",
        "def my_transition_matrix(dt):\n"
        "    return np.array([[1.0, dt, dt**2 / 2], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])\n"
        "A = model.transition_matrix(DEFAULT.dt)\n",
        "lqe_helpers.model.transition_matrix"),
    "00 Task 2, the band from propagate_covariance": (
        "00_background_model", "check_eyes_closed",
        "def predict_covariance(P, F, G, sigma):\n"
        "    return F @ P @ F.T + sigma**2 * G @ G.T\n"
        "Q_step = sigma_j**2 * g @ g.T\n"
        "two_sigma = 2 * np.sqrt(propagate_covariance(P_close, A, Q_step, 100)[:, 0, 0])\n",
        "lqe_helpers.prediction.propagate_covariance"),
    "00 Task 3, scenario.matched_jerk_std": (
        "00_background_model", "check_jerk_stds",
        "from lqe_helpers import scenario\n"
        "jerk_stds = {name: scenario.matched_jerk_std(DEFAULT.amplitude, DEFAULT.frequency,\n"
        "                                             DEFAULT.dt, fraction)\n"
        "             for name, fraction in periods.items()}\n",
        "lqe_helpers.scenario.matched_jerk_std"),
    "02 Task 1, estimates from the engine without my_filter": (
        "02_initial_covariance", "check_start_of_trial",
        "import dataclasses\n"
        "P0_small = np.diag([1.0, 1.0, 1.0])\n"
        "P0_large = np.diag([1e5, 1e5, 1e5])\n"
        "large = dataclasses.replace(DEFAULT, p0_variance=1e5)\n"
        "estimates_small = experiments.track(DEFAULT).result.estimates\n"
        "estimates_large = experiments.track(large).result.estimates\n",
        "lqe_helpers._engine.filter_run"),
    "03 Task 1, C and R from the model": (
        "03_fusion", "check_fusion",
        "from lqe_helpers import model\n"
        "C = model.observation_matrix(FUSED)\n"
        "R = model.measurement_noise_covariance([sigma_v, sigma_p])\n",
        "lqe_helpers.model.observation_matrix"),
    "03 Task 2, the positions of experiments.track": (
        "03_fusion", "check_fusion_trial",
        "fused_positions = experiments.track(DEFAULT, FUSED).positions\n"
        "vision_positions = experiments.track(DEFAULT, ('vision',)).positions\n"
        "mse_fused_trial = float(metrics.mse(fused_positions, truth, burn_in))\n"
        "mse_vision_trial = float(metrics.mse(vision_positions, truth, burn_in))\n",
        "lqe_helpers._engine.filter_run"),
    "04 Task 1, R from the model": (
        "04_noisier_proprioception", "check_noisier_sense",
        "from lqe_helpers import model\n"
        "sigma_p = 4.5\n"
        "R = model.measurement_noise_covariance([sigma_v, sigma_p])\n",
        "lqe_helpers.model.measurement_noise_covariance"),
    "05 Task 2, the fields of experiments.delay_and_compensate": (
        "05_sensory_delay", "check_delay_signals",
        "shifted = experiments.delay_and_compensate(experiments.track(DEFAULT), delay)\n"
        "late_readings = shifted.delayed_measurements[:, 0]\n"
        "delayed = shifted.delayed_estimates[:, 0]\n"
        "compensated = shifted.predictions[:, 0]\n",
        "lqe_helpers._engine.filter_run"),
    "06 Task 1, the bias model's matrices": (
        "06_bonus_bias_and_input", "check_bias_model",
        "F = bias_model.transition_matrix(dt)\n"
        "G = bias_model.input_matrix(dt)\n"
        "Q = bias_model.process_noise_covariance(dt, sigma_a)\n",
        "lqe_helpers.bias_model.equations.transition_matrix"),
}


@pytest.mark.slow
@pytest.mark.parametrize("case", list(LOOPHOLES))
def test_a_task_cell_that_computes_with_the_packs_answer_fails_its_check(case, folder) -> None:
    notebook, check, code, named = LOOPHOLES[case]
    error, printed = run_task(notebook, check, code, watch=False)
    assert error is None and printed.startswith("✓ "), (error, printed)  # right values
    error, printed = run_task(notebook, check, code)
    assert isinstance(error, CheckFailed), error
    assert "the task cell above runs the pack's" in str(error), str(error)
    assert named.removeprefix("lqe_helpers.") in str(error), str(error)
    assert printed == ""


@pytest.mark.slow
@pytest.mark.parametrize("case", ["00 Task 3, scenario.matched_jerk_std",
                                  "03 Task 1, C and R from the model",
                                  "03 Task 2, the positions of experiments.track"])
def test_the_packs_answer_in_a_cell_without_the_task_comment_fails_too(case, folder) -> None:
    """The student trial wrote its answers in cells of its own, without `# Task:`: every cell
    is recorded, so the check still finds the cell that made its values."""
    notebook, check, code, named = LOOPHOLES[case]
    error, _printed = run_task(notebook, check, code, comment=False)
    assert isinstance(error, CheckFailed), error
    assert "the task cell above runs the pack's" in str(error), str(error)
    assert named.removeprefix("lqe_helpers.") in str(error), str(error)


@pytest.mark.slow
def test_a_cell_without_the_task_comment_that_raised_is_not_judged_on_stale_values(
        folder) -> None:
    """The trial: a right run, then the same cell (no `# Task:`) raising at its top."""
    notebook, check = "03_fusion", "check_fusion"
    right = ("C = np.array([[1.0, 0, 0], [1.0, 0, 0]])\n"
             "R = np.diag([sigma_v**2, sigma_p**2])\n")
    error, printed = run_task(notebook, check, right, comment=False,
                              before_check="raise ValueError('oops')\n" + right)
    assert isinstance(error, CheckFailed), (error, printed)
    assert "the task cell above stopped with an error" in str(error)


@pytest.mark.slow
def test_a_check_called_in_the_cell_of_its_task_judges_that_cell(folder) -> None:
    notebook, check = "03_fusion", "check_fusion"
    code = ("from lqe_helpers import model\n"
            "C = model.observation_matrix(FUSED)\n"
            "R = model.measurement_noise_covariance([sigma_v, sigma_p])\n")
    before, _task, check_cell = cells_up_to(notebook, check)
    runner = CellRunner()
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            for source in before:
                assert runner.run(source) is None
            error = runner.run(code + check_cell)
    finally:
        runner.close()
    assert isinstance(error, CheckFailed), error
    assert "runs the pack's own model.observation_matrix" in str(error)


@pytest.mark.slow
@pytest.mark.parametrize(("notebook", "check"), [
    ("00_background_model", "check_jerk_stds"), ("02_initial_covariance", "check_start_of_trial"),
    ("03_fusion", "check_fusion_trial"), ("05_sensory_delay", "check_delay_signals"),
    ("06_bonus_bias_and_input", "check_bias_model")])
def test_the_worked_task_cell_passes_with_the_record(notebook, check, folder) -> None:
    error, printed = run_task(notebook, check, None)
    assert error is None and printed.startswith("✓ "), (error, printed)


@pytest.mark.slow
def test_a_one_trial_task_computed_by_hand_without_my_filter_fails(folder) -> None:
    """02 Task 1 with eq. (5) retyped in the cell: right values, but not the saved my_filter."""
    code = ("def loop(P):\n"
            "    z, estimates = z0, []\n"
            "    for y_j in y:\n"
            "        K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)\n"
            "        z = A @ z + K @ (y_j - C @ A @ z)\n"
            "        P = A @ (P - K @ C @ P) @ A.T + Q\n"
            "        estimates.append(z)\n"
            "    return np.array(estimates)\n"
            "P0_small = np.diag([1.0, 1.0, 1.0])\n"
            "P0_large = np.diag([1e5, 1e5, 1e5])\n"
            "estimates_small, estimates_large = loop(P0_small), loop(P0_large)\n")
    error, printed = run_task("02_initial_covariance", "check_start_of_trial", code, watch=False)
    assert error is None and printed.startswith("✓ "), (error, printed)
    error, _ = run_task("02_initial_covariance", "check_start_of_trial", code)
    assert "the task cell above does not run your my_filter" in str(error), error


HAND_LOOP = ("def loop(y, C, R):\n"
             "    z, P, estimates = z0, P0, []\n"
             "    for y_j in y:\n"
             "        K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)\n"
             "        z = A @ z + K @ (y_j - C @ A @ z)\n"
             "        P = A @ (P - K @ C @ P) @ A.T + Q\n"
             "        estimates.append(z)\n"
             "    return np.array(estimates)\n")


@pytest.mark.slow
def test_a_one_trial_value_not_from_my_filter_fails(folder) -> None:
    """03 Task 2: my_filter runs, but the fused positions come from another loop."""
    code = (HAND_LOOP
            + "fused_positions = loop(y, C, R)[:, 0]\n"
            "vision_positions = my_filter(y[:, :1], A, C[:1], Q, R[:1, :1], z0, P0)[:, 0]\n"
            "mse_fused_trial = float(metrics.mse(fused_positions, truth, burn_in))\n"
            "mse_vision_trial = float(metrics.mse(vision_positions, truth, burn_in))\n")
    error, printed = run_task("03_fusion", "check_fusion_trial", code, watch=False)
    assert error is None and printed.startswith("✓ "), (error, printed)
    error, _ = run_task("03_fusion", "check_fusion_trial", code)
    assert "fused_positions is not what your my_filter returned in the task cell above" in str(
        error), error


@pytest.mark.slow
def test_a_slip_with_my_filters_output_still_gets_its_named_cause(folder) -> None:
    """The velocity column of my_filter's estimates came from my_filter: the check names it."""
    code = ("fused_positions = my_filter(y, A, C, Q, R, z0, P0)[:, 1]\n"
            "vision_positions = my_filter(y[:, :1], A, C[:1], Q, R[:1, :1], z0, P0)[:, 0]\n"
            "mse_fused_trial = float(metrics.mse(fused_positions, truth, burn_in))\n"
            "mse_vision_trial = float(metrics.mse(vision_positions, truth, burn_in))\n")
    error, _ = run_task("03_fusion", "check_fusion_trial", code)
    assert "fused_positions is not right: it is column 1 of the estimates, the velocity" in str(
        error), error


# ------------------------------------------------------------------------------------------
# §1, function tasks: any function of the pack, at any depth
# ------------------------------------------------------------------------------------------

def bias_matrix_abs(dt):
    return np.abs(bias_model.transition_matrix(dt))


def predict_with_private_propagate(P, F, G, sigma):
    return prediction._propagate(P, F, sigma**2 * G @ G.T, 1, "steps")[-1]


def loop_over_the_packs_gains(y, A, C, Q, R, z0, P0):
    gains = _engine._covariance_sequence(len(y), A, C, Q, R, P0).gains
    z, estimates = z0, []
    for y_j, K in zip(y, gains, strict=True):
        z = A @ z + K @ (y_j - C @ A @ z)
        estimates.append(z)
    return np.array(estimates)


def compensate_with_delay_signal(estimates, A, delay_steps):
    from lqe_helpers.simulation import delay_signal

    return delay_signal(estimates, delay_steps) @ np.linalg.matrix_power(A, delay_steps).T


@pytest.mark.parametrize(("check", "function", "named"), [
    (checks.check_transition_matrix, bias_matrix_abs,
     "lqe_helpers.bias_model.equations.transition_matrix"),
    (checks.check_eyes_closed, predict_with_private_propagate, "lqe_helpers.prediction._propagate"),
    (checks.check_filter, loop_over_the_packs_gains, "lqe_helpers._engine._covariance_sequence"),
    (checks.check_compensation, compensate_with_delay_signal,
     "lqe_helpers.simulation.delay_signal"),
])
def test_a_function_task_that_runs_any_function_of_the_pack_fails(check, function, named):
    """The issue's cases, each the right answer: an old per-check forbid list missed them."""
    given = (eyes_closed()[0],) if check is checks.check_eyes_closed else ()
    assert_fails(f"runs the pack's own {named}", check, function, *given)


def test_a_function_task_may_call_the_students_own_loaded_function(folder, capsys) -> None:
    """01 Task 2 calls the saved my_filter: its wrappers (guard, call record) are no answer."""
    from lqe_helpers import student_code

    error, printed = run_task("01_vision_only", "check_vision_trial", None)
    assert error is None and printed.startswith("✓ "), (error, printed)
    loaded = student_code.load("my_filter")
    assert inspect.unwrap(loaded).__module__ == "my_functions.my_filter"


# ------------------------------------------------------------------------------------------
# §3: a ✓ only on what the current task cell made
# ------------------------------------------------------------------------------------------

def test_a_check_after_a_failed_task_cell_does_not_judge_the_old_values(folder, capsys):
    """03 Task 1 ran right, then failed when run again: C and R are the earlier run's."""
    before, task, check_cell = cells_up_to("03_fusion", "check_fusion")
    runner = CellRunner()
    try:
        for source in before:
            assert runner.run(source) is None
        assert runner.run(task) is None
        assert runner.run(check_cell) is None
        assert capsys.readouterr().out.startswith("✓ ")
        broken = task_comment(task) + "C = np.array([[1.0, 0.0, 0.0], [1.0, 0.0]])\nR = C\n"
        assert isinstance(runner.run(broken), ValueError)
        error = runner.run(check_cell)
        assert "the task cell above stopped with an error: fix it and run it again" in str(error)
        assert "✓" not in capsys.readouterr().out
        assert runner.run(task) is None and runner.run(check_cell) is None  # fixed: ✓ again
        assert capsys.readouterr().out.startswith("✓ ")
    finally:
        runner.close()


def test_a_name_the_check_cell_passes_that_no_cell_made_is_one_line(folder):
    before, task, check_cell = cells_up_to("03_fusion", "check_fusion")
    runner = CellRunner()
    try:
        for source in before:
            assert runner.run(source) is None
        error = runner.run(check_cell)                      # the task cell never ran
        assert isinstance(error, NameError)
        message = task_runs.missing_name_message(error, error.__traceback__)
        assert message == ("name 'C' is not defined: no cell run so far makes it. Run the "
                           "cells above this check in order, its task cell too, then this check "
                           "again")
        stub = task_comment(task) + "raise NotImplementedError\n"
        assert isinstance(runner.run(stub), NotImplementedError)
        error = runner.run(check_cell)
        message = task_runs.missing_name_message(error, error.__traceback__)
        assert message == ("name 'C' is not defined: the task cell that makes C is not written "
                           "yet: replace its line `raise NotImplementedError` with your code, "
                           "run it, then this check again")
        runner.namespace.update(C=np.eye(2), R=np.eye(2))  # earlier values: not judged
        error = runner.run(check_cell)
        assert str(error) == ("the task cell above is not written yet: replace its line `raise "
                              "NotImplementedError` with your code, run that cell, then this "
                              "check again")
        assert isinstance(runner.run(task_comment(task) + "C = [[1, 0, 0], [1, 0]\n"), SyntaxError)
        del runner.namespace["C"]
        error = runner.run(check_cell)
        message = task_runs.missing_name_message(error, error.__traceback__)
        assert message == ("name 'C' is not defined: the task cell that makes C stopped with "
                           "an error before making it: fix it and run it again, then this check")
        error = runner.run("print(undefined_name)\n")      # not a check cell: IPython's own
        assert task_runs.missing_name_message(error, error.__traceback__) is None
    finally:
        runner.close()


def test_without_the_record_a_check_judges_the_values_as_before(folder, capsys):
    """Plain Python (no IPython events): the check judges the values it is given."""
    before, task, check_cell = cells_up_to("03_fusion", "check_fusion")
    runner = CellRunner(watch=False)
    try:
        for source in [*before, task]:
            assert runner.run(source) is None
        assert isinstance(runner.run(task_comment(task) + "raise ValueError\n"), ValueError)
        assert task_runs.run_for("check_fusion") is None
        assert runner.run(check_cell) is None
        assert capsys.readouterr().out.startswith("✓ ")
    finally:
        runner.close()


def test_the_task_cell_of_a_check_is_the_latest_that_makes_its_names() -> None:
    task_runs._reset()
    runner = CellRunner()
    try:
        runner.run("# Task: build C\nC = 1\n")
        runner.run("# Task: build D from C\nD = C + 1\nraise ValueError\n")
        runner.run("checks = None\n")
        task_runs._RECORD.cell = "checks.check_fusion(C, R)"
        run = task_runs.run_for("check_fusion")
        assert run is not None and run.defines == {"C"} and run.completed
        task_runs._RECORD.cell = "checks.check_other(D)"
        assert task_runs.run_for("check_other").completed is False
    finally:
        runner.close()


def test_every_forbidden_entry_names_a_function_of_the_pack() -> None:
    """A misspelt entry would forbid nothing, silently."""
    from test_loopholes import pack_functions

    names = [name for name, _ in pack_functions()]
    for check, entries in own_work.TOP_LEVEL.items():
        assert hasattr(checks, check), check
        for entry in entries:
            assert any(own_work.covers(entry, name) for name in names), (check, entry)
    for check, wanted in own_work.DRIVEN.items():
        assert hasattr(checks, check), check
        assert {item.function for item in wanted} <= {"my_filter", "compensate"}


def test_only_the_recent_task_runs_keep_the_calls_of_saved_functions() -> None:
    runner = CellRunner()
    try:
        runner.namespace["note"] = task_runs.note_call
        for _ in range(task_runs.RUNS_WITH_CALLS + 1):
            assert runner.run("# Task: one trial\nnote('my_filter', (np.eye(2),), np.eye(2))\n"
                              .replace("np.eye", "__import__('numpy').eye")) is None
        runs = task_runs._RECORD.runs
        assert runs[0].saved_calls == []
        assert all(len(run.saved_calls) == 1 for run in runs[1:])
    finally:
        runner.close()


def test_a_function_task_may_read_the_scenarios_data() -> None:
    """The trial: vision_trial reading DEFAULT.truth was refused as "the pack's solution".
    Reading the task's data computes none of its answer; the filter must still be the
    student's own."""
    from reference_loops import student_lqe_filter

    vision = experiments.filter_model(DEFAULT)
    A, C, Q, z0, P0 = vision.A, vision.C, vision.Q, vision.z0, vision.P0
    namespace = {"my_filter": student_lqe_filter, "DEFAULT": DEFAULT, "np": np,
                 "A": A, "C": C, "Q": Q, "z0": z0, "P0": P0}
    exec("def vision_trial(sigma_v):\n"
         "    noise = DEFAULT.unit_noise(sensors=('vision',))\n"
         "    y = DEFAULT.truth[:, 0][:, None] + sigma_v * noise\n"
         "    return y, my_filter(y, A, C, Q, np.array([[sigma_v**2]]), z0, P0)\n", namespace)
    vision_trial = namespace["vision_trial"]

    with contextlib.redirect_stdout(io.StringIO()) as printed:
        checks.check_vision_trial(vision_trial)
    assert printed.getvalue().startswith("✓ ")

    def whole_state(sigma_v):
        y = DEFAULT.truth + sigma_v * DEFAULT.unit_noise(sensors=("vision",))
        return y, student_lqe_filter(y[:, :1], A, C, Q, np.array([[sigma_v**2]]), z0, P0)

    with pytest.raises(CheckFailed) as failed:
        checks.check_vision_trial(whole_state)
    assert "pack's own" not in str(failed.value)


@pytest.mark.slow
def test_a_wrong_value_made_from_my_filter_gets_its_own_cause_first(folder) -> None:
    """The second trial: 05's delayed made with np.roll from my_filter's output was told it
    was "not what your my_filter returned"; the check's own cause comes first now."""
    code = ("estimates = my_filter(y, vision.A, vision.C, vision.Q, vision.R, vision.z0, "
            "vision.P0)\n"
            "late_readings = simulation.delay_signal(y, steps)[:, 0]\n"
            "delayed = np.roll(estimates[:, 0], steps)\n"
            "compensated = compensate(estimates, vision.A, steps)[:, 0]\n")
    error, _ = run_task("05_sensory_delay", "check_delay_signals", code)
    assert isinstance(error, CheckFailed), error
    assert "not what your my_filter returned" not in str(error), str(error)
    assert str(error).startswith("delayed"), str(error)


# ------------------------------------------------------------------------------------------
# §1 again (the second student trial): the pack's answer made in an EARLIER cell, copied
# ------------------------------------------------------------------------------------------

#: The LOOPHOLES cases whose values are not one trial of the student's saved function.
CONSTANT_ANSWERS = ["00 Task 1, A from the pack", "00 Task 3, scenario.matched_jerk_std",
                    "03 Task 1, C and R from the model", "04 Task 1, R from the model",
                    "06 Task 1, the bias model's matrices"]


def answer_names(code: str) -> list[str]:
    """The values ``code`` makes: its top-level names but its defs and imports."""
    return sorted(name for name in task_runs.defined_names(code)
                  if f"def {name}(" not in code and name not in {"lqe_helpers", "copy"})


def copied(code: str, source: str = "") -> str:
    """A cell that copies every value ``code`` makes, from the names ``source + name``."""
    return "import copy\n" + "".join(f"{name} = copy.deepcopy({source}{name})\n"
                                     for name in answer_names(code))


def kept(code: str) -> str:
    """A cell keeping every value ``code`` makes under another name (``kept_ + name``)."""
    return "".join(f"kept_{name} = {name}\n" for name in answer_names(code))


@pytest.mark.slow
@pytest.mark.parametrize("case", CONSTANT_ANSWERS)
@pytest.mark.parametrize("through", ["directly", "through a second cell"])
def test_the_packs_answer_made_in_an_earlier_cell_and_copied_fails(case, through, folder):
    """The second trial: ``_pre = scenario.matched_jerk_std(...)`` in a cell of the student's,
    then ``jerk_stds = dict(_pre)`` in the task cell, passed (likewise 03's C and R, 06's F, G
    and Q). The check follows the task cell's values back through the student's cells."""
    notebook, check, code, named = LOOPHOLES[case]
    earlier, task = ((code,), copied(code)) if through == "directly" else (
        (code, kept(code)), copied(code, "kept_"))
    error, printed = run_task(notebook, check, task, earlier=earlier, watch=False)
    assert error is None and printed.startswith("✓ "), (error, printed)  # the right values
    error, printed = run_task(notebook, check, task, earlier=earlier)
    assert isinstance(error, CheckFailed), error
    assert "from a cell you ran before it" in str(error), str(error)
    assert named.removeprefix("lqe_helpers.") in str(error), str(error)
    assert printed == ""


@pytest.mark.slow
def test_the_pack_run_in_an_earlier_cell_on_other_inputs_is_no_reason_to_refuse(folder):
    """A student may try the pack's functions in a cell of their own; a task cell that does
    not use their values, which are not the task's answer, is judged on its own."""
    look = ("from lqe_helpers import model\n"
            "print(model.measurement_noise_covariance([1.0, 2.0]))\n"
            "seen = model.observation_matrix(('vision',))\n")
    error, printed = run_task("03_fusion", "check_fusion", None, earlier=(look,))
    assert error is None and printed.startswith("✓ "), (error, printed)


#: Ways a value leaves a cell without a name the task cell reads (03 Task 1's C and R).
HIDDEN_CHANNELS = {
    "a file": ("from lqe_helpers import model\n"
               "np.save('kept_c.npy', model.observation_matrix(FUSED))\n"
               "np.save('kept_r.npy', model.measurement_noise_covariance([sigma_v, sigma_p]))\n",
               "C = np.load('kept_c.npy')\nR = np.load('kept_r.npy')\n"),
    "a module's attribute": (
        "from lqe_helpers import model\n"
        "np.kept = (model.observation_matrix(FUSED),\n"
        "           model.measurement_noise_covariance([sigma_v, sigma_p]))\n",
        "C, R = (value.copy() for value in np.kept)\n"),
    "globals()": ("from lqe_helpers import model\n"
                  "globals()['C'] = model.observation_matrix(FUSED)\n"
                  "globals().update(R=model.measurement_noise_covariance([sigma_v, sigma_p]))\n",
                  "C = C * 1.0\nR = R + 0.0\n"),
}


@pytest.mark.slow
@pytest.mark.parametrize("channel", ["a file", "a module's attribute", "globals()"])
def test_the_packs_answer_passed_on_without_a_name_fails_too(channel, folder):
    """Names are not the only way a value travels between cells: what the check is given is
    compared with what the task's forbidden functions returned in the student's earlier
    cells. The message says what is true and how to start again."""
    earlier, task = HIDDEN_CHANNELS[channel]
    error, printed = run_task("03_fusion", "check_fusion", task, earlier=(earlier,),
                              watch=False)
    assert error is None and printed.startswith("✓ "), (error, printed)  # the right values
    error, printed = run_task("03_fusion", "check_fusion", task, earlier=(earlier,))
    assert isinstance(error, CheckFailed), error
    if channel == "a file":  # the task cell's read of the file is refused first
        assert str(error).startswith("the task cell above reads the file kept_c.npy. The "
                                     "check cannot see how numbers from a file"), error
    else:
        assert str(error).startswith(
            "C equals a value the pack's model.observation_matrix computed in a cell you ran "
            "before the task cell"), error
        assert "<locals>" not in str(error) and "put its code back" in str(error), error
        assert "restart the kernel" in str(error)
    assert printed == ""


@pytest.mark.slow
def test_the_packs_answer_looked_at_before_the_task_cell_is_refused_with_the_way_out(folder):
    """The policy the student edition's note states: values equal to what the task's pack
    function returned in a cell of the student's before the task cell cannot be told from
    it; the message says so, and how to start again."""
    look = ("from lqe_helpers import model\n"
            "print(model.measurement_noise_covariance([sigma_v, sigma_p]))\n")
    error, _printed = run_task("03_fusion", "check_fusion", None, earlier=(look,))
    assert isinstance(error, CheckFailed), error
    assert str(error).startswith("R equals a value the pack's"), error
    assert "model.measurement_noise_covariance" in str(error), error
    assert "restart the kernel" in str(error)


@pytest.mark.slow
def test_the_packs_answer_looked_at_after_the_task_cell_is_no_reason_to_refuse(folder):
    """Comparing with the pack once the task cell has run, then running the check (again),
    judges the task cell, which ran before the comparison."""
    look = ("from lqe_helpers import model\n"
            "print(model.measurement_noise_covariance([sigma_v, sigma_p]))\n")
    error, printed = run_task("03_fusion", "check_fusion", None, before_check=look)
    assert error is None and printed.startswith("✓ "), (error, printed)


@pytest.mark.slow
def test_comparing_with_the_pack_in_the_task_cell_gets_a_true_message(folder):
    """The second trial (D1): a right task cell that also prints the pack's MSE to compare was
    told the answer came from the pack. The message now says what is true and what to do;
    the same comparison in a cell after the task cell is no reason to refuse."""
    compare = "print(experiments.track(DEFAULT, FUSED).mse())\n"
    _before, task, _check = cells_up_to("03_fusion", "check_fusion_trial")
    error, _printed = run_task("03_fusion", "check_fusion_trial", task + "\n" + compare,
                               comment=False)
    assert isinstance(error, CheckFailed), error
    text = str(error)
    assert "runs the pack's experiments.track, which runs its own _engine.filter_run" in text
    assert "compare with the pack in a new cell below this check" in text
    assert "not your own work" not in text
    error, printed = run_task("03_fusion", "check_fusion_trial", None, before_check=compare)
    assert error is None and printed.startswith("✓ "), (error, printed)


#: 01 Task 2's vision_trial, returning the engine's results kept in an earlier cell.
KEEP_RESULTS = ("kept = {s: (experiments.readings(DEFAULT, sigmas=[s]),\n"
                "            experiments.track(DEFAULT, sigmas=[s]).result.estimates)\n"
                "        for s in (1.5, 4.5)}\n")


@pytest.mark.slow
def test_vision_trial_returning_results_kept_from_the_engine_fails(folder):
    """The second trial (L2): vision_trial returning results stored from experiments.track in
    an earlier cell passed. The check follows the function back to that cell, and, even
    without the record, requires the estimates to be what the student's my_filter returned
    inside vision_trial."""
    stored = "def vision_trial(sigma_v):\n    return kept[sigma_v]\n"
    error, _printed = run_task("01_vision_only", "check_vision_trial", stored,
                               earlier=(KEEP_RESULTS,))
    assert isinstance(error, CheckFailed), error
    assert "uses kept from a cell you ran before it" in str(error), str(error)
    error, _printed = run_task("01_vision_only", "check_vision_trial", stored,
                               earlier=(KEEP_RESULTS,), watch=False)
    assert isinstance(error, CheckFailed), error
    assert "vision_trial(1.5) does not run your my_filter" in str(error), str(error)
    filtered_aside = ("def vision_trial(sigma_v):\n"
                      "    y, estimates = kept[sigma_v]\n"
                      "    my_filter(y[::-1], A, C, Q, np.array([[sigma_v**2]]), z0, P0)\n"
                      "    return y, estimates\n")
    error, _printed = run_task("01_vision_only", "check_vision_trial", filtered_aside,
                               earlier=(KEEP_RESULTS,), watch=False)
    assert isinstance(error, CheckFailed), error
    assert "not what your my_filter returned inside it" in str(error), str(error)


def test_the_students_my_filter_is_put_back_after_the_check(folder) -> None:
    namespace: dict[str, object] = {"np": np}
    exec("def my_filter(*args):\n    raise ValueError('mine')\n"
         "def vision_trial(sigma_v):\n    return my_filter(sigma_v)\n", namespace)
    mine = namespace["my_filter"]
    with pytest.raises(CheckFailed):
        checks.check_vision_trial(namespace["vision_trial"])
    assert namespace["my_filter"] is mine


def test_a_trail_of_values_ends_at_a_cell_the_pack_gives(monkeypatch) -> None:
    """ancestry: the student's cells a task run draws on, transitively; a given cell (its
    code unchanged) ends the trail, however it made its values."""
    monkeypatch.setattr(task_runs, "is_given", lambda source: source.startswith("# given"))
    runner = CellRunner()
    try:
        runner.namespace["np"] = np
        runner.run("# given\nbase = np.ones(2)\n")
        runner.run("mine = base * 2\n")
        runner.run("unused = 3\n")
        runner.run("middle = mine + 1\n")
        runner.run("x = middle.copy()\nx = x + 1\n")
        run = task_runs._RECORD.runs[-1]
        found = [cell.source.split("=")[0].strip() for cell in task_runs.ancestry(run)]
    finally:
        runner.close()
    assert found == ["x", "middle", "mine"]


@pytest.mark.parametrize(("source", "reads"), [
    ("x = f(x)\n", {"f", "x"}),
    ("x = 1\ny = x\n", set()),
    ("d = {}\nd[1] = v\n", {"v"}),
    ("d[1] = 2\n", {"d"}),
    ("x += 1\n", {"x"}),
    ("import numpy as np\nfrom a import b\ny = np.ones(b)\n", set()),
    ("def f(a, b=c):\n    return a + g(b) + kept\n", {"c", "g", "kept"}),
    ("for i in items:\n    total = i\n", {"items"}),
    ("out = [v * k for v in values]\n", {"values", "k"}),
    ("lambda s: table[s]\n", {"table"}),
    ("class K(Base):\n    z = K2\n", {"Base", "K2"}),
    ("not python(", set()),
])
def test_the_names_a_cell_reads_are_those_it_uses_before_giving_them_a_value(source, reads):
    assert task_runs.read_names(source) == reads


def _arrays_within(value: object, depth: int = 3) -> list[np.ndarray]:
    """The arrays ``value`` holds, in its items and attributes, to ``depth`` levels."""
    if isinstance(value, np.ndarray):
        return [value]
    if depth == 0 or inspect.ismodule(value) or inspect.isroutine(value) or isinstance(
            value, (type, str, bytes)):
        return []
    if isinstance(value, dict):
        children = list(value.values())
    elif isinstance(value, (list, tuple)):
        children = list(value)
    elif dataclasses.is_dataclass(value):
        children = [getattr(value, field.name, None) for field in dataclasses.fields(value)]
    else:
        children = list(getattr(value, "__dict__", {}).values())
    return [array for child in children[:50] for array in _arrays_within(child, depth - 1)]


@pytest.mark.slow
@pytest.mark.parametrize(("notebook", "answers"), [
    ("03_fusion", ("R",)), ("04_noisier_proprioception", ("R",)),
    ("06_bonus_bias_and_input", ("F", "G", "Q"))])
def test_no_value_the_notebook_gives_holds_a_tasks_answer(notebook, answers, folder):
    """The second trial (L3): 03's and 04's given cells kept a filter model whose R a student
    could copy (``trial.model.R``). After every core cell has run, no value a given cell
    made holds a task's answer."""
    book = nbformat.read(NOTEBOOKS / f"{notebook}.ipynb", as_version=4)
    core = next((index for index, cell in enumerate(book.cells)
                 if cell.cell_type == "markdown" and "## Going further" in cell.source),
                len(book.cells))
    runner = CellRunner(watch=False)
    solutions: set[str] = set()
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            for cell in book.cells[:core]:
                tags = cell.metadata.get("tags", [])
                if cell.cell_type != "code" or "explorer" in tags:
                    continue
                assert runner.run(quiet(cell.source)) is None, cell.source[:200]
                if "solution" in tags:
                    solutions |= task_runs.defined_names(cell.source)
        namespace = runner.namespace
        for answer in answers:
            right = np.asarray(namespace[answer], dtype=float)
            holders = [name for name, value in namespace.items()
                       if name not in solutions and not name.startswith("_")
                       and any(array.shape == right.shape and np.allclose(array, right)
                               for array in _arrays_within(value))]
            assert not holders, (answer, holders)
    finally:
        runner.close()


@pytest.mark.slow
def test_the_packs_answer_computed_in_another_python_process_fails(folder):
    """The third trial (L-A): 03 Task 1's C and R from the pack run by a subprocess passed:
    the record cannot see another process, so a task whose values depend on one is refused."""
    code = ("import subprocess, sys, json\n"
            "_o = json.loads(subprocess.check_output([sys.executable, '-c', 'from lqe_helpers "
            "import model; import json; print(json.dumps([model.observation_matrix((\"vision\", "
            "\"proprioception\")).tolist(), model.measurement_noise_covariance([1.5, 1.5])"
            ".tolist()]))'], text=True))\n"
            "C, R = np.array(_o[0]), np.array(_o[1])\n")
    error, printed = run_task("03_fusion", "check_fusion", code, watch=False)
    assert error is None and printed.startswith("✓ "), (error, printed)
    error, printed = run_task("03_fusion", "check_fusion", code)
    assert isinstance(error, CheckFailed), error
    assert "the task cell above runs another program" in str(error), str(error)
    error, printed = run_task("03_fusion", "check_fusion",
                              "C, R = np.array(_o[0]), np.array(_o[1])\n",
                              earlier=(code.rsplit("C, R", 1)[0],))
    assert isinstance(error, CheckFailed), error
    assert "a cell you ran before the task cell" in str(error), str(error)


@pytest.mark.slow
def test_a_task_cell_rerun_that_stops_before_making_its_values_is_judged_not_the_old_run(
        folder):
    """The third trial (L-B): after a right run, the task cell re-run with only a raise under
    its comment defines nothing, and the check judged the earlier run's values."""
    _before, task, _check = cells_up_to("02_initial_covariance", "check_start_of_trial")
    error, printed = run_task("02_initial_covariance", "check_start_of_trial", None,
                              before_check=task_comment(task) + "raise RuntimeError('oops')\n")
    assert isinstance(error, CheckFailed), (error, printed)
    assert "the task cell above stopped with an error" in str(error)


@pytest.mark.slow
def test_a_note_added_to_a_given_cell_leaves_it_the_notebooks(folder, monkeypatch):
    """The third trial (D-1): a comment added to 02's given cell 6 (it runs the pack) made
    the worked Task 1 fail, "copied is not your own work"."""
    import cell_runner

    original = cell_runner.code_cells

    def noted(notebook):
        return [(source + "  # my note" if "burn_in" in source and "solution" not in tags
                 else source, tags) for source, tags in original(notebook)]

    monkeypatch.setattr(cell_runner, "code_cells", noted)
    before, _task, _check = cells_up_to("02_initial_covariance", "check_start_of_trial")
    assert any(source.endswith("# my note") for source in before)
    error, printed = run_task("02_initial_covariance", "check_start_of_trial", None)
    assert error is None and printed.startswith("✓ "), (error, printed)


#: The fourth trial: the pack's answer made by another program, left in a file. The program
#: runs in an earlier cell (os.system, subprocess) or beside the notebook (a terminal: here
#: the test writes the file before the cells run); the task cell only reads the file.
PROGRAM = ("import subprocess, sys\n"
           "subprocess.run([sys.executable, '-c', 'import numpy as np; from lqe_helpers import "
           "model; np.save(\"c.npy\", model.observation_matrix((\"vision\", \"proprioception\")));"
           " np.save(\"r.npy\", model.measurement_noise_covariance([1.5, 1.5]))'], check=True)\n")
SHELL = PROGRAM.replace("subprocess.run([sys.executable, '-c', ", "import shlex; os.system("
                        "shlex.quote(sys.executable) + ' -c ' + shlex.quote(").replace(
    "'], check=True)", "'))").replace("import subprocess, sys", "import os, sys")


@pytest.mark.slow
@pytest.mark.parametrize("where", ["subprocess in an earlier cell", "os.system in an earlier cell",
                                   "a program beside the notebook", "read in an earlier cell"])
def test_the_packs_answer_left_in_a_file_by_another_program_fails(where, folder):
    """The fourth trial: an earlier cell ran the pack in another program that wrote the
    answer to a file, and the task cell only read the file: ✓. The record cannot trace a
    file's numbers, so a task cell (or a cell of the student's it draws on) that reads a file
    is refused, and says which file."""
    read = "C = np.load('c.npy')\nR = np.load('r.npy')\n"
    earlier: tuple[str, ...] = ()
    if where == "a program beside the notebook":
        subprocess.run([sys.executable, "-c", PROGRAM], check=True, cwd=folder)
    else:
        earlier = (SHELL if where.startswith("os.system") else PROGRAM,)
    task = read
    if where == "read in an earlier cell":
        earlier, task = (PROGRAM, "kept_c = np.load('c.npy')\nkept_r = np.load('r.npy')\n"), (
            "C = kept_c.copy()\nR = kept_r.copy()\n")
    error, printed = run_task("03_fusion", "check_fusion", task, earlier=earlier, watch=False)
    assert error is None and printed.startswith("✓ "), (error, printed)  # the right values
    (folder / "c.npy").unlink()
    (folder / "r.npy").unlink()
    if where == "a program beside the notebook":
        subprocess.run([sys.executable, "-c", PROGRAM], check=True, cwd=folder)
    error, printed = run_task("03_fusion", "check_fusion", task, earlier=earlier)
    assert isinstance(error, CheckFailed), error
    assert "reads the file c.npy. The check cannot see how numbers from a file" in str(error), \
        error
    if where == "read in an earlier cell":
        assert str(error).startswith("a cell you ran before the task cell (`kept_c = "), error
    assert printed == ""


@pytest.mark.slow
def test_a_task_cell_that_imports_a_module_and_draws_a_figure_is_not_refused(folder):
    """Files of the installation (a module imported for the first time, matplotlib's fonts)
    are not a student's file."""
    _before, task, _check = cells_up_to("03_fusion", "check_fusion")
    extra = ("import io, fractions, matplotlib.pyplot as plt\n"
             "fig, ax = plt.subplots()\nax.set_title('C and R')\nfig.savefig(io.BytesIO())\n"
             "plt.close(fig)\n")
    error, printed = run_task("03_fusion", "check_fusion", task + "\n" + extra, comment=False)
    assert error is None and printed.startswith("✓ "), (error, printed)


ANSWER = ("from lqe_helpers import model\nC = model.observation_matrix(FUSED)\n"
          "R = model.measurement_noise_covariance([sigma_v, sigma_p])\n")
#: Ways the student's own code takes its work out of the record's sight (found after the
#: fourth trial): the pack's answer computed with the profile hook switched off, in another
#: thread, or by a copy of the pack's function under another file's name.
UNWATCHED = {
    "sys.setprofile": ("import sys\nsys.setprofile(None)\n" + ANSWER,
                       "switches off the pack's watch of the functions it runs (sys.setprofile)"),
    "a thread": ("import threading\n_t = threading.Thread(target=exec, args=(\n"
                 + repr(ANSWER) + ", globals()))\n_t.start()\n_t.join()\n",
                 "starts another thread, whose calls the pack cannot watch"),
    "code.replace": ("import types\nfrom lqe_helpers import _matrices\n"
                     "def _mine(f):\n"
                     "    return types.FunctionType(f.__code__.replace(co_filename='mine.py'),\n"
                     "                              f.__globals__)\n"
                     "C = _mine(_matrices.observation)(2)\n"
                     "R = _mine(_matrices.noise_covariance)(np.array([sigma_v, sigma_p]))\n",
                     "makes a code object by hand"),
}


@pytest.mark.slow
@pytest.mark.parametrize("how", list(UNWATCHED))
def test_the_packs_answer_made_out_of_the_records_sight_fails(how, folder):
    """Before this, each passed with ✓: the record saw no pack function run."""
    task, said = UNWATCHED[how]
    error, printed = run_task("03_fusion", "check_fusion", task)
    assert isinstance(error, CheckFailed), (error, printed)
    assert str(error).startswith(f"the task cell above {said}"), error
    assert "cannot tell them from the pack's answer" in str(error), error
    assert printed == ""


def test_a_task_cell_that_loses_the_records_hook_is_refused(folder):
    """Python switches a profile hook off when it raises (a RecursionError inside it); its
    ``sys.setprofile`` event may be one the watch does not blame on the student (here, heard
    with the watch set aside: ``outside.unheard``). A cell whose hook is gone at its end says
    so all the same, and its check refuses."""
    runner = CellRunner()
    try:
        lose = ("from lqe_helpers.student_code import outside\nimport sys\n"
                "with outside.unheard():\n    sys.setprofile(None)\n")
        assert runner.run("# Task: C and R\n" + lose + "C = R = 1\n") is None
        run = task_runs._RECORD.runs[-1]
        assert run.outside == [outside.LOST_WATCH]
        assert own_work.trail_problem("check_fusion", run).startswith(
            "the task cell above switched off the pack's watch of the functions it runs")
    finally:
        runner.close()


#: The sixth trial's routes to the answer a check computes: its frames (a failed check's
#: traceback), its private helpers, the memory. Each passed with ✓ before.
CHECKS_ANSWER = {
    "a failed check's traceback": (
        "import sys\ntry:\n    checks.check_convergence_times(0.0, 0.0)\n"
        "except Exception as error:\n    tb = error.__traceback__\n"
        "while tb.tb_frame.f_code.co_name != 'check_convergence_times':\n"
        "    tb = tb.tb_next\n"
        "t_small, t_large = map(float, tb.tb_frame.f_locals['right']['right'])\n",
        "the task cell above looks into the frames of a traceback or a generator"),
    "a check's private helper": (
        "from lqe_helpers.checks import initial_covariance\n"
        "t_small, t_large = map(float, initial_covariance._convergence()['right'])\n",
        "the task cell above runs the pack's own checks.initial_covariance._convergence"),
    "the memory": (
        "import gc\nfound = [o for o in gc.get_objects() if isinstance(o, dict) and 'right' in o"
        " and 'runs' in o]\nt_small, t_large = map(float, found[0]['right'])\n",
        "the task cell above searches the memory for objects"),
}


@pytest.mark.slow
@pytest.mark.parametrize("route", list(CHECKS_ANSWER))
def test_the_answer_a_check_computes_is_not_the_students(route, folder):
    code, said = CHECKS_ANSWER[route]
    error, printed = run_task("02_initial_covariance", "check_convergence_times", code)
    assert isinstance(error, CheckFailed), (error, printed)
    assert str(error).startswith(said), error


@pytest.mark.slow
def test_a_task_cell_that_runs_its_own_check_is_not_refused(folder):
    """The sixth trial: a right task cell that calls its check (✓ there) was then refused by
    the check cell, which took the check's own run of the pack for the student's."""
    _before, task, check = cells_up_to("00_background_model", "check_transition_matrix")
    error, printed = run_task("00_background_model", "check_transition_matrix",
                              task + "\n" + check + "\n", comment=False)
    assert error is None and printed.startswith("✓ "), (error, printed)


@pytest.mark.slow
def test_comparing_with_the_pack_after_a_passed_check_then_running_the_task_again_passes(
        folder):
    """The sixth trial: the messages suggest comparing with the pack in a new cell below the
    check; re-running the task cell after that comparison was refused as copied."""
    before, task, check = cells_up_to("03_fusion", "check_fusion")
    runner = CellRunner()
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            for source in (*before, task, check,
                           "from lqe_helpers import model\n"
                           "same = np.allclose(C, model.observation_matrix(FUSED))\n", task):
                assert runner.run(source) is None, source[:80]
        with contextlib.redirect_stdout(io.StringIO()) as printed:
            error = runner.run(check)
        assert error is None and printed.getvalue().startswith("✓ "), (error, printed.getvalue())
    finally:
        runner.close()


def _given_cell(notebook: str, starts: str) -> str:
    """The code of ``notebook``'s given cell whose code starts with ``starts``."""
    book = nbformat.read(NOTEBOOKS / f"{notebook}.ipynb", as_version=4)
    return next(cell.source for cell in book.cells if cell.cell_type == "code"
                and "solution" not in cell.metadata.get("tags", [])
                and cell.source.startswith(starts))


STAND_IN_FITS = ("import types\nfrom lqe_helpers import lowpass\n"
                 "fits = {name: types.SimpleNamespace(amplitude=1.0, lead=0.0) "
                 "for name in ('vision only', 'fused')}\n")


@pytest.mark.slow
def test_a_given_cell_from_further_on_run_early_does_not_lend_the_task_its_values(folder):
    """The sixth trial (defect 5): 03's Going-further Figure 3 cell, a given cell, run before
    Task 1 with a stand-in ``fits``, leaves ``settled_model``; ``C = settled_model.C.copy()``
    passed, because any given cell ended the trail of values. A given cell ends it only if it
    comes before the task in its notebook."""
    figure_cell = _given_cell("03_fusion", "frequencies = np.geomspace")
    copied = "C = settled_model.C.copy()\nR = settled_model.R.copy()\n"
    error, printed = run_task("03_fusion", "check_fusion", copied,
                              earlier=(STAND_IN_FITS, figure_cell))
    assert isinstance(error, CheckFailed), (error, printed)
    assert ("the task cell above uses settled_model from a cell of the notebook that comes "
            "after this task (`frequencies = np.geomspace") in str(error), str(error)
    # The given cells before the task still end the trail: the worked answer passes after
    # the same early run, and so does the task cell with its comment taken off.
    error, printed = run_task("03_fusion", "check_fusion", None,
                              earlier=(STAND_IN_FITS, figure_cell))
    assert error is None and printed.startswith("✓ "), (error, printed)


def test_a_given_cell_ends_a_trail_only_before_its_task() -> None:
    """given_cells.comes_before: by the places written by make notebooks (cell indices)."""
    from lqe_helpers.student_code import given_cells

    book = nbformat.read(NOTEBOOKS / "03_fusion.ipynb", as_version=4)
    code = [(index, cell) for index, cell in enumerate(book.cells) if cell.cell_type == "code"]
    first_given = next(cell.source for _, cell in code
                       if "solution" not in cell.metadata.get("tags", []))
    figure_cell = _given_cell("03_fusion", "frequencies = np.geomspace")
    check_cell = _given_cell("03_fusion", "checks.check_fusion(")
    task = next(cell.source for _, cell in code if "Build C, shape (2, 3)" in cell.source)
    for anchor in (given_cells.places(check_cell), given_cells.places(task),
                   given_cells.places(task_comment(task) + "C = 1\n")):
        assert anchor and anchor[0][0] == "03_fusion", anchor
        assert given_cells.comes_before(first_given, anchor)
        assert not given_cells.comes_before(figure_cell, anchor)
    assert given_cells.places("x = 1\n") == ()
    assert not given_cells.comes_before("x = 1\n", given_cells.places(check_cell))


@pytest.mark.slow
def test_a_given_cell_from_further_on_that_makes_an_input_again_leaves_the_task_its_own(
        folder, monkeypatch):
    """Re-running a task after the rest of the notebook: a given cell further on that makes
    an input again (``sigma_v``) and runs the pack is not where the task's values come from."""
    from lqe_helpers.student_code import given_cells

    later = ("sigma_v = 1.5\nlater_model = experiments.filter_model(DEFAULT, "
             "('vision', 'proprioception'))\n")
    monkeypatch.setitem(given_cells.GIVEN, given_cells.cell_key(later), (("03_fusion", 999),))
    error, printed = run_task("03_fusion", "check_fusion", None, earlier=(later,))
    assert error is None and printed.startswith("✓ "), (error, printed)
    error, printed = run_task("03_fusion", "check_fusion", "C = later_model.C.copy()\n"
                              "R = np.diag([sigma_v**2, sigma_p**2])\n", earlier=(later,))
    assert isinstance(error, CheckFailed), (error, printed)
    assert "comes after this task" in str(error), str(error)


@pytest.mark.slow
@pytest.mark.parametrize(("notebook", "check", "first", "second"), [
    ("05_sensory_delay", "check_delay_signals",
     "estimates = my_filter(y, vision.A, vision.C, vision.Q, vision.R, vision.z0, vision.P0)\n"
     "z_star = compensate(estimates, vision.A, steps)\n",
     "late_readings = simulation.delay_signal(y, steps)[:, 0]\n"
     "delayed = simulation.delay_signal(estimates, steps)[:, 0]\n"
     "compensated = z_star[:, 0]\n"),
    ("02_initial_covariance", "check_start_of_trial", None,
     "estimates_small = estimates_small.copy()\n"),
])
def test_a_one_trial_task_written_over_two_cells_passes(notebook, check, first, second,
                                                        folder) -> None:
    """The seventh trial (F1): the task cell runs my_filter (and compensate), and a cell of
    the student's after it makes the checked values from its results: "the task cell above
    does not run your my_filter" was a false refusal. The saved functions' calls of the
    cells the values are drawn from count."""
    error, printed = run_task(notebook, check, first, before_check=second)
    assert error is None and printed.startswith("✓ "), (error, printed)


@pytest.mark.slow
def test_the_packs_source_run_under_another_name_in_a_task_cell_fails(folder) -> None:
    """The seventh trial (L1): 03 Task 1 from the pack's own _matrices.py, read and run with
    exec under another file name, passed: code made from text by the student's own cell."""
    code = ("from lqe_helpers import _matrices\n"
            "_ns = {'__name__': 'mine'}\n"
            "exec(compile(open(_matrices.__file__).read().replace('from .', 'from lqe_helpers.'),"
            " 'mine.py', 'exec'), _ns)\n"
            "C = _ns['observation'](2)\n"
            "R = _ns['noise_covariance'](np.array([sigma_v, sigma_p]))\n")
    error, printed = run_task("03_fusion", "check_fusion", code, watch=False)
    assert error is None and printed.startswith("✓ "), (error, printed)
    error, printed = run_task("03_fusion", "check_fusion", code)
    assert isinstance(error, CheckFailed), (error, printed)
    assert "the task cell above makes code from text" in str(error), str(error)


@pytest.mark.slow
@pytest.mark.parametrize("module_name", ["mymat", "lqe_helpers.mine"])
def test_a_pack_file_imported_under_another_name_in_a_task_cell_fails(module_name,
                                                                       folder) -> None:
    """The eighth trial (D2): 03 Task 1 from the pack's _matrices.py imported with importlib
    under another module name passed: its functions were named by that module. They are
    named by their file, the pack's."""
    code = ("import importlib.util as _iu\nfrom lqe_helpers import _matrices as _m\n"
            f"_spec = _iu.spec_from_file_location({module_name!r}, _m.__file__)\n"
            "_mm = _iu.module_from_spec(_spec)\n_mm.__package__ = 'lqe_helpers'\n"
            "_spec.loader.exec_module(_mm)\n"
            "C = _mm.observation(2)\nR = _mm.noise_covariance(np.array([sigma_v, sigma_p]))\n")
    error, printed = run_task("03_fusion", "check_fusion", code, watch=False)
    assert error is None and printed.startswith("✓ "), (error, printed)
    error, printed = run_task("03_fusion", "check_fusion", code)
    assert isinstance(error, CheckFailed), (error, printed)
    assert "the task cell above runs the pack's own _matrices.observation" in str(error), (
        str(error))


@pytest.mark.slow
@pytest.mark.parametrize(("scratch", "task", "said"), [
    ("_Ps = propagate_covariance(P_close, A, sigma_j**2 * g @ g.T, 100)\n",
     "two_sigma = 2 * np.sqrt(globals()['_P' + 's'][:, 0, 0])\n", "globals()"),
    ("_Ps = propagate_covariance(P_close, A, sigma_j**2 * g @ g.T, 100)\n",
     "two_sigma = 2 * np.sqrt(vars()['_P' + 's'][:, 0, 0])\n", "vars()"),
    ("import builtins\nbuiltins.zz2 = propagate_covariance(P_close, A, sigma_j**2 * g @ g.T, "
     "100)\n", "import builtins\ntwo_sigma = 2 * np.sqrt(builtins.zz2[:, 0, 0])\n", "builtins"),
    ("import os, json\nos.environ['ZZ'] = json.dumps(propagate_covariance(P_close, A, "
     "sigma_j**2 * g @ g.T, 100)[:, 0, 0].tolist())\n",
     "import os, json\ntwo_sigma = 2 * np.sqrt(np.array(json.loads(os.environ['ZZ'])))\n",
     "os.environ"),
    ("np.zz4 = propagate_covariance(P_close, A, sigma_j**2 * g @ g.T, 100)\n",
     "two_sigma = 2 * np.sqrt(np.__dict__['zz' + '4'][:, 0, 0])\n", "__dict__"),
    ("_Ps = propagate_covariance(P_close, A, sigma_j**2 * g @ g.T, 100)\n",
     "two_sigma = 2 * np.sqrt(locals()['_P' + 's'][:, 0, 0])\n", "locals()"),
    ("np.zz3 = propagate_covariance(P_close, A, sigma_j**2 * g @ g.T, 100)\n",
     "two_sigma = 2 * np.sqrt(getattr(np, 'zz' + '3')[:, 0, 0])\n", "getattr with a name"),
])
def test_a_value_reached_by_a_name_made_at_run_time_fails(scratch, task, said,
                                                          folder) -> None:
    """The eighth trial (D1): 00 Task 2's band from a pack result of a scratch cell, reached
    by a name made as the code runs or kept outside the notebook's names, passed (the trail
    follows names written in the code)."""
    code = ("def predict_covariance(P, F, G, sigma):\n"
            "    return F @ P @ F.T + sigma**2 * G @ G.T\n" + task)
    error, printed = run_task("00_background_model", "check_eyes_closed", code,
                              earlier=(scratch,))
    assert isinstance(error, CheckFailed), (error, printed)
    assert f"the task cell above reaches values through {said}" in str(error), str(error)


def test_the_ways_to_reach_a_value_by_a_run_time_name_are_found_in_a_cells_code() -> None:
    from lqe_helpers.student_code.cell_code import untraceable_reads

    assert untraceable_reads("x = globals()['a' + 'b']\ny = Out[3]\n") == ["globals()", "Out"]
    assert untraceable_reads("ip = get_ipython()\nC = ip.user_ns['c']\n") == ["user_ns"]
    assert untraceable_reads("v = getattr(batch, 'positions')\nC = np.eye(2)\n") == []
    assert untraceable_reads("P_new = P.copy()\nd = dict(a=1)\nd['a']\n") == []
    assert untraceable_reads("not python(") == []
