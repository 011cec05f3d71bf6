"""Simulated submissions of notebook 01 (and of 02–05 for the whole assignment), made from
the worked notebooks and their student editions or nbgrader's release.

Used by the grading tests (tests/grading/test_grading*.py) and benchmarks/bench_grading.py. Each
maker returns the text of an ``.ipynb`` file (or raw bytes for the broken ones).
"""

from __future__ import annotations

import copy
from pathlib import Path

import nbformat

from lqe_helpers.authoring.points import core_end
from lqe_helpers.authoring.student_edition import student_edition
from lqe_helpers.authoring.task_cells import SOLUTION_TAG, TASK_TAG, cell_tags

ROOT = Path(__file__).resolve().parents[1]
WORKED = ROOT / "notebooks" / "01_vision_only.ipynb"
NAME = WORKED.name
#: The automatic points of 01: check_filter and check_vision_trial, 4.5 each.
CHECKS = ("check_filter", "check_vision_trial")

#: my_filter without Q in the covariance update (the filter grows overconfident).
WRONG_FILTER = '''def my_filter(y, A, C, Q, R, z0, P0):
    z, P, estimates = z0, P0, []
    for y_j in y:
        K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
        z = A @ z + K @ (y_j - C @ A @ z)
        P = A @ (P - K @ C @ P) @ A.T
        estimates.append(z)
    return np.array(estimates)
'''
#: vision_trial with R = [[σ_v]]: σ where σ² belongs.
WRONG_TRIAL = '''def vision_trial(sigma_v):
    y = truth[:, None] + sigma_v * noise
    R = np.array([[sigma_v]])
    return y, my_filter(y, A, C, Q, R, z0, P0)
'''
#: A first look that never ends (i is never increased), before the worked function.
LOOP = "i = 0\nwhile i < 10:\n    pass\n"


def worked() -> nbformat.NotebookNode:
    """The worked notebook as it is."""
    return nbformat.read(WORKED, as_version=4)


def edition() -> nbformat.NotebookNode:
    """The untouched student edition of 01."""
    return nbformat.reads(student_edition(worked(), WORKED.stem), as_version=4)


def _tasks(notebook: nbformat.NotebookNode) -> list[nbformat.NotebookNode]:
    """The core path's task cells (Going further's stay as they are)."""
    return [cell for cell in notebook.cells[:core_end(notebook)]
            if {SOLUTION_TAG, TASK_TAG} & set(cell_tags(cell))]


def _filled(notebook: nbformat.NotebookNode, bodies: list[str | None],
            source: Path = WORKED) -> nbformat.NotebookNode:
    """``notebook`` (a student's copy of the worked notebook ``source``) with each core
    task's code (None: the worked one)."""
    notebook = copy.deepcopy(notebook)
    solutions = _tasks(nbformat.read(source, as_version=4))
    for task, solution, body in zip(_tasks(notebook), solutions, bodies, strict=True):
        task.source = solution.source if body is None else \
            "# Task: (the student's)\n" + body
    return notebook


def filled(notebook: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """Every task written as the worked notebook does."""
    return _filled(notebook, [None, None])


def filled_as(notebook: nbformat.NotebookNode, name: str) -> nbformat.NotebookNode:
    """A student's copy of the worked notebook ``name`` (e.g. ``03_fusion.ipynb``) with
    every core task written as the worked notebook does."""
    source = WORKED.parent / name
    return _filled(notebook, [None] * len(_tasks(notebook)), source)


def wrong_science(notebook: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """Both of 01's core tasks written with a realistic mistake."""
    return _filled(notebook, [WRONG_FILTER, WRONG_TRIAL])


def endless_loop(notebook: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """Task 1 worked; task 2's cell starts with a loop that never ends."""
    notebook = filled(notebook)
    _tasks(notebook)[1].source = LOOP + _tasks(notebook)[1].source
    return notebook


def raises_first(notebook: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """The first code cell raises; task 2 is wrong and its check cell edited to pass."""
    notebook = _filled(notebook, [None, WRONG_TRIAL])
    first = next(cell for cell in notebook.cells if cell.cell_type == "code")
    first.source = "raise RuntimeError('my own first cell')\n" + first.source
    check = next(cell for cell in notebook.cells if "checks.check_vision_trial(" in cell.source)
    check.source = "print('✓ vision_trial is right')  # edited by the student"
    return notebook


def out_of_order(notebook: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """Untouched, saved with ✓ outputs and execution counts out of order."""
    notebook = copy.deepcopy(notebook)
    for count, cell in enumerate(reversed(notebook.cells)):
        if cell.cell_type == "code":
            cell.execution_count = count + 1
            cell.outputs = [nbformat.v4.new_output("stream", text="✓ all right\n")]
    return notebook


#: Name → (what the student did to their copy, whether each check passes).
SUBMISSIONS = {
    "filled": (filled, {"check_filter": True, "check_vision_trial": True}),
    "untouched": (out_of_order, {"check_filter": False, "check_vision_trial": False}),
    "wrong": (wrong_science, {"check_filter": False, "check_vision_trial": False}),
    "loop": (endless_loop, {"check_filter": True, "check_vision_trial": False}),
    "raises": (raises_first, {"check_filter": True, "check_vision_trial": False}),
}
#: Submissions that are not notebooks: each must still get a row.
BROKEN = {"invalid": b"{not json", "empty": b"", "not-a-notebook": b'{"cells": 3}'}


def submission(student: str, notebook: nbformat.NotebookNode) -> str:
    """The ``.ipynb`` text ``student`` of :data:`SUBMISSIONS` submits from ``notebook``."""
    return nbformat.writes(SUBMISSIONS[student][0](notebook))
