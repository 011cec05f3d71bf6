"""The committed notebooks are what the brief promises before anyone runs them.

nbval proves that each notebook re-executes with the same text; these checks cover
what nbval does not look at: that the saved file was executed top to bottom in one
fresh kernel, carries no widget state, shows no error, and follows the pack's
conventions (``/work``'s STYLE and README): known cell tags only (explorers marked for
nbval, worked answers marked for the student edition, which builds), the ``lqe``
metadata with the tutorial's marks, a core path of at most 1,500 words of markdown
ended by ``## Going further``, a check after every core task (the background and bonus
notebooks too), and every static figure shown with its description through
``plotting.show_figure``.
"""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest

from lqe_helpers.authoring import student_edition as se
from lqe_helpers.authoring import task_cells as tc
from lqe_helpers.authoring.marking_guide import QUESTION_MARKS

NOTEBOOK_DIR = Path(__file__).resolve().parent.parent / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb"))
QUESTION_PREFIXES = ("01_", "02_", "03_", "04_", "05_")
QUESTIONS = [path for path in NOTEBOOKS if path.name.startswith(QUESTION_PREFIXES)]
#: Question of each notebook, in order: the tutorial's (a)–(e), with the background first
#: and the bonus last.
EXPECTED_QUESTIONS = ["background", "a", "b", "c", "d", "e", "bonus"]
#: Most words of markdown in the core path (before ``## Going further``).
CORE_WORDS = 1500
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
#: A figure shown by matplotlib itself rather than through plotting.show_figure.
BARE_SHOW = re.compile(r"\bplt\.show\(|\.show\(\s*\)")


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
    solutions = [cell for cell in notebook.cells if tc.SOLUTION_TAG in tags(cell)]
    answers = [cell for cell in notebook.cells if tc.ANSWER_TAG in tags(cell)]
    assert solutions, f"{path.name} marks no solution cell: the student edition would leak"
    assert answers, f"{path.name} marks no written answer"
    for cell in solutions:
        assert cell.cell_type == "code"
        assert cell.source.startswith(tc.TASK_PREFIX), (
            f"{path.name}: a solution cell does not start with {tc.TASK_PREFIX!r}: "
            f"{cell.source[:60]!r}")
    assert all(cell.cell_type == "markdown" for cell in answers)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_only_known_tags_and_the_student_edition_builds(path):
    notebook = nbformat.read(path, as_version=4)
    for index, cell in enumerate(notebook.cells):
        unknown = set(tags(cell)) - tc.ALLOWED_TAGS
        assert not unknown, f"{path.name}, cell {index}: unknown tags {sorted(unknown)}"
    se.student_edition(notebook, path.stem)  # raises, naming the cell, on a broken convention


def test_each_notebook_says_which_question_it_answers():
    found = [nbformat.read(path, as_version=4).metadata.get("lqe", {}).get("question")
             for path in NOTEBOOKS]
    assert found == EXPECTED_QUESTIONS


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_metadata_gives_the_tutorials_marks_and_the_core_time(path):
    meta = nbformat.read(path, as_version=4).metadata.get("lqe")
    assert meta is not None, f"{path.name} has no 'lqe' notebook metadata"
    assert set(meta) == {"question", "marks", "core_minutes"}, meta
    assert meta["marks"] == QUESTION_MARKS.get(meta["question"], 0), meta
    assert isinstance(meta["core_minutes"], int) and 0 < meta["core_minutes"] <= 60, meta


@pytest.mark.parametrize("path", QUESTIONS, ids=lambda path: path.stem)
def test_question_notebooks_state_their_marks(path):
    notebook = nbformat.read(path, as_version=4)
    text = "\n".join(cell.source for cell in notebook.cells if cell.cell_type == "markdown")
    marks = notebook.metadata.get("lqe", {}).get("marks")
    assert re.search(rf"\b{marks} marks\b", text), (
        f"{path.name} never states its {marks} marks in its text")


def core_end(notebook: nbformat.NotebookNode) -> int:
    """Index of the ``## Going further`` cell (the end of the core path), or -1."""
    return next((index for index, cell in enumerate(notebook.cells)
                 if cell.cell_type == "markdown"
                 and cell.source.lstrip().startswith(tc.GOING_FURTHER)), -1)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_a_short_core_path_then_going_further(path):
    notebook = nbformat.read(path, as_version=4)
    end = core_end(notebook)
    assert end > 0, f"{path.name} has no markdown cell starting {tc.GOING_FURTHER!r}"
    words = sum(len(cell.source.split()) for cell in notebook.cells[:end]
                if cell.cell_type == "markdown")
    assert words <= CORE_WORDS, f"{path.name}: {words} words of markdown before Going further"
    headings = [cell for cell in notebook.cells
                if cell.cell_type == "markdown" and tc.GOING_FURTHER in cell.source]
    assert len(headings) == 1, f"{path.name}: {len(headings)} Going further headings"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_a_check_right_after_every_core_task(path):
    notebook = nbformat.read(path, as_version=4)
    cells, end = notebook.cells, core_end(notebook)
    assert end > 0, f"{path.name} has no markdown cell starting {tc.GOING_FURTHER!r}"
    tasks = [index for index, cell in enumerate(cells[:end]) if tc.SOLUTION_TAG in tags(cell)]
    assert tasks, f"{path.name}: no task in the core path"
    for index in tasks:
        after = cells[index + 1] if index + 1 < len(cells) else None
        place = tc.cell_place(path.name, index, cells[index])
        assert after is not None and after.cell_type == "code" and not tags(after), (
            f"{place}: the next cell must be an untagged code cell with its check")
        calls = re.findall(r"\bchecks\.check_\w+\s*\(", after.source)
        assert len(calls) == 1, f"{place}: its check cell must call one checks.check_…(…)"
        printed = "".join(output.get("text", "") for output in after.outputs)
        assert printed.startswith("✓ "), f"{place}: its check printed {printed!r}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_every_figure_is_shown_with_its_description(path):
    for index, cell in enumerate(nbformat.read(path, as_version=4).cells):
        if cell.cell_type != "code" or tc.EXPLORER_TAG in tags(cell):
            continue
        place = f"{path.name}, cell {index}"
        assert not BARE_SHOW.search(cell.source), (
            f"{place} shows a figure with plt.show(); use plotting.show_figure(fig, '…')")
        for output in cell.outputs:
            if "image/png" in output.get("data", {}):
                alt = output.get("metadata", {}).get("image/png", {}).get("alt", "")
                assert len(alt.split()) >= 5, f"{place}: a figure without its description"
