"""One line, naming the thing: the tools' messages under attack.

Issue 19: Ctrl-C while a tool was still importing printed a traceback (issue 27: SIGTERM
then printed nothing); a non-UTF-8 file in the student pack, a deeply nested notebook and
``File too large`` (``ulimit -f``) named no file; one error line repeated the same
sentence 171 times (the handouts build, when its folder holds a MathJax copy it did not
write: one sentence per MathJax file).
"""

from __future__ import annotations

import os
import resource
import shutil
import signal
import subprocess
import textwrap
import time

import pytest
from nbformat.v4 import new_code_cell, new_markdown_cell, new_output
from tools_helpers import (
    make_course,
    python_command,
    run_tool,
    snapshot,
    tools_environment,
    worked_notebook,
    write_notebook,
)

from lqe_helpers.authoring import handout_pages, handouts, student_edition, student_pack
from lqe_helpers.authoring.errors import OutputFolderError, error_line
from lqe_helpers.authoring.notebook_io import read_notebook
from lqe_helpers.authoring.output_folder import plan_output_folder

TOOLS = ["clean", "notebook_runner", "handouts", "student_edition", "student_pack",
         "marking_guide"]

#: Installed as sitecustomize: the first import of a module named in SLOW_IMPORTS (one
#: each tool makes after its own first line) takes 60 s, after writing IMPORTING.
SLOW_IMPORT = textwrap.dedent("""
    import os, sys, time
    class Slow:
        def find_spec(self, name, path=None, target=None):
            if name in ("nbformat", "lqe_helpers.authoring.manifest"):
                sys.meta_path.remove(self)
                open(os.environ["IMPORTING"], "w").close()
                time.sleep(60)
            return None
    sys.meta_path.insert(0, Slow())
""")


@pytest.mark.parametrize(("how", "status", "said"), [
    (signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "stopped by SIGTERM")])
@pytest.mark.parametrize("tool", TOOLS)
def test_a_signal_while_a_tool_is_importing_is_one_line(tmp_path, tool, how, status, said):
    hooks = tmp_path / "hooks"
    hooks.mkdir()
    (hooks / "sitecustomize.py").write_text(SLOW_IMPORT)
    importing = tmp_path / "importing"
    environment = tools_environment()
    environment["PYTHONPATH"] = f"{hooks}:{environment['PYTHONPATH']}"
    environment["IMPORTING"] = str(importing)
    process = subprocess.Popen(python_command("-m", f"lqe_helpers.authoring.{tool}", "--help"),
                               cwd=tmp_path, env=environment, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    end = time.monotonic() + 60
    while not importing.exists():
        assert time.monotonic() < end and process.poll() is None, process.communicate()
        time.sleep(0.05)
    process.send_signal(how)
    out, err = process.communicate(timeout=60)
    assert err == f"error: {said} while starting; nothing was done\n", err
    assert process.returncode == status
    assert out == ""


# --- files named --------------------------------------------------------------------------------

@pytest.mark.parametrize("where", ["tests/test_validation.py", "Makefile"])
def test_a_non_utf8_file_in_the_pack_is_named(tmp_path, where):
    course = make_course(tmp_path / "course")
    path = course / where
    text = path.read_bytes() if path.exists() else b"def test_nothing():\n    pass\n"
    path.write_bytes(text + "# café\n".encode("latin-1"))
    with pytest.raises(ValueError) as raised:
        student_pack.build_student_pack(course, tmp_path / "out")
    assert error_line(raised.value).startswith(f"{path} is not UTF-8 text (invalid")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("folder", ["lqe_helpers", "notebooks"])
def test_a_file_name_that_is_not_utf8_is_named_escaped(tmp_path, capsys, folder):
    """Issue 27: the pack said only "'utf-8' codec can't encode character '\\udce9'"."""
    course = make_course(tmp_path / "course")
    name = os.fsdecode(b"caf\xe9.py" if folder == "lqe_helpers" else b"02_caf\xe9.ipynb")
    shutil.copy(course / "notebooks" / "01_first.ipynb", course / folder / name)
    assert student_pack.main(["--root", str(course), "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert err == (f"error: '{course / folder}/caf\\udce9.py': its name is not UTF-8; the "
                   f"student pack (a zip) names its files in UTF-8: rename it\n"
                   if folder == "lqe_helpers" else
                   f"error: '{course / folder}/02_caf\\udce9.ipynb': its name is not UTF-8; "
                   f"the student pack (a zip) names its files in UTF-8: rename it\n"), err
    assert err.isascii()
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_a_deeply_nested_notebook_is_named_by_every_tool(tmp_path):
    source = tmp_path / "notebooks"
    deep = source / "01_deep.ipynb"
    deep.parent.mkdir()
    deep.write_text('{"nbformat": 4, "nbformat_minor": 5, "cells": [], "metadata": {"a": '
                    + "[" * 2000 + "]" * 2000 + "}}")
    for tool in ("student_edition", "marking_guide", "handouts"):
        result = run_tool(tool, "--source", str(source), "--out", str(tmp_path / tool))
        assert result.returncode == 1
        [line] = result.stderr.splitlines()
        assert line.startswith(f"error: {deep} is not a valid notebook: its JSON is nested"), \
            (tool, line)


def limit_file_size(limit: int):
    def limited() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return limited


@pytest.mark.parametrize("exists", [False, True])
@pytest.mark.slow
def test_file_too_large_names_the_file(tmp_path, exists):
    source = tmp_path / "notebooks"
    big = [new_markdown_cell("A long introduction. " * 5000)]  # 100 kB
    write_notebook(source / "01_big.ipynb", worked_notebook(extra=big))
    out = tmp_path / "student"
    if exists:
        write_notebook(source / "01_big.ipynb", worked_notebook())
        student_edition.build_student_edition(source, out)
        write_notebook(source / "01_big.ipynb", worked_notebook(extra=big))
    before = snapshot(tmp_path)
    result = subprocess.run(
        python_command("-m", "lqe_helpers.authoring.student_edition", "--source", str(source),
                       "--out", str(out)),
        env=tools_environment(), capture_output=True, text=True, timeout=120,
        preexec_fn=limit_file_size(60_000), check=False)
    assert result.returncode == 1
    assert result.stderr == (f"error: cannot write into {out}: File too large "
                             f"({out / '01_big.ipynb'}); it was left as it was\n")
    assert snapshot(tmp_path) == before


# --- each fault once ---------------------------------------------------------------------------

def test_a_mathjax_copy_in_the_way_is_one_short_line(tmp_path):
    """The issue's 5,117-character line: 171 times 'mathjax/… was not written by handouts'."""
    out = tmp_path / "handouts"
    mathjax = handout_pages.mathjax_copy()
    for name, data in mathjax.items():
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_bytes(data)
    with pytest.raises(OutputFolderError) as raised:
        plan_output_folder(out, ["index.html", *mathjax], tool="handouts")
    line = error_line(raised.value)
    assert len(line) < 400, line
    assert line.count("was not written") + line.count("were not written") == 1
    assert f"and {len(mathjax) - 3} more were not written by handouts" in line


def test_many_cells_with_an_error_are_one_short_line(tmp_path, monkeypatch):
    notebook = worked_notebook()
    error = new_output("error", ename="NameError", evalue="name 'np' is not defined",
                       traceback=["NameError"])
    notebook.cells = [new_code_cell(f"x{number}", outputs=[error]) for number in range(120)]
    source = tmp_path / "notebooks"
    write_notebook(source / "01_errors.ipynb", notebook)
    monkeypatch.setattr(handouts, "execute_notebook",
                        lambda path, timeout=None, allow_errors=False: read_notebook(path))
    with pytest.raises(handouts.HandoutBuildError) as raised:
        handouts.build_handouts(source, tmp_path / "out", mathjax_url="")
    line = error_line(raised.value)
    assert len(line) < 400, line
    assert "and 117 more" in line
