"""The notebook runner: every notebook runs before any is saved; any failure changes no file.

Each failure the issue names is provoked for real (a cell that raises, a kernel that dies,
a cell past its time limit, a full disk while saving, a file that is not a notebook) and
each test checks that every notebook is byte-identical afterwards and that the command
printed exactly one ``error:`` line.
"""

from __future__ import annotations

import errno
import hashlib
import os
import re
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_notebook

from lqe_helpers.authoring import execution, files, notebook_runner

KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}


def write(path: Path, *sources: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(new_notebook(cells=[new_code_cell(source) for source in sources],
                                metadata={"kernelspec": KERNELSPEC}), path)
    return path


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def digests(folder: Path) -> dict[str, str]:
    return {path.name: digest(path) for path in sorted(folder.iterdir())}


def one_error_line(err: str) -> str:
    """The single ``error:`` line of a failed command's stderr (fails if there is more)."""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), err
    return lines[0]


def assert_line(line: str, expected: str) -> None:
    """``line`` is ``expected``, perhaps followed by the note that --verbose shows more.

    (The note comes when the kernel process printed something of its own, which
    depends on the ipykernel version.)
    """
    assert re.fullmatch(re.escape(expected) + r"( \(--verbose shows the rest\))?", line), line


def test_help_states_the_default_time_limit(capsys):
    with pytest.raises(SystemExit) as raised:
        notebook_runner.main(["--help"])
    assert raised.value.code == 0
    help_text = " ".join(capsys.readouterr().out.split())
    assert f"seconds one cell may run before the run stops (default: " \
           f"{notebook_runner.CELL_TIMEOUT})" in help_text
    assert notebook_runner.CELL_TIMEOUT == 300


@pytest.mark.parametrize("value", ["0", "-1", "soon", "inf", "nan"])
def test_a_bad_time_limit_is_one_error_line(tmp_path, capsys, value):
    good = write(tmp_path / "01_good.ipynb", "print('ran')")
    with pytest.raises(SystemExit) as raised:
        notebook_runner.main([str(good), "--timeout", value])
    assert raised.value.code == 1
    assert "must be a number of seconds > 0" in one_error_line(capsys.readouterr().err)


def test_a_bad_path_anywhere_stops_before_any_notebook_runs(tmp_path, capsys):
    good = write(tmp_path / "01_good.ipynb", "print('ran')")
    before = digest(good)
    (tmp_path / "notes.txt").write_text("not a notebook")
    arguments = [str(good), str(tmp_path / "missing.ipynb"), str(tmp_path / "notes.txt")]
    assert notebook_runner.main(arguments) == 1
    captured = capsys.readouterr()
    assert captured.out == ""  # nothing was executed
    assert captured.err == (f"error: notebooks must be existing .ipynb files, got "
                            f"{tmp_path / 'missing.ipynb'}, {tmp_path / 'notes.txt'}\n")
    assert digest(good) == before


@pytest.mark.parametrize(("content", "message"), [
    ("{not json", "is not a notebook (not valid JSON: "),
    ('{"cells": []}', "is not a valid notebook: "),
])
def test_a_file_that_is_not_a_notebook_stops_before_any_runs(tmp_path, capsys, content, message):
    good = write(tmp_path / "01_good.ipynb", "print('ran')")
    bad = tmp_path / "02_bad.ipynb"
    bad.write_text(content)
    before = digests(tmp_path)
    assert notebook_runner.main([str(good), str(bad)]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert one_error_line(captured.err).startswith(f"error: {bad} {message}")
    assert digests(tmp_path) == before


def test_a_linked_notebook_is_refused(tmp_path, capsys):
    good = write(tmp_path / "worked" / "01_good.ipynb", "print('ran')")
    link = tmp_path / "01_link.ipynb"
    link.symlink_to(good)
    before = digest(good)
    assert notebook_runner.main([str(link)]) == 1
    assert "is a symbolic link" in one_error_line(capsys.readouterr().err)
    assert link.is_symlink()
    assert digest(good) == before


@pytest.mark.slow
@pytest.mark.kernel
def test_a_good_notebook_is_not_rewritten_before_a_bad_one_fails(tmp_path, capsys):
    good = write(tmp_path / "good.ipynb", "print('ran')")
    bad = write(tmp_path / "bad.ipynb", "x = 1", "x / 0")
    before = digests(tmp_path)
    assert notebook_runner.main([str(good), str(bad)]) == 1
    captured = capsys.readouterr()
    assert captured.out.splitlines() == [f"executing {good}", f"executing {bad}"]
    assert one_error_line(captured.err) == (
        f"error: {bad}: cell 1 (x / 0) raised ZeroDivisionError: division by zero "
        f"(--verbose shows the rest)")
    assert digests(tmp_path) == before  # the good one was executed but not saved


@pytest.mark.slow
@pytest.mark.kernel
def test_verbose_shows_the_cell_traceback(tmp_path, capsys):
    bad = write(tmp_path / "bad.ipynb", "x = 1", "x / 0")
    assert notebook_runner.main([str(bad), "--verbose"]) == 1
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err
    assert "----> 1 x / 0" in err
    assert "\x1b[" not in err  # no terminal colour codes
    assert err.splitlines()[-1].startswith(f"error: {bad}: cell 1 (x / 0) raised")


@pytest.mark.slow
@pytest.mark.kernel
def test_a_kernel_that_dies_is_one_error_line(tmp_path, capsys):
    good = write(tmp_path / "good.ipynb", "print('ran')")
    dying = write(tmp_path / "dying.ipynb", "print('start')", "import os\nos._exit(1)")
    before = digests(tmp_path)
    assert notebook_runner.main([str(good), str(dying)]) == 1
    assert_line(one_error_line(capsys.readouterr().err),
                f"error: {dying}: the kernel died while running cell 1 (import os)")
    assert digests(tmp_path) == before


@pytest.mark.slow
@pytest.mark.kernel
def test_a_cell_past_its_time_limit_is_one_error_line(tmp_path, capsys):
    good = write(tmp_path / "good.ipynb", "print('ran')")
    endless = write(tmp_path / "endless.ipynb", "import time", "while True:\n    time.sleep(0.1)")
    before = digests(tmp_path)
    assert notebook_runner.main([str(good), str(endless), "--timeout", "2"]) == 1
    assert_line(one_error_line(capsys.readouterr().err),
                f"error: {endless}: cell 1 (while True:) ran longer than the time limit of 2 s "
                f"per cell (--timeout)")
    assert digests(tmp_path) == before


@pytest.mark.slow
@pytest.mark.kernel
def test_a_full_disk_while_saving_leaves_every_notebook_as_it_was(tmp_path, capsys,
                                                                   monkeypatch):
    first = write(tmp_path / "01.ipynb", "print('one')")
    second = write(tmp_path / "02.ipynb", "print('two')")
    before = digests(tmp_path)
    real = files._write_fd
    calls = []

    def full_disk(fd: int, data: bytes) -> None:
        calls.append(len(data))
        if len(calls) == 2:  # the second notebook's temporary file: half, then ENOSPC
            real(fd, data[:len(data) // 2])
            raise OSError(errno.ENOSPC, "No space left on device")
        real(fd, data)

    monkeypatch.setattr(files, "_write_fd", full_disk)
    assert notebook_runner.main([str(first), str(second)]) == 1
    line = one_error_line(capsys.readouterr().err)
    assert line.endswith("No space left on device")
    assert len(calls) == 2
    assert digests(tmp_path) == before  # no notebook truncated, no temporary file left


@pytest.mark.slow
@pytest.mark.kernel
def test_notebooks_are_saved_together_and_unchanged_ones_not_rewritten(tmp_path, capsys):
    first = write(tmp_path / "01.ipynb", "print('one')")
    second = write(tmp_path / "02.ipynb", "print('two')")
    first.chmod(0o640)
    assert notebook_runner.main([str(first), str(second), str(tmp_path / "." / "01.ipynb")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out == [f"executing {first}", f"executing {second}", f"saved {first}",
                   f"saved {second}"]  # the same file named twice runs once
    assert nbformat.read(first, as_version=4).cells[0].outputs[0]["text"] == "one\n"
    assert (first.stat().st_mode & 0o777) == 0o640
    assert sorted(os.listdir(tmp_path)) == ["01.ipynb", "02.ipynb"]
    saved = digests(tmp_path)
    mtime = first.stat().st_mtime_ns
    assert notebook_runner.main([str(first)]) == 0
    assert capsys.readouterr().out.splitlines() == [
        f"executing {first}", f"unchanged {first} (not rewritten)"]
    assert digests(tmp_path) == saved
    assert first.stat().st_mtime_ns == mtime


@pytest.mark.slow
@pytest.mark.kernel
def test_allow_errors_keeps_the_error_in_the_outputs(tmp_path):
    path = write(tmp_path / "errors.ipynb", "1 / 0", "print('still runs')")
    notebook = execution.execute_notebook(path, allow_errors=True)
    [error] = notebook.cells[0].outputs
    assert error["output_type"] == "error"
    assert error["ename"] == "ZeroDivisionError"
    traceback = re.sub(r"\x1b\[[0-9;]*m", "", "\n".join(error["traceback"]))
    assert "----> 1 1 / 0" in traceback
    assert notebook.cells[1].outputs[0]["text"] == "still runs\n"


@pytest.mark.kernel
def test_a_stream_is_one_output_however_the_kernel_chunked_it(tmp_path):
    source = ("import sys, time\n"
              "print('first', flush=True)\n"
              "time.sleep(0.3)\n"
              "print('second', flush=True)\n"
              "sys.stderr.write('warning\\n')\n"
              "print('third')")
    notebook = execution.execute_notebook(write(tmp_path / "chunks.ipynb", source))
    streams = {output["name"]: output["text"] for output in notebook.cells[0].outputs}
    assert len(notebook.cells[0].outputs) == 2, notebook.cells[0].outputs
    assert streams == {"stdout": "first\nsecond\nthird\n", "stderr": "warning\n"}


@pytest.mark.parametrize("timeout", [0, -1.0, True, "5"])
def test_execute_notebook_refuses_a_bad_timeout(tmp_path, timeout):
    path = write(tmp_path / "a.ipynb", "1")
    with pytest.raises(ValueError, match=r"timeout must be a number of seconds > 0, got "):
        execution.execute_notebook(path, timeout=timeout)
