"""The code cells the pack gives, told apart from the cells a student writes.

Every code cell of a notebook that is not a task (not tagged ``solution``) reaches the
student as the pack wrote it: the set-up, the given data, the check calls, the figures,
the explorers. :data:`GIVEN` holds a key (:func:`cell_key`) of each of them, for all the
notebooks; a cell whose code is not among them (a task the student wrote, a cell of their
own, a given cell they changed) is the student's. The task-cell record
(:mod:`lqe_helpers.student_code.task_runs`) uses this to follow a task's values back
through the cells the student wrote, and only those.

``_given_cell_keys.py`` is written by ``python -m lqe_helpers.authoring.given_cells``
(``make notebooks`` runs it after executing the notebooks);
``tests/student_code/test_given_cells.py`` fails when it is not current.
"""

from __future__ import annotations

import ast
import hashlib

from ._given_cell_keys import GIVEN


def cell_key(source: str) -> str:
    """16 hex digits of the SHA-256 of a cell's code, as Python reads it.

    The key is of the code's syntax tree, so comments, blank lines and spacing do not
    change it (a student's note in a given cell leaves it given); code that does not
    parse is keyed by its text (line ends and outer blanks normalised).
    """
    text = source.replace("\r\n", "\n").replace("\r", "\n").strip()
    try:
        text = ast.dump(ast.parse(text))
    except (SyntaxError, ValueError):
        pass
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:16]


def is_given(source: str) -> bool:
    """Whether a cell's code is one the pack gives, unchanged."""
    return cell_key(source) in GIVEN
