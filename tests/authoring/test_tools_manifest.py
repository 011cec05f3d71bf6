"""A manifest is never trusted: no file outside an output folder can be deleted through it.

Issue 19's case: a rebuild deleted any file the output folder's ``.lqe-manifest.json``
listed under ``../…`` (or ``sub/../../…``, or through a symlinked sub-folder) when its
checksum matched, and exited 0. Each tool is attacked through its real build function
(handouts without a kernel: its notebooks are "executed" by reading them), and ``clean``
too. A poisoned entry stops the build with one line naming it, and nothing anywhere is
changed. ``clean`` removes only temporary folders a tool recorded creating.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from tools_helpers import (
    MANIFEST,
    make_course,
    poison_manifest,
    run_tool,
    snapshot,
    write_notebook,
)

from lqe_helpers.authoring import handouts, marking_guide, student_edition, student_pack
from lqe_helpers.authoring.errors import OutputFolderError
from lqe_helpers.authoring.notebook_io import read_notebook
from lqe_helpers.authoring.output_folder import write_output_folder


def fake_execute(path, timeout=None, *, allow_errors=False):
    """handouts' notebooks 'executed' without a kernel: their saved outputs, as read."""
    return read_notebook(path)


def build(tool: str, course: Path, out: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    notebooks = course / "notebooks"
    if tool == "student_edition":
        student_edition.build_student_edition(notebooks, out)
    elif tool == "marking_guide":
        marking_guide.build_marking_guide(notebooks, out)
    elif tool == "handouts":
        monkeypatch.setattr(handouts, "execute_notebook", fake_execute)
        handouts.build_handouts(notebooks, out, mathjax_url="")
    else:
        student_pack.build_student_pack(course, out)


TOOLS = ["student_edition", "marking_guide", "handouts", "student_pack"]


def poisoned_entries(course: Path, out: Path) -> dict[str, str]:
    """Entry → how it reaches the victim, ``course/notebooks/01_first.ipynb``."""
    (out / "link").symlink_to(course / "notebooks", target_is_directory=True)
    (out / "sub").mkdir()
    return {
        "dot-dot": "../course/notebooks/01_first.ipynb",
        "through a sub-folder": "sub/../../course/notebooks/01_first.ipynb",
        "through a symlinked sub-folder": "link/01_first.ipynb",
        "absolute": str(course / "notebooks" / "01_first.ipynb"),
    }


@pytest.mark.parametrize("tool", TOOLS)
@pytest.mark.parametrize("how", ["dot-dot", "through a sub-folder",
                                 "through a symlinked sub-folder", "absolute"])
@pytest.mark.slow
def test_a_rebuild_never_deletes_what_a_poisoned_manifest_lists(tmp_path, monkeypatch, tool,
                                                                how):
    course = make_course(tmp_path / "course")
    out = tmp_path / "out"
    build(tool, course, out, monkeypatch)
    entry = poisoned_entries(course, out)[how]
    poison_manifest(out, entry, course / "notebooks" / "01_first.ipynb")
    before_course, before_out = snapshot(course), snapshot(out)
    with pytest.raises(OutputFolderError) as raised:
        build(tool, course, out, monkeypatch)
    message = str(raised.value)
    assert "\n" not in message
    assert repr(entry) in message and MANIFEST in message, message
    assert "nothing was changed" in message
    assert snapshot(course) == before_course  # the victim is still there
    assert snapshot(out) == before_out


@pytest.mark.slow
def test_the_issue_case_from_the_command_line(tmp_path):
    """A listed ``../../notebooks/01_…`` with its checksum: one error line, exit 1."""
    course = make_course(tmp_path / "course")
    out = course / "build" / "student"
    result = run_tool("student_edition", "--out", "build/student", cwd=course)
    assert result.returncode == 0, result.stderr
    poison_manifest(out, "../../notebooks/01_first.ipynb", course / "notebooks" / "01_first.ipynb")
    before = snapshot(course)
    result = run_tool("student_edition", "--out", "build/student", cwd=course)
    assert result.returncode == 1
    assert result.stderr.count("\n") == 1 and result.stderr.startswith("error: "), result.stderr
    assert "'../../notebooks/01_first.ipynb'" in result.stderr
    assert snapshot(course) == before


@pytest.mark.parametrize("entry", ["", ".", "a//b", "./a", "a/./b", "a\\..\\b", "a/", "x\x00y",
                                   MANIFEST, ".lqe-build-x/a", ".lqe-journal.json"])
def test_every_other_odd_entry_stops_the_build(tmp_path, entry):
    out = tmp_path / "out"
    write_output_folder(out, {"a": "x"}, tool="t")
    content = json.loads((out / MANIFEST).read_text())
    content["files"][entry] = "0" * 64
    (out / MANIFEST).write_text(json.dumps(content))
    before = snapshot(tmp_path)
    with pytest.raises(OutputFolderError, match="nothing was changed"):
        write_output_folder(out, {"b": "y"}, tool="t")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("content", [
    {"format": 1, "tool": "t", "files": {"a": 5}},
    {"format": 1, "tool": "t", "files": {"a": "not a checksum"}},
    {"format": 1, "tool": ["t"], "files": {"a": "0" * 64}},
    {"format": 1, "tool": "t", "files": ["a"]},
    {"format": 99, "tool": "t", "files": {}},
])
def test_a_manifest_of_the_wrong_shape_is_refused(tmp_path, content):
    out = tmp_path / "out"
    write_output_folder(out, {"a": "x"}, tool="t")
    (out / MANIFEST).write_text(json.dumps(content))
    before = snapshot(tmp_path)
    with pytest.raises(OutputFolderError, match="is not a manifest the course tools can read"):
        write_output_folder(out, {"b": "y"}, tool="t")
    assert snapshot(tmp_path) == before


def test_clean_refuses_a_poisoned_manifest_and_deletes_nothing(tmp_path):
    victim = tmp_path / "notebooks" / "01_worked.ipynb"
    write_notebook(victim)
    out = tmp_path / "build" / "student"
    write_output_folder(out, {"01.ipynb": "student", "02.ipynb": "other"},
                        tool="student_edition")
    poison_manifest(out, "../../notebooks/01_worked.ipynb", victim)
    other = tmp_path / "build" / "handouts"
    write_output_folder(other, {"index.html": "i"}, tool="handouts")
    before = snapshot(out)
    result = run_tool("clean", str(out), str(other), cwd=tmp_path)
    assert result.returncode == 1
    [line] = result.stderr.splitlines()
    assert line.startswith(f"error: {out / MANIFEST} lists '../../notebooks/01_worked.ipynb'")
    assert victim.is_file()
    assert snapshot(out) == before  # not one of its files deleted
    assert not other.exists()  # the other folder was cleaned all the same


def test_clean_keeps_a_folder_a_user_named_with_the_reserved_prefix(tmp_path):
    out = tmp_path / "build" / "handouts"
    write_output_folder(out, {"index.html": "i"}, tool="handouts")
    mine = out / ".lqe-build-my-drafts"
    mine.mkdir()
    (mine / "draft.html").write_text("my draft")
    beside = tmp_path / "build" / ".handouts.lqe-build-notes"
    beside.mkdir()
    (beside / "notes.txt").write_text("my notes")
    result = run_tool("clean", str(out), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert (mine / "draft.html").read_text() == "my draft"
    assert (beside / "notes.txt").read_text() == "my notes"
    assert not (out / "index.html").exists()
    assert ".lqe-build-my-drafts/draft.html" in result.stdout


def test_a_manifest_that_is_a_deep_json_is_one_line(tmp_path):
    out = tmp_path / "out"
    write_output_folder(out, {"a": "x"}, tool="t")
    (out / MANIFEST).write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(OutputFolderError, match="is not a manifest the course tools can read"):
        write_output_folder(out, {"b": "y"}, tool="t")
    assert os.path.exists(out / "a")
