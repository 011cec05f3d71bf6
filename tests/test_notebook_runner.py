"""The notebook runner's command line: every path checked first, errors reported in one way."""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

import nbformat
from nbformat.v4 import new_code_cell, new_notebook

from lqe_helpers.authoring import notebook_runner

KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}


def write(path: Path, *sources: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(new_notebook(cells=[new_code_cell(source) for source in sources],
                                metadata={"kernelspec": KERNELSPEC}), path)
    return path


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


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


def test_a_cell_that_raises_is_reported_and_not_written(tmp_path, capsys):
    good = write(tmp_path / "01_good.ipynb", "print('ran')")
    broken = write(tmp_path / "02_broken.ipynb", "x = 1", "x / 0")
    before = digest(broken)
    assert notebook_runner.main([str(good), str(broken)]) == 1
    captured = capsys.readouterr()
    assert captured.out.split("\n")[:2] == [f"executing {good}", f"executing {broken}"]
    assert captured.err.startswith(f"error: {broken}: ")
    assert "x / 0" in captured.err
    assert "ZeroDivisionError" in captured.err
    assert "\x1b[" not in captured.err  # no terminal colour codes
    assert digest(broken) == before
    ran = nbformat.read(good, as_version=4)
    assert ran.cells[0].outputs[0]["text"] == "ran\n"


def test_allow_errors_keeps_the_error_in_the_outputs(tmp_path):
    path = write(tmp_path / "errors.ipynb", "1 / 0", "print('still runs')")
    notebook = notebook_runner.execute_notebook(path, allow_errors=True)
    [error] = notebook.cells[0].outputs
    assert error["output_type"] == "error"
    assert error["ename"] == "ZeroDivisionError"
    traceback = re.sub(r"\x1b\[[0-9;]*m", "", "\n".join(error["traceback"]))
    assert "----> 1 1 / 0" in traceback
    assert notebook.cells[1].outputs[0]["text"] == "still runs\n"
