"""What grading adds to the points: the questions' labels and the saved functions.

The points themselves (which cells are graded, for how many) are
:mod:`lqe_helpers.authoring.points`, shared with the marking guide.
"""

from __future__ import annotations

import nbformat

from lqe_helpers.authoring.points import core_end

#: The tutorial's question of each graded notebook, by its number.
QUESTION_LABELS = {"01": "(a)", "02": "(b)", "03": "(c)", "04": "(d)", "05": "(e)"}
#: The folder where a check saves a student's function for later notebooks
#: (``student_code.SAVE_FOLDER``: 01 saves ``my_filter``, which 02–05 load). Grading makes it
#: anew from the submission's own notebooks; a submitted or instructor's copy is never used.
SAVED_FUNCTIONS = "my_functions"
#: The call by which a notebook saves a student's function for later notebooks.
SAVE_CALL = "student_code.save("


def question_label(notebook_name: str) -> str:
    """``(a)`` for ``01_vision_only…``; the notebook's name if it answers no question."""
    return QUESTION_LABELS.get(notebook_name[:2], notebook_name)


def saves_functions(notebook: nbformat.NotebookNode) -> bool:
    """Whether a worked notebook's core path saves a student's function (into
    :data:`SAVED_FUNCTIONS`) for the notebooks after it."""
    return any(cell.cell_type == "code" and SAVE_CALL in cell.source
               for cell in notebook.cells[:core_end(notebook)])
