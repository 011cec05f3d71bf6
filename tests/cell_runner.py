"""A notebook's cells run in this process, with IPython's cell events fired at a fake shell.

The task-cell record (:mod:`lqe_helpers.student_code.task_runs`) listens to IPython's
``pre_run_cell`` and ``post_run_cell`` events. :class:`CellRunner` fires them around each
cell it runs (as IPython does), without a kernel, so the tests of what a check judges
(``tests/checks/test_own_work.py``, ``tests/checks/test_loopholes.py``) stay fast. Not a
test module.
"""

from __future__ import annotations

import linecache
import shutil
from collections import defaultdict
from pathlib import Path
from types import SimpleNamespace

import nbformat

from lqe_helpers.student_code import task_runs

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"


class Events:
    """IPython's ``shell.events``: ``register`` and ``trigger``."""

    def __init__(self) -> None:
        self.callbacks: dict[str, list] = defaultdict(list)

    def register(self, name: str, callback) -> None:
        self.callbacks[name].append(callback)

    def trigger(self, name: str, *args: object) -> None:
        for callback in self.callbacks[name]:
            callback(*args)


class CellRunner:
    """Runs cells' code in one namespace, as a kernel would, firing the cell events.

    With ``watch=False`` the events go nowhere: the checks then behave as in plain Python.
    """

    def __init__(self, watch: bool = True) -> None:
        task_runs._reset()
        self.events = Events()
        if watch:
            task_runs.watch_task_cells(self)
        self.namespace: dict[str, object] = {"__name__": "__main__"}
        self.count = 0

    def run(self, source: str) -> BaseException | None:
        """Run one cell; return the exception it stopped with, or None."""
        self.count += 1
        filename = f"<cell In[{self.count}]>"
        linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
        error = code = None
        try:  # compiled here, as IPython compiles a cell: not by the cell's own code
            code = compile(source, filename, "exec")
        except SyntaxError as caught:
            error = caught
        self.events.trigger("pre_run_cell", SimpleNamespace(raw_cell=source))
        try:
            if code is not None:
                exec(code, self.namespace)
        except Exception as caught:  # a cell's error, as IPython reports it
            error = caught
        self.events.trigger("post_run_cell",
                            SimpleNamespace(success=error is None, error_in_exec=error))
        return error

    def close(self) -> None:
        task_runs._reset()


def code_cells(notebook: str) -> list[tuple[str, list[str]]]:
    """The code cells of ``notebooks/<notebook>.ipynb``: (source, tags), in order."""
    book = nbformat.read(NOTEBOOKS / f"{notebook}.ipynb", as_version=4)
    return [(cell.source, list(cell.metadata.get("tags", []))) for cell in book.cells
            if cell.cell_type == "code"]


def quiet(source: str) -> str:
    """A set-up cell without the pack's plot style (a global of matplotlib in this process)."""
    return source.replace("plotting.use_pack_style()", "")


def cells_up_to(notebook: str, check: str) -> tuple[list[str], str, str]:
    """The cells before the task of ``check``, that task's cell and its check cell.

    Explorer cells and figure cells are left out (the tests need only the values).
    """
    cells = code_cells(notebook)
    for index, (source, _) in enumerate(cells):
        if f"checks.{check}(" in source:
            before = [quiet(text) for text, tags in cells[: index - 1]
                      if "explorer" not in tags and "figures." not in text
                      and "show_figure" not in text]
            return before, cells[index - 1][0], source
    raise LookupError(f"{check} is not called in {notebook}")


def saved_functions(folder: Path) -> None:
    """Copy the worked notebooks' saved functions into ``folder/my_functions``."""
    shutil.copytree(NOTEBOOKS / "my_functions", folder / "my_functions", dirs_exist_ok=True)


def task_comment(source: str) -> str:
    """The ``# Task:`` comment block at the top of a task cell."""
    lines = []
    for line in source.splitlines():
        if not line.startswith("#"):
            break
        lines.append(line)
    return "\n".join(lines) + "\n"
