"""The student pack copies only real files from its own folders, and writes elsewhere.

Issue 19: ``student_pack`` followed symlinks (a symlinked marking guide landed in the
student zip) and accepted ``--out`` inside the pack's own source folders. A symbolic
link (or a fifo, a device) in what the pack copies stops the build with one line naming
it, as every other tool refuses links; an output folder overlapping ``notebooks/``,
``lqe_helpers/`` or ``tests/`` is refused.
"""

from __future__ import annotations

import os
import zipfile
from pathlib import Path

import pytest
from tools_helpers import make_course, run_tool, snapshot, write_notebook

from lqe_helpers.authoring import student_pack
from lqe_helpers.authoring.errors import OutputFolderError, error_line

SECRET = "# Marking guide: the worked answers\n"


@pytest.fixture
def course(tmp_path: Path) -> Path:
    course = make_course(tmp_path / "course")
    (tmp_path / "instructor").mkdir()
    (tmp_path / "instructor" / "marking-guide.md").write_text(SECRET)
    return course


@pytest.mark.parametrize("link", [
    "tests/test_validation.py", "lqe_helpers/guide.md", "lqe_helpers/data",
    "notebooks/02_link.ipynb",
])
def test_a_symlink_in_what_the_pack_copies_stops_the_build(tmp_path, course, link):
    path = course / link
    if path.exists():
        path.unlink()
    target = tmp_path / "instructor" / ("" if link.endswith("data") else "marking-guide.md")
    if link.endswith(".ipynb"):
        target = write_notebook(tmp_path / "instructor" / "02_worked.ipynb")
    path.symlink_to(target)
    before = snapshot(tmp_path)
    with pytest.raises(ValueError) as raised:
        student_pack.build_student_pack(course, tmp_path / "out")
    line = error_line(raised.value)
    assert "\n" not in line and "symbolic link" in line, line
    assert str(path.name) in line
    assert snapshot(tmp_path) == before


def test_before_the_fix_the_guide_would_have_been_in_the_zip(tmp_path, course):
    """The same course without the link builds, and nothing of the guide is in it."""
    archive = student_pack.build_student_pack(course, tmp_path / "out")
    with zipfile.ZipFile(archive) as opened:
        assert all(SECRET.encode() not in opened.read(name) for name in opened.namelist())


def test_a_fifo_in_the_tests_stops_the_build_without_blocking(tmp_path, course):
    shipped = course / "tests" / "test_validation.py"  # a test the pack copies
    shipped.unlink()
    os.mkfifo(shipped)
    with pytest.raises(ValueError, match=r"test_validation\.py is not a regular file \(a fifo"):
        student_pack.build_student_pack(course, tmp_path / "out")
    (course / "lqe_helpers" / "pipe.py").unlink(missing_ok=True)
    shipped.unlink()
    shipped.write_text("def test_shipped():\n    assert True\n")
    os.mkfifo(course / "lqe_helpers" / "pipe.py")
    with pytest.raises(ValueError, match=r"pipe\.py is neither a file nor a folder"):
        student_pack.build_student_pack(course, tmp_path / "out")


@pytest.mark.parametrize("out", ["notebooks/pack", "lqe_helpers", "tests/out", ".", "..", "/"])
@pytest.mark.slow
def test_an_output_folder_overlapping_what_the_pack_copies_is_refused(tmp_path, course, out):
    before = snapshot(tmp_path)
    result = run_tool("student_pack", "--root", str(course), "--out", out, cwd=course)
    assert result.returncode == 1, result.stdout
    [line] = result.stderr.splitlines()
    assert "the output folder" in line and ("lies inside" in line or "contains" in line
                                            or " is the source folder" in line), line
    assert snapshot(tmp_path) == before


def test_an_output_folder_beside_the_sources_is_fine(tmp_path, course):
    written = student_pack.build_student_pack(course, course / "build" / "student-pack")
    assert written.name == student_pack.ZIP_NAME


@pytest.mark.slow
def test_the_pack_refuses_a_folder_another_tool_holds(tmp_path, course):
    """Two tools at once on one folder: the second stops at once with one line."""
    from lqe_helpers.authoring.folder_lock import FolderLock

    out = tmp_path / "out"
    out.mkdir()
    result = None
    with FolderLock(out):
        result = run_tool("student_pack", "--root", str(course), "--out", str(out))
    assert result.returncode == 1
    assert result.stderr == (f"error: another course tool is writing {out} right now; wait "
                             f"until it ends, then run this again (nothing was changed)\n")
    assert list(out.iterdir()) == []


def test_the_one_output_folder_check_is_the_pack_s(tmp_path, course):
    with pytest.raises(OutputFolderError, match="lies inside the source folder"):
        student_pack.build_student_pack(course, course / "lqe_helpers" / "zips")
