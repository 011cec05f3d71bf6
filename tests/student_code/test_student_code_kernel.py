"""In a Jupyter kernel: a failed check shows the student's own cells and one message.

nbclient runs small notebooks as JupyterLab would. The error output a student sees (its
``traceback``) must hold their cell and the message and no line of ``lqe_helpers``; the
time limit must stop a pure-Python endless loop in the kernel; a function saved in one
kernel must load in a fresh one.
"""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient
from nbformat.v4 import new_code_cell, new_notebook

pytestmark = pytest.mark.kernel

KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
ANSI = re.compile(r"\x1b\[[0-9;]*m")

SETUP = """\
import numpy as np
from lqe_helpers import checks, student_code
from lqe_helpers.student_code import calling
calling.TIME_LIMIT = 1.0"""
WRONG_C = """\
C = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
checks.check_fusion(C, np.diag([2.25, 2.25]), 1.5, 1.5)"""
RAISING = """\
def my_filter(y, A, C, Q, R, z0, P0):
    rows = []
    for y_j in y:
        gain = 1 / 0
    return np.array(rows)"""
ENDLESS = """\
def my_filter(y, A, C, Q, R, z0, P0):
    j = 0
    while j < len(y):
        try:
            rows = [z0]
        except Exception:
            pass
    return np.array(rows)"""
CHECK = "checks.check_filter(my_filter)"
SAVED_RAISING = """\
# Written by lqe_helpers.student_code.save: edit the notebook, not this file.
import numpy as np

def my_filter(y, A, C, Q, R, z0, P0):
    for y_j in y:
        gain = 1 / 0
    return y
"""
LATER_CALL = """\
import numpy as np
my_filter = student_code.load('my_filter')
my_filter(np.zeros((3, 1)), np.eye(1), np.eye(1), np.eye(1), np.eye(1), np.zeros(1), np.eye(1))"""
READ_ONLY = """\
student_code.brief_errors()
P_close = np.eye(3)
P_close.flags.writeable = False
P = P_close
P += np.eye(3)"""
SAVE = """\
def doubled(x):
    return 2 * np.asarray(x)

print(student_code.save(doubled)(21))"""
OUTSIDE = """\
factor = 3
def tripled(x):
    return factor * x

student_code.save(tripled)"""


def run(cells: list[str], folder: Path) -> nbformat.NotebookNode:
    notebook = new_notebook(cells=[new_code_cell(source) for source in cells],
                            metadata={"kernelspec": KERNELSPEC})
    NotebookClient(notebook, timeout=120, kernel_name="python3", allow_errors=True,
                   resources={"metadata": {"path": str(folder)}}).execute()
    return notebook


def error_of(cell: nbformat.NotebookNode) -> tuple[str, str]:
    """(ename, the traceback as the student sees it, without colours) of a cell's error."""
    [error] = [output for output in cell.outputs if output.output_type == "error"]
    return error.ename, ANSI.sub("", "\n".join(error.traceback))


@pytest.fixture(scope="module")
def executed(tmp_path_factory) -> tuple[nbformat.NotebookNode, Path]:
    folder = tmp_path_factory.mktemp("kernel")
    return run([SETUP, WRONG_C, RAISING, CHECK, ENDLESS, CHECK, SAVE, OUTSIDE], folder), folder


def assert_only_the_students_code(shown: str) -> None:
    assert "lqe_helpers" not in shown and "site-packages" not in shown, shown
    assert "__tracebackhide__" not in shown and "raise failure" not in shown, shown


def test_a_failed_check_shows_the_cell_and_the_message_only(executed) -> None:
    notebook, _ = executed
    name, shown = error_of(notebook.cells[1])
    assert name == "CheckFailed"
    assert "----> 2 checks.check_fusion(C, np.diag([2.25, 2.25]), 1.5, 1.5)" in shown
    assert shown.rstrip().endswith("CheckFailed: C's row 1 (proprioception) is [0.0, 1.0, "
                                   "0.0], which reads velocity v. Proprioception measures the "
                                   "position only: its row must pick out p from the state "
                                   "[p, v, a], with weight 1")
    assert_only_the_students_code(shown)


def test_an_error_in_the_students_function_shows_their_own_line(executed) -> None:
    notebook, _ = executed
    name, shown = error_of(notebook.cells[3])
    assert name == "CheckFailed"
    assert "----> 1 checks.check_filter(my_filter)" in shown
    assert "in my_filter(y, A, C, Q, R, z0, P0)" in shown and "----> 4         gain = 1 / 0" \
        in shown
    assert ("CheckFailed: my_filter raised ZeroDivisionError: division by zero (in my_filter, "
            "line 4 of cell In[3]: `gain = 1 / 0`), on a model with k = 3 states") in shown
    assert_only_the_students_code(shown)


def test_the_time_limit_stops_an_endless_loop_in_the_kernel(executed) -> None:
    notebook, _ = executed
    name, shown = error_of(notebook.cells[5])
    assert name == "TimedOut"
    assert "TimedOut: my_filter did not return within 1 s (in my_filter, line " in shown
    assert "of cell In[5]" in shown
    assert_only_the_students_code(shown)


def test_a_saved_function_loads_in_a_fresh_kernel(executed) -> None:
    notebook, folder = executed
    assert "".join(output.text for output in notebook.cells[6].outputs) == (
        "doubled is saved in my_functions/doubled.py, where student_code.load('doubled') "
        "finds it\n42\n")
    name, shown = error_of(notebook.cells[7])
    assert name == "StudentCodeError"
    assert shown.rstrip().endswith(
        "StudentCodeError: tripled uses factor from the notebook; a saved function may use only "
        "its arguments, numpy as np, Python's built-ins and functions of yours defined with def "
        "at the top of a cell under the same rule. Pass the others in as arguments (or compute "
        "them inside), run its cell, then this one again")
    assert_only_the_students_code(shown)
    (folder / "my_functions" / "my_filter.py").write_text(SAVED_RAISING, "utf-8")
    later = run(["from lqe_helpers import student_code\n"
                 "print(student_code.load('doubled')([1, 2]))", LATER_CALL, READ_ONLY],
                folder)
    assert later.cells[0].outputs[0].text == "[2 4]\n"
    # A saved my_filter that raises in a later notebook: the student's lines (the cell, the
    # saved file) and one message, not the source of the pack's inputs guard.
    name, shown = error_of(later.cells[1])
    assert name == "StudentCodeError"
    assert shown.rstrip().endswith(
        "StudentCodeError: my_filter raised ZeroDivisionError: division by zero (in "
        "my_filter, line 6 of my_filter.py: `gain = 1 / 0`). This my_filter is yours, saved by "
        "notebook 01 (the check after Task 1): fix it there, run that check again (it saves "
        "my_filter anew), then restart this notebook's kernel and run it from the top")
    assert "----> 6         gain = 1 / 0" in shown and "guards" not in shown
    assert_only_the_students_code(shown)
    # numpy's "assignment destination is read-only" names the array and how to copy it.
    name, shown = error_of(later.cells[2])
    assert name == "ValueError"
    assert shown.rstrip().endswith("ValueError: P_close is read-only: copy it "
                                   "(P = P_close.copy()) before changing P in place")
    assert "numpy" not in shown and "assignment destination" not in shown
    (folder / "my_functions" / "my_filter.py").unlink()
    # Not saved yet: loading says so in one line and gives a stand-in, so the notebook runs
    # on; using the stand-in is the error, with only the student's code shown.
    missing = run(["from lqe_helpers import student_code",
                   "my_filter = student_code.load('my_filter')", "my_filter(None)"], folder)
    said = "".join(output.get("text", "") for output in missing.cells[1].outputs)
    assert said.startswith("my_filter is not saved yet: my_functions/my_filter.py does not "
                           "exist. notebook 01"), said
    name, shown = error_of(missing.cells[2])
    assert name == "NotSavedYet"
    assert "my_filter is not saved yet" in shown
    assert_only_the_students_code(shown)


def test_an_input_error_of_the_pack_shows_only_the_students_code(tmp_path) -> None:
    """After student_code.brief_errors(), a ValueError the pack raises about an input
    shows the student's cell and the message; an error of the student's own code, and one
    of numpy, keep IPython's usual traceback."""
    notebook = run(["import numpy as np\nfrom lqe_helpers import metrics, student_code\n"
                    "student_code.brief_errors()",
                    "estimate = np.array([np.nan, 1.0])\n"
                    "mse = metrics.mse(estimate, np.zeros(2))",
                    "def mine():\n    raise ValueError('my own')\nmine()",
                    "np.zeros(2) @ np.zeros(3)"], tmp_path)
    assert notebook.cells[0].outputs == []
    name, shown = error_of(notebook.cells[1])
    assert name == "ValueError"
    assert "mse = metrics.mse(estimate, np.zeros(2))" in shown
    assert "estimate must be finite" in shown
    assert_only_the_students_code(shown)
    name, shown = error_of(notebook.cells[2])
    assert name == "ValueError" and "raise ValueError('my own')" in shown
    name, shown = error_of(notebook.cells[3])
    assert name == "ValueError" and "matmul" in shown
