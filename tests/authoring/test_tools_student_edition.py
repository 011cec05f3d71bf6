"""The student edition never ships a worked answer because of how a cell is written.

Issue 19: an untagged code cell whose ``# Task:`` line was its second line shipped its
worked code (issue 27: so did one whose ``# Task:`` line followed an import line); a
misspelt tag on a notebook's only solution cell was reported as "no cell
is tagged 'solution'" instead of naming the typo.
"""

from __future__ import annotations

import pytest
from nbformat.v4 import new_code_cell
from tools_helpers import make_course, snapshot, worked_notebook, write_notebook

from lqe_helpers.authoring import marking_guide, student_edition, student_pack

WORKED = "estimate = truth + 0.5  # the worked answer"


@pytest.mark.parametrize("source", [
    f"\n\n# Task: add half a centimetre to the truth.\n{WORKED}",
    f"# Setup for the task below.\n# Task: add half a centimetre.\n{WORKED}",
    f"# A comment\n\n#task: add half a centimetre\n{WORKED}",
    f"    # Task: indented, still the cell's instruction\n{WORKED}",
    f"## Task: add half a centimetre\n{WORKED}",
    f"%%time\n# Task: add half a centimetre\n{WORKED}",
    f"# TASK :  add half a centimetre\n{WORKED}",
    # Issue 27: a '# Task:' comment after code (an import line, say) shipped the code too.
    f"import numpy as np\n# Task: add half a centimetre.\n{WORKED}",
    f"{WORKED}\n# Task: add half a centimetre (written below its code)",
])
def test_an_untagged_cell_whose_comment_block_holds_a_task_stops_the_build(tmp_path, source):
    extra = [new_code_cell(source)]
    write_notebook(tmp_path / "src" / "01_a.ipynb", worked_notebook(extra=extra))
    out = tmp_path / "out"
    with pytest.raises(ValueError) as raised:
        student_edition.build_student_edition(tmp_path / "src", out)
    message = str(raised.value)
    assert message.startswith("01_a, cell 5 ("), message
    assert "not tagged 'solution'" in message and "\n" not in message
    assert not out.exists()


@pytest.mark.parametrize("source", [
    f"# Setup: nothing to do here.\n{WORKED}",
    f"print('# Task: in a string')\n{WORKED}",
])
def test_other_cells_still_pass(tmp_path, source):
    write_notebook(tmp_path / "src" / "01_a.ipynb",
                   worked_notebook(extra=[new_code_cell(source)]))
    [written] = student_edition.build_student_edition(tmp_path / "src", tmp_path / "out")
    assert WORKED in written.read_text()  # not a task: kept as it is


@pytest.mark.parametrize("typo", ["soluton", "Solution", "solutions", "solution "])
def test_a_misspelt_tag_on_the_only_solution_cell_is_named(tmp_path, typo):
    write_notebook(tmp_path / "src" / "01_a.ipynb", worked_notebook(tags=(typo,)))
    with pytest.raises(ValueError) as raised:
        student_edition.build_student_edition(tmp_path / "src", tmp_path / "out")
    message = str(raised.value)
    assert f"unknown tag {typo!r}" in message, message
    assert "did you mean 'solution'?" in message
    assert "no cell is tagged" not in message


def test_the_pack_names_the_typo_too(tmp_path):
    course = make_course(tmp_path / "course")
    write_notebook(course / "notebooks" / "01_first.ipynb", worked_notebook(tags=("soluton",)))
    before = snapshot(course)
    with pytest.raises(ValueError, match="unknown tag 'soluton'"):
        student_pack.build_student_pack(course, tmp_path / "out")
    assert snapshot(course) == before
    assert not (tmp_path / "out").exists()


def test_the_marking_guide_does_not_drop_a_task_with_a_misspelt_tag(tmp_path):
    write_notebook(tmp_path / "src" / "01_a.ipynb", worked_notebook(tags=("soluton",)))
    with pytest.raises(ValueError, match=r"01_a\.ipynb, cell 2 .*unknown tag 'soluton'"):
        marking_guide.build_marking_guide(tmp_path / "src", tmp_path / "out")
    assert not (tmp_path / "out").exists()
