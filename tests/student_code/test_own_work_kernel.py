"""In a Jupyter kernel: a check judges only what its current task cell made (issue 23 §1, §3).

One small notebook, run by nbclient as JupyterLab would: a task cell that computes C and R
with the pack's own functions fails its check naming the function; after the task cell
stops with an error, its check says so instead of judging the earlier run's C and R; the
worked cell passes; a name no cell made is one line in the check cell.
"""

from __future__ import annotations

import pytest
from test_student_code_kernel import error_of, run

pytestmark = pytest.mark.kernel

SETUP = """\
import numpy as np
from lqe_helpers import checks, student_code
student_code.brief_errors()
sigma_v, sigma_p = 1.5, 1.5
FUSED = ("vision", "proprioception")"""
TASK = "# Task: Build C, shape (2, 3), and R, shape (2, 2) in cm², from sigma_v and sigma_p.\n"
THE_PACKS = TASK + """\
from lqe_helpers import model
C = model.observation_matrix(FUSED)
R = model.measurement_noise_covariance([sigma_v, sigma_p])"""
FAILING = TASK + """\
C = np.array([[1.0, 0.0, 0.0], [1.0, 0.0]])
R = np.diag([sigma_v**2, sigma_p**2])"""
WORKED = TASK + """\
C = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
R = np.diag([sigma_v**2, sigma_p**2])"""
CHECK = "checks.check_fusion(C, R, sigma_v, sigma_p)"
UNMADE = "checks.check_noisier_sense(sigma_q, R)"


@pytest.fixture(scope="module")
def cells(tmp_path_factory):
    folder = tmp_path_factory.mktemp("own_work")
    return run([SETUP, THE_PACKS, CHECK, FAILING, CHECK, WORKED, CHECK, UNMADE], folder).cells


def test_a_task_cell_that_runs_the_packs_answer_fails_its_check_naming_it(cells) -> None:
    ename, shown = error_of(cells[2])
    assert ename == "CheckFailed"
    assert "the task cell above runs the pack's own model.observation_matrix" in shown
    assert "lqe_helpers/" not in shown


def test_after_a_failed_task_cell_its_check_says_so(cells) -> None:
    assert error_of(cells[3])[0] == "ValueError"
    ename, shown = error_of(cells[4])
    assert ename == "CheckFailed"
    assert "the task cell above stopped with an error: fix it and run it again" in shown
    assert "✓" not in "".join(output.get("text", "") for output in cells[4].outputs)


def test_the_worked_cell_passes(cells) -> None:
    [output] = cells[6].outputs
    assert output.text.startswith("✓ C (2 × 3) reads the position p")


def test_a_name_no_cell_made_is_one_line(cells) -> None:
    ename, shown = error_of(cells[7])
    assert ename == "NameError"
    assert shown == ("NameError: name 'sigma_q' is not defined: no cell run so far makes it. "
                     "Run the cells above this check in order, its task cell too, then this "
                     "check again")
