"""The student notebooks of this pack are well formed (they are not run: the tasks are yours).

Shipped in the student pack as ``tests/test_student_notebooks.py`` (by
``lqe_helpers.authoring.student_pack``); ``make test`` runs it with the unit tests. The
conventions it checks come from ``tests/student_pack.json``, which the pack's build
writes from the instructor tools' own definitions. For every notebook in ``notebooks/``:

- it is a valid notebook, and the pack's notebooks are all there;
- it carries only the student edition's tags;
- every task cell starts with ``# Task:``, and in the core path (before
  ``## Going further``) of a question notebook a check cell (``checks.check_…(…)``)
  follows each task before the next one (cells you add in between are fine);
- every check it calls exists in ``lqe_helpers.checks``;
- every import outside the task cells resolves: the module is installed and has the
  names imported from it.

Your own code and your answers are never judged here; the checks in the notebooks do that.
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import json
import re
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[1]
CONVENTIONS = json.loads((Path(__file__).with_name("student_pack.json")).read_text("utf-8"))
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
CHECK_FUNCTION = re.compile(r"\bchecks\.(check_\w+)\s*\(")


def tags(cell: nbformat.NotebookNode) -> list[str]:
    return list(cell.get("metadata", {}).get("tags", []))


def read(path: Path) -> nbformat.NotebookNode:
    notebook = nbformat.read(path, as_version=4)
    nbformat.validate(notebook)
    return notebook


def test_every_notebook_of_the_pack_is_here():
    assert [path.name for path in NOTEBOOKS] == sorted(CONVENTIONS["notebooks"])


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_only_student_tags(path):
    for index, cell in enumerate(read(path).cells):
        unknown = set(tags(cell)) - set(CONVENTIONS["tags"])
        assert not unknown, f"{path.name}, cell {index}: tags {sorted(unknown)}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_each_task_is_followed_by_its_check(path):
    cells = read(path).cells
    tasks = [index for index, cell in enumerate(cells) if CONVENTIONS["task_tag"] in tags(cell)]
    assert tasks, f"{path.name} has no task"
    end = next((index for index, cell in enumerate(cells) if cell.cell_type == "markdown"
                and cell.source.lstrip().startswith(CONVENTIONS["going_further"])), len(cells))
    for number, index in enumerate(tasks):
        assert cells[index].cell_type == "code"
        assert cells[index].source.startswith(CONVENTIONS["task_prefix"]), (
            f"{path.name}, cell {index}: a task starts with {CONVENTIONS['task_prefix']!r}")
        if path.name not in CONVENTIONS["checked_notebooks"] or index > end:
            continue
        following = cells[index + 1:tasks[number + 1] if number + 1 < len(tasks) else end]
        checks = [cell for cell in following if cell.cell_type == "code" and not tags(cell)
                  and CONVENTIONS["check_call"] in cell.source]
        assert checks, f"{path.name}, cell {index}: no check follows this core task"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_the_checks_called_exist(path):
    checks = importlib.import_module("lqe_helpers.checks")
    for index, cell in enumerate(read(path).cells):
        if cell.cell_type == "code" and CONVENTIONS["task_tag"] not in tags(cell):
            for name in CHECK_FUNCTION.findall(cell.source):
                assert callable(getattr(checks, name, None)), (
                    f"{path.name}, cell {index}: lqe_helpers.checks has no {name}")


def imports(source: str) -> list[tuple[str, str | None]]:
    """(module, name or None) for every import statement of a cell's code."""
    try:
        tree = ast.parse(source)
    except SyntaxError:  # IPython syntax such as %magics: nothing to check
        return []
    found: list[tuple[str, str | None]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, None) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            found += [(node.module, alias.name) for alias in node.names]
    return found


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_imports_resolve(path):
    for index, cell in enumerate(read(path).cells):
        if cell.cell_type != "code" or CONVENTIONS["task_tag"] in tags(cell):
            continue
        for module, name in imports(cell.source):
            where = f"{path.name}, cell {index}"
            assert importlib.util.find_spec(module) is not None, f"{where}: no module {module}"
            if name is not None and name != "*":
                loaded = importlib.import_module(module)
                assert (hasattr(loaded, name)
                        or importlib.util.find_spec(f"{module}.{name}") is not None), (
                    f"{where}: {module} has no {name}")


def test_the_package_is_this_packs_own():
    """The notebooks import the lqe_helpers beside them, not another copy."""
    module = importlib.import_module("lqe_helpers")
    assert Path(module.__file__).resolve().parent == ROOT / "lqe_helpers"
