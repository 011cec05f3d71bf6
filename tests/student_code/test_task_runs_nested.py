"""A task cell that runs a cell of its own (``get_ipython().run_cell(...)``), in a real
IPython shell: the nested cell's events neither end the task cell's record nor start one
(issue 23: the check said "the task cell above stopped with an error" of a cell that had
not), its code counts as the task cell's (a pack call in it is seen) and its error too.

The shell runs in a child process: IPython's shell is a process-wide singleton, which the
other tests of a worker must not see."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest

TASK = "# Task: Build C, shape (2, 3) and R, shape (2, 2) in cm² from sigma_v and sigma_p.\n"
C_LINE = "C = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])\n"
R_CODE = "R = np.diag([sigma_v**2, sigma_p**2])"

#: Case → the task cell's code.
CASES = {
    "a nested cell before the task's code": (
        f"{TASK}get_ipython().run_cell('print(1 + 1)')\n{C_LINE}{R_CODE}\n"),
    "the task's code in the nested cell": (
        f"{TASK}{C_LINE}get_ipython().run_cell({R_CODE!r})\n"),
    "a nested cell running the pack's answer": (
        f"{TASK}{C_LINE}get_ipython().run_cell('from lqe_helpers import model\\n"
        f"R = model.measurement_noise_covariance([sigma_v, sigma_p])')\n"),
    "a nested cell that stops with an error": (
        f"{TASK}get_ipython().run_cell('1 / 0')\n{C_LINE}{R_CODE}\n"),
    "a plain task cell after them": f"{TASK}{C_LINE}{R_CODE}\n",
}

SCRIPT = textwrap.dedent("""
    import json, sys
    from IPython.core.interactiveshell import InteractiveShell
    from lqe_helpers.student_code import task_runs

    shell = InteractiveShell.instance()
    task_runs.watch_task_cells(shell)
    shell.run_cell("import numpy as np\\nfrom lqe_helpers import checks")
    shell.run_cell("sigma_v = sigma_p = 1.5")
    outcomes = {}
    for name, task in json.loads(sys.argv[1]).items():
        shell.run_cell(task)
        result = shell.run_cell("checks.check_fusion(C, R, sigma_v, sigma_p)")
        outcomes[name] = "passed" if result.success else str(result.error_in_exec)
    print("OUTCOMES", json.dumps(outcomes))
""")


@pytest.fixture(scope="module")
def outcomes() -> dict[str, str]:
    done = subprocess.run([sys.executable, "-c", SCRIPT, json.dumps(CASES)],
                          capture_output=True, text=True, timeout=120, check=True)
    line = next(line for line in done.stdout.splitlines() if line.startswith("OUTCOMES "))
    return json.loads(line.removeprefix("OUTCOMES "))


@pytest.mark.slow
@pytest.mark.parametrize("case", ["a nested cell before the task's code",
                                  "the task's code in the nested cell",
                                  "a plain task cell after them"])
def test_a_task_cell_with_a_nested_cell_is_judged_as_one_cell(outcomes, case) -> None:
    assert outcomes[case] == "passed"


@pytest.mark.slow
def test_the_pack_run_in_a_nested_cell_is_the_task_cells(outcomes) -> None:
    assert outcomes["a nested cell running the pack's answer"].startswith(
        "the task cell above runs the pack's own model.measurement_noise_covariance")


@pytest.mark.slow
def test_an_error_of_a_nested_cell_is_named_as_such(outcomes) -> None:
    assert outcomes["a nested cell that stops with an error"].startswith(
        "the task cell above ran a cell of its own (get_ipython().run_cell) that stopped "
        "with an error")
