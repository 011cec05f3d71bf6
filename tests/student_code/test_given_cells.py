"""The given cells: the keys are current, and they tell the pack's cells from a student's."""

from __future__ import annotations

import json

import nbformat
import pytest
from cell_runner import NOTEBOOKS

from lqe_helpers.authoring import given_cells as writer
from lqe_helpers.authoring.student_edition import student_edition
from lqe_helpers.student_code import given_cells
from lqe_helpers.student_code._given_cell_keys import GIVEN, TASKS


def test_the_keys_are_those_of_the_notebooks_given_cells() -> None:
    assert (GIVEN, TASKS) == writer.given_places(NOTEBOOKS), (
        "notebooks/ changed: run python -m lqe_helpers.authoring.given_cells (make notebooks)")


@pytest.mark.parametrize("notebook", sorted(path.name for path in NOTEBOOKS.glob("*.ipynb")))
def test_in_the_student_edition_the_given_cells_are_given_and_the_stubs_are_not(notebook):
    edition = nbformat.reads(student_edition(nbformat.read(NOTEBOOKS / notebook, as_version=4),
                                             notebook), as_version=4)
    code = [cell for cell in edition.cells if cell.cell_type == "code"]
    for index, cell in enumerate(code):
        assert given_cells.is_given(cell.source) == ("task" not in cell.metadata["tags"]
                                                     if "tags" in cell.metadata else True), (
            notebook, cell.source[:80])
        # every code cell stands where it stands in the worked notebook: a given cell by
        # its code, a stub by its ``# Task:`` line
        assert (notebook.removesuffix(".ipynb"), index) in given_cells.places(cell.source), (
            notebook, index, cell.source[:80])


def test_a_changed_cell_is_the_students_and_line_ends_do_not_matter() -> None:
    cells = [cell.source for cell in nbformat.read(NOTEBOOKS / "03_fusion.ipynb",
                                                    as_version=4).cells
             if cell.cell_type == "code" and "solution" not in cell.metadata.get("tags", [])]
    source = cells[0]
    assert given_cells.is_given(source)
    assert given_cells.is_given(source.replace("\n", "\r\n") + "\n\n")
    assert given_cells.is_given(source + "\n# a note of mine\n")  # the trial: a comment
    assert given_cells.is_given("# mine\n" + source.replace("\n", "  # x\n", 1))
    assert not given_cells.is_given(source + "\nprint(1)")
    assert not given_cells.is_given("")


def test_the_writer_writes_the_keys_module_and_refuses_a_folder_without_notebooks(
        tmp_path, monkeypatch, capsys) -> None:
    task = nbformat.v4.new_code_cell("# Task: y\ny = 2", metadata={"tags": ["solution"]})
    book = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("x = 1"), task])
    (tmp_path / "a.ipynb").write_text(json.dumps(book), encoding="utf-8")
    target = tmp_path / "keys.py"
    monkeypatch.setattr(writer, "KEYS_MODULE", target)
    assert writer.main(["--source", str(tmp_path)]) == 0
    namespace: dict[str, object] = {}
    exec(target.read_text(encoding="utf-8"), namespace)
    assert namespace["GIVEN"] == {given_cells.cell_key("x = 1"): (("a", 0),)}
    assert namespace["TASKS"] == {"# Task: y": (("a", 1),)}
    empty = tmp_path / "empty"
    empty.mkdir()
    before = target.read_bytes()
    assert writer.main(["--source", str(empty)]) == 1
    assert capsys.readouterr().err.count("\n") == 1
    assert target.read_bytes() == before
