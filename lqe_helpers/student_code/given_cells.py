"""The code cells the pack gives, told apart from the cells a student writes, and their places.

Every code cell of a notebook that is not a task (not tagged ``solution``) reaches the
student as the pack wrote it: the set-up, the given data, the check calls, the figures,
the explorers. :data:`GIVEN` holds a key (:func:`cell_key`) of each of them, for all the
notebooks, with its places (notebook, index among its code cells); :data:`TASKS` holds the
places of each task's ``# Task:`` line. A cell whose code is not among the keys (a task
the student wrote, a cell of their own, a given cell they changed) is the student's. The
task-cell record (:mod:`lqe_helpers.student_code.task_runs`) uses this to follow a task's
values back through the cells the student wrote: a given cell that comes *before* the task in its
notebook ends that trail (its values are the task's inputs); a given cell from further on
(a student may run it early) does not.

``_given_cell_keys.py`` is written by ``python -m lqe_helpers.authoring.given_cells``
(``make notebooks`` runs it before executing the notebooks);
``tests/student_code/test_given_cells.py`` fails when it is not current.
"""

from __future__ import annotations

import ast
import functools
import hashlib

from ._given_cell_keys import GIVEN, TASKS
from .cell_code import TASK_PREFIX

#: A cell's places: (notebook name without ``.ipynb``, index among its code cells), ...
Places = tuple[tuple[str, int], ...]


@functools.lru_cache(maxsize=1024)
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


def task_line(source: str) -> str:
    """A cell's ``# Task:`` line with its blanks squeezed, or "" if it starts with none."""
    first = next((line for line in source.splitlines() if line.strip()), "").strip()
    return " ".join(first.split()) if first.startswith(TASK_PREFIX) else ""


def is_given(source: str) -> bool:
    """Whether a cell's code is one the pack gives, unchanged."""
    return cell_key(source) in GIVEN


def places(source: str) -> Places:
    """Where a cell stands in the pack's notebooks: a given cell's places, else those of
    its ``# Task:`` line; () for a cell of the student's own."""
    found = GIVEN.get(cell_key(source), ())
    line = task_line(source)
    return found or (TASKS.get(line, ()) if line else ())


def comes_before(source: str, later: Places) -> bool:
    """Whether the given cell ``source`` comes before one of the places ``later`` in the
    same notebook (where the pack runs it before them)."""
    return any(notebook == other and index < other_index
               for notebook, index in GIVEN.get(cell_key(source), ())
               for other, other_index in later)
