"""What is graded in a worked notebook, and for how many points.

One rule for the marking guide and both grading routes (:mod:`lqe_helpers.grading`, which
imports it from here: nothing in authoring imports grading). Only the core path is graded
(the cells before ``## Going further``, which is optional and carries no points). A
question's marks (the tutorial's, :data:`~lqe_helpers.authoring.marking_guide.QUESTION_MARKS`)
are split: :data:`ANSWER_SHARE` of them go to its written answers (``answer`` cells,
marked by hand), the rest to its check cells (the untagged ``checks.check_…`` cell right
after each ``solution`` cell), shared equally; a check cell earns its points when it runs
without raising. Notebooks 00 and 06 (background, bonus) have 0 marks, so 0 points.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction

import nbformat

from lqe_helpers.authoring.task_cells import (
    ANSWER_TAG,
    CHECK_CALL,
    GOING_FURTHER,
    SOLUTION_TAG,
    cell_tags,
)

#: Share of a question's marks given to its written answers (the checks share the rest).
ANSWER_SHARE = Fraction(2, 5)
#: The check function a check cell calls (its name is the cell's grade id).
CHECK_NAME = re.compile(r"\bchecks\.(check_\w+)\s*\(")


@dataclass(frozen=True)
class GradedCell:
    """A cell of a worked notebook's core path that takes part in grading.

    Attributes
    ----------
    index : int
        The cell's index in the worked notebook.
    kind : str
        ``"task"`` (a ``solution`` cell, no points of its own), ``"check"`` (the check
        cell after a task: automatic points) or ``"answer"`` (marked by hand).
    grade_id : str
        Its name in grade tables and nbgrader (``task-1``, ``check_filter``, ``answer-1``).
    points : float
        Points it carries (0 for a task).
    """

    index: int
    kind: str
    grade_id: str
    points: float


def core_end(notebook: nbformat.NotebookNode) -> int:
    """Index of the ``## Going further`` cell (the number of cells if none)."""
    return next((index for index, cell in enumerate(notebook.cells)
                 if cell.cell_type == "markdown"
                 and cell.source.lstrip().startswith(GOING_FURTHER)), len(notebook.cells))


def is_check_cell(cell: nbformat.NotebookNode | None) -> bool:
    """Whether ``cell`` is a check cell: untagged code calling ``checks.check_…``."""
    return (cell is not None and cell.cell_type == "code" and not cell_tags(cell)
            and CHECK_CALL in cell.source)


def graded_cells(notebook: nbformat.NotebookNode, marks: int) -> list[GradedCell]:
    """The tasks, checks and written answers of the core path, with their points.

    Parameters
    ----------
    notebook : nbformat.NotebookNode
        A worked notebook (cells tagged ``solution`` and ``answer``).
    marks : int
        The question's marks (``marking_guide.question_and_marks``); ≥ 0.

    Returns
    -------
    list of GradedCell
        In cell order. The points of the checks and answers add up to ``marks``
        (to the answers only if no task has a check, to the checks if no answer).

    Raises
    ------
    ValueError
        If ``marks`` is negative, or two check cells call the same check (their grade
        ids would clash).
    """
    if marks < 0:
        raise ValueError(f"marks must be >= 0, got {marks!r}")
    cells = notebook.cells[:core_end(notebook)]
    found: list[tuple[int, str, str]] = []
    for index, cell in enumerate(cells):
        tags = cell_tags(cell)
        if SOLUTION_TAG in tags:
            found.append((index, "task", f"task-{sum(k == 'task' for _, k, _ in found) + 1}"))
            after = cells[index + 1] if index + 1 < len(cells) else None
            match = CHECK_NAME.search(after.source) if is_check_cell(after) else None
            if match:
                found.append((index + 1, "check", match.group(1)))
        elif ANSWER_TAG in tags:
            found.append((index, "answer",
                          f"answer-{sum(k == 'answer' for _, k, _ in found) + 1}"))
    ids = [grade_id for _, kind, grade_id in found if kind == "check"]
    if len(set(ids)) < len(ids):
        raise ValueError(f"two check cells call the same check ({', '.join(ids)}); each "
                         f"check cell must call its own check to be graded")
    n_checks = len(ids)
    n_answers = sum(kind == "answer" for _, kind, _ in found)
    answer_share = ANSWER_SHARE if n_checks and n_answers else Fraction(int(n_answers > 0))
    each = {"task": Fraction(0),
            "check": (1 - answer_share) * marks / n_checks if n_checks else Fraction(0),
            "answer": answer_share * marks / n_answers if n_answers else Fraction(0)}
    return [GradedCell(index, kind, grade_id, float(each[kind]))
            for index, kind, grade_id in found]
