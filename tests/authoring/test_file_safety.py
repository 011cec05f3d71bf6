"""The course tools' file safety: atomic writes, owned output folders, one-line errors.

Every failure here is provoked for real (a full disk is an ``OSError(ENOSPC)`` raised
half-way through a write, a read-only folder an ``OSError(EACCES)`` or a real
``chmod``), and each test checks that every file that existed is byte-identical after.
"""

from __future__ import annotations

import argparse
import errno
import json
import os
import stat
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_notebook
from tools_helpers import snapshot

from lqe_helpers.authoring import command_line, files, folder_lock, manifest, notebook_io
from lqe_helpers.authoring.errors import (
    FileSafetyError,
    NotebookFileError,
    OutputFolderError,
    OutputWriteError,
)
from lqe_helpers.authoring.manifest import MANIFEST_NAME
from lqe_helpers.authoring.output_folder import check_out_dir, write_output_folder

IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0


def full_disk_after(limit: int):
    """A stand-in for ``files._write_fd`` that writes ``limit`` bytes, then fails (ENOSPC)."""
    real = files._write_fd

    def write(fd: int, data: bytes) -> None:
        real(fd, data[:limit])
        raise OSError(errno.ENOSPC, "No space left on device")

    return write


# --- single files ------------------------------------------------------------------------------

def test_atomic_write_creates_and_replaces_keeping_the_mode(tmp_path):
    path = tmp_path / "a.txt"
    files.atomic_write_text(path, "first")
    assert path.read_text() == "first"
    path.chmod(0o640)
    files.atomic_write_bytes(path, b"second")
    assert path.read_bytes() == b"second"
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert sorted(os.listdir(tmp_path)) == ["a.txt"]  # no temporary file left


def test_a_full_disk_mid_write_leaves_the_file_byte_identical(tmp_path, monkeypatch):
    path = tmp_path / "worked.ipynb"
    path.write_bytes(b"the worked notebook " * 100)
    before = snapshot(tmp_path)
    monkeypatch.setattr(files, "_write_fd", full_disk_after(10))
    with pytest.raises(OSError) as raised:
        files.atomic_write_bytes(path, b"x" * 5000)
    assert raised.value.errno == errno.ENOSPC
    assert snapshot(tmp_path) == before


def test_a_symlink_is_never_written_through_nor_replaced(tmp_path):
    worked = tmp_path / "01_worked.ipynb"
    worked.write_text("worked")
    link = tmp_path / "link.ipynb"
    link.symlink_to(worked)
    dangling = tmp_path / "dangling.ipynb"
    dangling.symlink_to(tmp_path / "nowhere")
    before = snapshot(tmp_path)
    for target in (link, dangling):
        with pytest.raises(FileSafetyError, match="is a symbolic link"):
            files.atomic_write_text(target, "student edition")
    with pytest.raises(FileSafetyError, match="is a folder"):
        files.atomic_write_text(tmp_path, "x")
    assert snapshot(tmp_path) == before


def test_atomic_write_many_is_all_or_nothing(tmp_path, monkeypatch):
    first, second = tmp_path / "good.ipynb", tmp_path / "other.ipynb"
    first.write_text("good before")
    second.write_text("other before")
    before = snapshot(tmp_path)

    # A full disk while the second is being written: nothing replaced yet.
    monkeypatch.setattr(files, "_write_fd", full_disk_after(3))
    with pytest.raises(OSError):
        folder_lock.atomic_write_many({first: "good after", second: "other after"})
    assert snapshot(tmp_path) == before
    monkeypatch.undo()

    # The second move fails after the first one was made: the first is put back.
    real_link = os.link

    def link(source, target, *args, **kwargs):  # a new file is linked into place
        if Path(target) == second:
            raise OSError(errno.EACCES, "Permission denied", str(target))
        return real_link(source, target, *args, **kwargs)

    monkeypatch.setattr(os, "link", link)
    with pytest.raises(OSError):
        folder_lock.atomic_write_many({first: "good after", second: "other after"})
    monkeypatch.undo()
    assert snapshot(tmp_path) == before

    assert folder_lock.atomic_write_many({first: "good after",
                                          second: b"other after"}) == [first, second]
    assert (first.read_text(), second.read_text()) == ("good after", "other after")
    assert sorted(os.listdir(tmp_path)) == ["good.ipynb", "other.ipynb"]


# --- notebooks ---------------------------------------------------------------------------------

@pytest.mark.parametrize(("content", "message"), [
    (b"not json", r"is not a notebook \(not valid JSON: Expecting value at line 1, column 1\)"),
    (b"\xff\xfe", r"is not a notebook \(not UTF-8 text"),
    (b"{}", "is not a valid notebook: "),
    (b"[1, 2]", "is not a valid notebook: "),
    (b'{"nbformat": 4, "nbformat_minor": 5, "metadata": {}, "cells": [{"cell_type": "x"}]}',
     "is not a valid notebook: "),
])
def test_a_file_that_is_not_a_notebook_is_one_clear_error(tmp_path, content, message):
    path = tmp_path / "bad.ipynb"
    path.write_bytes(content)
    with pytest.raises(NotebookFileError, match=message) as raised:
        notebook_io.read_notebook(path)
    assert str(raised.value).startswith(str(path))
    assert "\n" not in str(raised.value)


def test_missing_or_folder_notebooks_are_clear_errors(tmp_path):
    with pytest.raises(NotebookFileError, match=r"missing\.ipynb: no such file"):
        notebook_io.read_notebook(tmp_path / "missing.ipynb")
    with pytest.raises(NotebookFileError, match="is a folder, not a notebook"):
        notebook_io.read_notebook(tmp_path)


def test_notebook_bytes_match_nbformat_write(tmp_path):
    notebook = new_notebook(cells=[new_code_cell("print('é')")])
    nbformat.write(notebook, tmp_path / "reference.ipynb")
    (tmp_path / "ours.ipynb").write_bytes(notebook_io.notebook_bytes(notebook))
    assert (tmp_path / "ours.ipynb").read_bytes() == (tmp_path / "reference.ipynb").read_bytes()
    assert notebook_io.read_notebook(tmp_path / "ours.ipynb") == notebook


# --- where an output folder may be ------------------------------------------------------------

def test_an_output_folder_overlapping_the_source_is_refused(tmp_path):
    course = tmp_path / "C"
    (course / "drafts").mkdir(parents=True)
    with pytest.raises(OutputFolderError, match="contains the source folder"):
        check_out_dir(course / "drafts", course)  # the case
    with pytest.raises(OutputFolderError, match="lies inside the source folder"):
        check_out_dir(course, course / "drafts" / "new" / "deeper")
    with pytest.raises(OutputFolderError, match="is the source folder"):
        check_out_dir(course, tmp_path / "C" / ".." / "C")
    check_out_dir(course / "drafts", tmp_path / "elsewhere")  # fine


def test_another_spelling_of_the_source_folder_is_recognised(tmp_path):
    course = tmp_path / "C"
    (course / "drafts").mkdir(parents=True)
    alias = tmp_path / "alias"
    alias.symlink_to(course)
    with pytest.raises(OutputFolderError, match="contains the source folder"):
        check_out_dir(course / "drafts", alias)
    with pytest.raises(OutputFolderError, match="lies inside the source folder"):
        check_out_dir(alias, course / "drafts")
    # Where the file system ignores case, "C/DRAFTS" is "C/drafts": samefile decides.
    upper = tmp_path / "C" / "DRAFTS"
    if upper.exists():
        with pytest.raises(OutputFolderError):
            check_out_dir(course / "drafts", upper)


def test_an_output_path_that_is_a_file_is_refused(tmp_path):
    (tmp_path / "src").mkdir()
    (tmp_path / "out").write_text("a file")
    with pytest.raises(OutputFolderError, match="is a file; give a folder"):
        check_out_dir(tmp_path / "src", tmp_path / "out")
    with pytest.raises(OutputFolderError, match="is a file; give a folder"):
        write_output_folder(tmp_path / "out", {"a.html": "x"}, tool="t")
    assert (tmp_path / "out").read_text() == "a file"


# --- writing an output folder ------------------------------------------------------------------

def test_a_new_folder_is_written_whole_with_its_manifest(tmp_path):
    out = tmp_path / "build" / "handouts"
    written = write_output_folder(out, {"index.html": "i", "prose/a b é.html": b"p"},
                                  tool="handouts")
    assert written == [out / "index.html", out / "prose" / "a b é.html"]
    written_manifest = json.loads((out / MANIFEST_NAME).read_text())
    assert written_manifest["tool"] == "handouts"
    assert written_manifest["files"] == {"index.html": files.sha256(b"i"),
                                         "prose/a b é.html": files.sha256(b"p")}
    assert sorted(os.listdir(out.parent)) == ["handouts"]  # no staging folder left
    assert manifest.read_manifest(out) == manifest.Manifest("handouts",
                                                                written_manifest["files"])


def test_a_rebuild_replaces_and_deletes_only_its_own_unchanged_files(tmp_path):
    out = tmp_path / "out"
    write_output_folder(out, {"01_a.html": "a1", "02_old.html": "old", "index.html": "i1"},
                        tool="handouts")
    (out / "course_home.html").write_text("the instructor's own page")
    (out / "notes").mkdir()
    (out / "notes" / "x.html").write_text("notes")
    write_output_folder(out, {"01_a.html": "a2", "index.html": "i2"}, tool="handouts")
    assert snapshot(out) == {
        MANIFEST_NAME: (out / MANIFEST_NAME).read_bytes(),
        "01_a.html": b"a2", "index.html": b"i2",  # replaced
        "course_home.html": b"the instructor's own page",  # never touched
        "notes": "folder", "notes/x.html": b"notes",
    }  # 02_old.html, written by the first build and no longer, is gone


def test_a_changed_file_of_an_earlier_build_is_kept(tmp_path):
    out = tmp_path / "out"
    write_output_folder(out, {"01.ipynb": "a", "02.ipynb": "b"}, tool="student_edition")
    (out / "01.ipynb").write_text("hand-edited by the instructor")
    (out / "02.ipynb").write_text("hand-edited too")
    before = snapshot(out)
    with pytest.raises(OutputFolderError, match=r"01\.ipynb was changed since student_edition "
                                                r"wrote it"):
        write_output_folder(out, {"01.ipynb": "new"}, tool="student_edition")
    assert snapshot(out) == before
    # Not written any more but changed: kept, and no longer listed as the tool's.
    write_output_folder(out, {"03.ipynb": "c"}, tool="student_edition")
    assert (out / "01.ipynb").read_text() == "hand-edited by the instructor"
    assert (out / "02.ipynb").read_text() == "hand-edited too"
    assert set(manifest.read_manifest(out).files) == {"03.ipynb"}


def test_a_file_in_the_way_that_the_tool_did_not_write_stops_the_build(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "index.html").write_text("the instructor's index")
    (out / "my_grading_notes.ipynb").write_text("grading notes")
    before = snapshot(out)
    with pytest.raises(OutputFolderError) as raised:
        write_output_folder(out, {"index.html": "generated", "01.html": "page"},
                            tool="handouts")
    assert "index.html was not written by handouts" in str(raised.value)
    assert "Nothing was changed" in str(raised.value)
    assert snapshot(out) == before


def test_links_in_the_output_folder_are_refused(tmp_path):
    worked = tmp_path / "worked"
    worked.mkdir()
    (worked / "01.ipynb").write_text("the worked notebook")
    out = tmp_path / "out"
    write_output_folder(out, {"02.ipynb": "x"}, tool="student_edition")
    (out / "01.ipynb").symlink_to(worked / "01.ipynb")
    (out / "sub").symlink_to(worked)
    before, worked_before = snapshot(out), snapshot(worked)
    with pytest.raises(OutputFolderError, match=r"01\.ipynb is a symbolic link"):
        write_output_folder(out, {"01.ipynb": "student"}, tool="student_edition")
    with pytest.raises(OutputFolderError, match="sub/ is a symbolic link"):
        write_output_folder(out, {"sub/01.ipynb": "student"}, tool="student_edition")
    assert snapshot(out) == before
    assert snapshot(worked) == worked_before


def test_another_tools_folder_or_a_broken_manifest_is_refused(tmp_path):
    out = tmp_path / "out"
    write_output_folder(out, {"a.ipynb": "x"}, tool="student_edition")
    with pytest.raises(OutputFolderError, match="holds the output of student_edition"):
        write_output_folder(out, {"a.html": "x"}, tool="handouts")
    (out / MANIFEST_NAME).write_text("{not json")
    with pytest.raises(OutputFolderError, match="is not a manifest the course tools can read"):
        write_output_folder(out, {"a.ipynb": "x"}, tool="student_edition")


@pytest.mark.parametrize("limit", [0, 7])
@pytest.mark.parametrize("exists", [True, False])
def test_a_full_disk_leaves_the_output_folder_as_it_was(tmp_path, monkeypatch, limit, exists):
    out = tmp_path / "out"
    if exists:
        write_output_folder(out, {"01.html": "one", "02.html": "two" * 100},
                            tool="handouts")
        (out / "course_home.html").write_text("mine")
    before = snapshot(tmp_path)
    monkeypatch.setattr(files, "_write_fd", full_disk_after(limit))
    with pytest.raises(OutputWriteError, match=r"No space left on device.*left as it was"):
        write_output_folder(out, {"01.html": "ONE" * 100, "03.html": "three"},
                            tool="handouts")
    assert snapshot(tmp_path) == before


def test_a_failure_while_moving_into_place_is_undone(tmp_path, monkeypatch):
    out = tmp_path / "out"
    write_output_folder(out, {"01.html": "one", "02.html": "two", "old.html": "old"},
                        tool="handouts")
    before = snapshot(tmp_path)
    real_link = os.link
    calls = []

    def link(source, target, *args, **kwargs):  # a new file is linked into place
        calls.append(target)
        if Path(target) == out / MANIFEST_NAME:  # the last move of the build
            raise OSError(errno.EIO, "Input/output error", str(target))
        return real_link(source, target, *args, **kwargs)

    monkeypatch.setattr(os, "link", link)
    with pytest.raises(OutputWriteError, match="Input/output error"):
        write_output_folder(out, {"01.html": "ONE", "02.html": "TWO", "new/03.html": "3"},
                            tool="handouts")
    monkeypatch.undo()
    assert len(calls) > 3  # the pages had been moved into place before the failure
    assert snapshot(tmp_path) == before


def test_a_read_only_output_folder_is_one_clear_error(tmp_path, monkeypatch):
    out = tmp_path / "out"
    write_output_folder(out, {"01.html": "one"}, tool="handouts")
    before = snapshot(tmp_path)
    real_mkdir = os.mkdir

    def read_only(path, *args, **kwargs):  # the first thing a build creates in out
        if Path(path).parent == out:
            raise OSError(errno.EROFS, "Read-only file system", str(out))
        return real_mkdir(path, *args, **kwargs)

    monkeypatch.setattr(os, "mkdir", read_only)
    with pytest.raises(OutputWriteError, match=f"cannot write into {out}: Read-only file system"):
        write_output_folder(out, {"01.html": "ONE"}, tool="handouts")
    assert snapshot(tmp_path) == before


@pytest.mark.skipif(IS_ROOT, reason="root writes into a chmod 555 folder anyway; the "
                    "simulated read-only folder above covers root")
def test_a_really_read_only_output_folder(tmp_path):
    out = tmp_path / "out"
    write_output_folder(out, {"01.html": "one"}, tool="handouts")
    before = snapshot(tmp_path)
    out.chmod(0o555)
    try:
        with pytest.raises(OutputWriteError, match="Permission denied"):
            write_output_folder(out, {"01.html": "ONE"}, tool="handouts")
    finally:
        out.chmod(0o755)
    assert snapshot(tmp_path) == before


def test_output_names_must_stay_inside_the_folder(tmp_path):
    for name in ["../escape.html", "/abs.html", "a/../../b", ".lqe-build-x/a", "./a.html"]:
        with pytest.raises(ValueError, match="plain relative paths"):
            write_output_folder(tmp_path / "out", {name: "x"}, tool="t")
    assert not (tmp_path / "out").exists()


# --- command lines -----------------------------------------------------------------------------

def _parser() -> argparse.ArgumentParser:
    parser = command_line.CommandLineParser(prog="tool")
    parser.add_argument("--n", type=int, default=0)
    return parser


def _raising(error: BaseException):
    def command(args: argparse.Namespace) -> int:
        raise error
    return command


@pytest.mark.parametrize(("error", "line"), [
    (OSError(errno.ENOSPC, "No space left on device", "out/a.html"),
     "error: out/a.html: No space left on device"),
    (PermissionError(errno.EACCES, "Permission denied", "out"), "error: out: Permission denied"),
    (FileNotFoundError(errno.ENOENT, "No such file or directory", "x.ipynb"),
     "error: x.ipynb: No such file or directory"),
    (ValueError("sigma must be > 0, got -1"), "error: sigma must be > 0, got -1"),
    (OutputFolderError("refused"), "error: refused"),
    (RuntimeError("Kernel died"), "error: RuntimeError: Kernel died"),
    (KeyError("x"), "error: KeyError: 'x'"),
    (ValueError("first line\n  Traceback\x1b[0;31m more"),
     "error: first line (--verbose shows the rest)"),
])
def test_every_failure_is_one_error_line_and_status_1(capsys, error, line):
    assert command_line.run_command(_parser(), _raising(error), []) == 1
    captured = capsys.readouterr()
    assert captured.err == line + "\n"
    assert captured.out == ""


def test_verbose_adds_the_traceback(capsys):
    assert command_line.run_command(_parser(), _raising(RuntimeError("boom\nline 2")),
                             ["--verbose"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("Traceback (most recent call last):")
    assert "line 2" in err
    assert err.splitlines()[-1] == "error: RuntimeError: boom (--verbose shows the rest)"


def test_usage_errors_warnings_and_interrupts(capsys):
    with pytest.raises(SystemExit) as raised:
        command_line.run_command(_parser(), lambda args: 0, ["--n", "many"])
    assert raised.value.code == 1
    assert capsys.readouterr().err == ("error: argument --n: invalid int value: 'many'; "
                                       "see tool --help\n")

    def warns(args):
        import warnings
        warnings.warn("careful\nsecond line", UserWarning, stacklevel=1)
        return None

    assert command_line.run_command(_parser(), warns, []) == 0
    assert capsys.readouterr().err == "warning: careful\n"
    assert command_line.run_command(_parser(), _raising(KeyboardInterrupt()), []) == 130
    assert capsys.readouterr().err == "error: interrupted\n"
    assert command_line.run_command(_parser(), lambda args: None, ["--n", "2"]) == 0
