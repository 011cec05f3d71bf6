"""The committed notebooks are what the brief promises before anyone runs them.

nbval proves that each notebook re-executes with the same text; these checks cover
what nbval does not look at: that the saved file was executed top to bottom in one
fresh kernel, carries no widget state, shows no error, and follows the pack's cell
tag convention (explorers marked for nbval, worked answers marked for the student
edition).
"""

from __future__ import annotations

from pathlib import Path

import nbformat
import pytest

NOTEBOOK_DIR = Path(__file__).resolve().parent.parent / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb"))
QUESTION_PREFIXES = ("01_", "02_", "03_", "04_", "05_")
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"


def code_cells(path: Path) -> list[nbformat.NotebookNode]:
    notebook = nbformat.read(path, as_version=4)
    return [cell for cell in notebook.cells if cell.cell_type == "code"]


def tags(cell: nbformat.NotebookNode) -> list[str]:
    return list(cell.metadata.get("tags", []))


def test_every_notebook_of_the_pack_is_here():
    prefixes = [path.name[:3] for path in NOTEBOOKS]
    assert prefixes == ["00_", "01_", "02_", "03_", "04_", "05_", "06_"]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_executed_top_to_bottom_in_one_fresh_kernel(path):
    counts = [cell.execution_count for cell in code_cells(path)]
    assert counts == list(range(1, len(counts) + 1)), (
        f"{path.name}: execution counts {counts}; re-run it with `make notebooks`")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_no_saved_widget_state_and_no_timings(path):
    notebook = nbformat.read(path, as_version=4)
    assert "widgets" not in notebook.metadata, f"{path.name} saved widget state"
    timed = [index for index, cell in enumerate(notebook.cells)
             if "execution" in cell.metadata]
    assert not timed, f"{path.name}: cells {timed} carry execution timings"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_no_error_and_every_figure_static(path):
    for index, cell in enumerate(code_cells(path)):
        kinds = [output.output_type for output in cell.outputs]
        assert "error" not in kinds, f"{path.name}, code cell {index} saved an error"
        streams = [output for output in cell.outputs if output.output_type == "stream"]
        assert all(output.name == "stdout" for output in streams), (
            f"{path.name}, code cell {index} wrote to stderr (a warning?)")
        for output in cell.outputs:
            data = output.get("data", {})
            if WIDGET_VIEW in data:
                assert "explorer" in tags(cell), (
                    f"{path.name}, code cell {index} shows a widget but is not tagged explorer")
                assert "image/png" in data, (
                    f"{path.name}, code cell {index}: a widget without its static figure")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_explorer_cells_are_marked_for_nbval(path):
    explorers = [cell for cell in code_cells(path) if "explorer" in tags(cell)]
    assert len(explorers) == 1, f"{path.name} has {len(explorers)} explorer cells, expected 1"
    for cell in explorers:
        assert "nbval-ignore-output" in tags(cell)
        assert any(WIDGET_VIEW in output.get("data", {}) for output in cell.outputs), (
            f"{path.name}: the explorer cell displays no widget")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_only_explorer_cells_skip_output_comparison(path):
    ignored = [index for index, cell in enumerate(code_cells(path))
               if "nbval-ignore-output" in tags(cell) and "explorer" not in tags(cell)]
    assert not ignored, f"{path.name}: code cells {ignored} hide their output from nbval"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_worked_answers_are_marked(path):
    notebook = nbformat.read(path, as_version=4)
    solutions = [cell for cell in notebook.cells if "solution" in tags(cell)]
    answers = [cell for cell in notebook.cells if "answer" in tags(cell)]
    assert solutions, f"{path.name} marks no solution cell: the student edition would leak"
    assert answers, f"{path.name} marks no written answer"
    for cell in solutions:
        assert cell.cell_type == "code"
        assert cell.source.startswith("# Task:"), (
            f"{path.name}: a solution cell does not start with '# Task:': "
            f"{cell.source[:60]!r}")
    assert all(cell.cell_type == "markdown" for cell in answers)


@pytest.mark.parametrize("path", [p for p in NOTEBOOKS if p.name.startswith(QUESTION_PREFIXES)],
                         ids=lambda path: path.stem)
def test_question_notebooks_state_their_marks(path):
    notebook = nbformat.read(path, as_version=4)
    text = "\n".join(cell.source for cell in notebook.cells if cell.cell_type == "markdown")
    assert "marks" in text, f"{path.name} never states the question's marks"
