"""``make student-pack``: one zip a student unpacks and uses with ``make lab``.

The pack is built once per test run from this course folder (the real notebooks, package
and Makefile) and unpacked into a temporary folder (``student_pack``, tests/artefacts.py).
Its contents are checked; its Makefile is compared with the course's by ``make -n`` (dry
runs: nothing is installed, and nothing of how this run's ``make`` was called reaches them:
tests/make_env.py); and the pytest command of its ``make test`` is run with the current
interpreter (no new virtualenv) in a copy of the pack: every test of the pack is collected
against the pack's own package, and the structure tests of the student notebooks and a
sample of the unit tests are run. The unit tests in the pack are copies of this folder's,
which the course's own run executes in full.
"""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
import zipfile
from pathlib import Path

import nbformat
import pytest
from artefacts import StudentPack
from make_env import make_environment
from once_per_run import writable_copy

from lqe_helpers.authoring import student_edition as se
from lqe_helpers.authoring import student_pack as sp
from lqe_helpers.authoring import task_cells as tc
from lqe_helpers.authoring.errors import OutputFolderError

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
#: Unit tests run inside the pack besides the structure tests (the rest are collected).
SAMPLE_UNIT_TESTS = ("student_code/test_student_code", "test_validation")


@pytest.fixture
def pack(student_pack: StudentPack) -> tuple[Path, Path]:
    """(the zip, the folder it unpacks to): the run's student pack, read-only."""
    return student_pack.archive, student_pack.folder


def names(archive: Path) -> list[str]:
    with zipfile.ZipFile(archive) as opened:
        return opened.namelist()


def dry_run(folder: Path, target: str, **variables: str) -> list[str]:
    """The commands ``make -n -B target`` would run in ``folder`` (nothing is executed)."""
    settings = [f"{name}={value}" for name, value in variables.items()]
    result = subprocess.run(["make", "-n", "-B", "-C", str(folder), "--no-print-directory",
                             target, *settings], capture_output=True, text=True, check=True,
                            env=make_environment())
    return result.stdout.splitlines()


# ---------------------------------------------------------------- the Makefile

COURSE_MAKEFILE = """\
# Header.

VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: lab test lint clean

$(BIN)/python:
\tpython3 -m venv $(VENV)

$(STAMP): pyproject.toml | $(BIN)/python
\t$(BIN)/python -m pip install -e '.[test]'

lab: $(STAMP)
\t$(BIN)/jupyter lab notebooks/

lint: $(STAMP)
\t$(BIN)/ruff check notebooks

# Everything.
test: $(STAMP) lint
\t$(BIN)/python -m pytest tests --nbval notebooks

clean:
\trm -rf $(VENV)
"""


def test_pack_makefile_keeps_lab_word_for_word_and_replaces_test():
    made = sp.pack_makefile(COURSE_MAKEFILE)
    kept = COURSE_MAKEFILE.split("lint: $(STAMP)")[0].replace(
        ".PHONY: lab test lint clean", ".PHONY: lab test clean")
    assert made.startswith(kept + sp.PACK_TEST_RULE + "\n\nclean:\n\trm -rf $(VENV)\n")
    assert "nbval" not in made and "ruff" not in made and "# Everything" not in made


@pytest.mark.parametrize(("text", "message"), [
    (COURSE_MAKEFILE.replace("lab: $(STAMP)\n\t$(BIN)/jupyter lab notebooks/\n\n", ""),
     "no rule lab"),
    (COURSE_MAKEFILE.replace("notebooks/\n\nlint:", "notebooks/\nlint:"), "share one paragraph"),
])
def test_pack_makefile_refuses_a_makefile_it_cannot_keep_lab_from(text, message):
    with pytest.raises(ValueError, match=message):
        sp.pack_makefile(text)


#: What no test shipped to students may import or read: the oracle loops, the checks'
#: worked and wrong answers, the instructor's tools, the worked notebooks, the suite's
#: shared builds.
INSTRUCTOR_ONLY = re.compile(r"reference_loops|check_outcomes|lqe_helpers\.(authoring|grading)"
                             r"|from lqe_helpers import authoring|[\"']notebooks[\"']"
                             r"|(?:from|import) (?:artefacts|once_per_run|make_env)\b"
                             r"|[\"']artefacts[\"']")


@pytest.mark.parametrize("name", sp.PACK_TESTS)
def test_every_test_the_pack_ships_exists_and_needs_nothing_of_the_instructor(name):
    text = (ROOT / "tests" / name).read_text("utf-8")
    if name == "conftest.py":  # it loads the artefacts plugin only where that file exists
        text = text.replace('pytest_plugins = ["artefacts"] if (Path(__file__).parent / '
                            '"artefacts.py").is_file() else []', "")
    assert not INSTRUCTOR_ONLY.search(text), INSTRUCTOR_ONLY.search(text)


def test_a_new_test_stays_with_the_instructor_unless_it_is_listed():
    """The pack lists what may ship: a test added to tests/ is left out by default."""
    shipped = set(sp.PACK_TESTS)
    checks_tests = {path.relative_to(ROOT / "tests").as_posix()
                    for path in (ROOT / "tests").rglob("test_checks_*.py")}
    assert checks_tests and checks_tests.isdisjoint(shipped)
    assert {"reference_loops.py", "test_reference.py", "test_smoothing.py",
            "test_science_numbers.py", "check_outcomes.py"}.isdisjoint(shipped)


# ------------------------------------------------------------------ the zip


def test_the_pack_holds_what_a_student_needs_and_nothing_of_the_instructor(pack):
    archive, folder = pack
    assert archive == archive.parent / sp.ZIP_NAME
    listed = names(archive)
    assert listed == sorted(listed)
    assert all(name.startswith(f"{sp.PACK_NAME}/") for name in listed)
    inside = {name.removeprefix(f"{sp.PACK_NAME}/") for name in listed}
    for needed in ("Makefile", "README.md", "pyproject.toml", "constraints.txt",
                   sp.MARKER_NAME, "lqe_helpers/__init__.py", "lqe_helpers/checks/__init__.py",
                   "lqe_helpers/explorers/__init__.py", "tests/conftest.py",
                   f"tests/{sp.STRUCTURE_TEST}", f"tests/{sp.CONVENTIONS_NAME}"):
        assert needed in inside, needed
    assert not [name for name in inside if name.startswith(("lqe_helpers/authoring",
                                                            "lqe_helpers/grading"))]
    assert not [name for name in inside if "__pycache__" in name or name.endswith(".pyc")]
    assert not [name for name in inside if "marking" in name]
    assert {name for name in inside if name.startswith("tests/")} == {
        f"tests/{name}" for name in (*sp.PACK_TESTS, sp.STRUCTURE_TEST, sp.CONVENTIONS_NAME)}
    assert not [name for name in inside if "my_functions" in name]
    assert (folder / "pyproject.toml").read_bytes() == (ROOT / "pyproject.toml").read_bytes()
    assert (folder / "README.md").read_bytes() == (sp.PACK_FILES / sp.STUDENT_README).read_bytes()


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_the_notebooks_are_the_student_edition(pack, path):
    _, folder = pack
    packed = (folder / "notebooks" / path.name).read_text("utf-8")
    assert packed == se.student_edition(nbformat.read(path, as_version=4), path.stem)
    assert not any(tc.SOLUTION_TAG in cell.metadata.get("tags", []) or cell.get("outputs")
                   for cell in nbformat.reads(packed, as_version=4).cells)


@pytest.mark.slow
def test_the_zip_is_the_same_every_time_and_replaced_safely(pack, tmp_path):
    archive, _ = pack
    again = sp.build_student_pack(ROOT, tmp_path / "out")
    assert again.read_bytes() == archive.read_bytes()
    assert sp.build_student_pack(ROOT, tmp_path / "out") == again  # its own file: replaced
    foreign = tmp_path / "mine" / sp.ZIP_NAME
    foreign.parent.mkdir()
    foreign.write_bytes(b"an instructor's own zip")
    with pytest.raises(OutputFolderError, match="not written by student_pack"):
        sp.build_student_pack(ROOT, foreign.parent)
    assert foreign.read_bytes() == b"an instructor's own zip"


def test_command_line(tmp_path, capsys):
    assert sp.main(["--root", str(tmp_path), "--out", str(tmp_path / "out")]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("error: root must be the course folder; ")
    assert len(captured.err.splitlines()) == 1


# ------------------------------------------------------------- make, in the pack


def test_make_lab_is_the_courses_and_make_test_runs_no_notebook(pack):
    _, folder = pack
    stamp = ".venv/.installed"  # the Makefiles' $(STAMP): the install step
    assert dry_run(folder, "lab") == dry_run(ROOT, "lab")
    assert dry_run(folder, stamp) == dry_run(ROOT, stamp)
    test = dry_run(folder, "test")
    assert test[:-1] == dry_run(folder, stamp)  # the same install, then pytest only
    assert test[-1].split()[1:] == ["-m", "pytest", "tests"]
    assert (folder / sp.MARKER_NAME).read_text().count("make lab") == 1


def test_the_packs_make_is_not_the_callers(pack, monkeypatch):
    """The issue's case: ``make test PYTEST_ARGS=--durations=60`` failed the test above.

    Make exports a variable given on its command line to every recipe and passes it on to
    every make below it through MAKEFLAGS: a dry run of the pack's ``make test`` printed
    the caller's options.
    """
    _, folder = pack
    for name, value in {"MAKEFLAGS": r" -- PYTEST_ARGS=--durations=60\ -x", "MAKELEVEL": "1",
                        "MAKEOVERRIDES": "${-*-command-variables-*-}",
                        "PYTEST_ARGS": "--durations=60 -x"}.items():
        monkeypatch.setenv(name, value)
    assert dry_run(folder, "test")[-1].split()[1:] == ["-m", "pytest", "tests"]


@pytest.mark.slow
def test_the_packs_structure_tests_can_fail(pack, tmp_path):
    """A notebook with a worked solution left in, and a core task without its check."""
    _, folder = pack
    copy = writable_copy(folder, tmp_path / sp.PACK_NAME)
    conventions = json.loads((copy / "tests" / sp.CONVENTIONS_NAME).read_text("utf-8"))
    [name, *_] = conventions["checked_notebooks"] or pytest.fail("no question notebook")
    path = copy / "notebooks" / name
    notebook = nbformat.read(path, as_version=4)
    first_task = next(i for i, cell in enumerate(notebook.cells)
                      if tc.TASK_TAG in cell.metadata.get("tags", []))
    notebook.cells[first_task].metadata["tags"] = ["solution"]
    kept = [cell for cell in notebook.cells if tc.CHECK_CALL not in cell.source]
    notebook.cells = kept
    nbformat.write(notebook, path)
    result = subprocess.run([sys.executable, "-m", "pytest", f"tests/{sp.STRUCTURE_TEST}",
                             "-q", "-p", "no:cacheprovider"], cwd=copy, capture_output=True,
                            text=True, timeout=600, env=make_environment())
    assert result.returncode == 1, result.stdout[-3000:]
    assert f"{name}, cell {first_task}: tags ['solution']" in result.stdout
    assert "no check follows this core task" in result.stdout


@pytest.mark.slow
def test_the_packs_make_test_passes_with_this_interpreter(pack, tmp_path):
    """Its pytest command, run as ``make test`` runs it, with the current Python."""
    _, packed = pack
    folder = writable_copy(packed, tmp_path / sp.PACK_NAME)  # pytest writes caches there
    [command] = [line for line in dry_run(folder, "test") if " -m pytest" in line]
    argv = [sys.executable, *shlex.split(command)[1:], "-p", "no:cacheprovider", "-q"]
    sample = " or ".join([sp.STRUCTURE_TEST.removesuffix(".py"),
                          *(name.rsplit("/", 1)[-1] for name in SAMPLE_UNIT_TESTS)])
    # One run: pytest collects every test (an error in any stops the run), then runs the
    # sample; -rA lists each test that passed.
    result = subprocess.run([*argv, "-k", sample, "-rA"], cwd=folder, capture_output=True,
                            text=True, timeout=600, env=make_environment())
    assert result.returncode == 0, result.stdout[-5000:] + result.stderr[-3000:]
    last = result.stdout.splitlines()[-1]
    assert " passed" in last and " deselected" in last, last
    assert f"PASSED tests/{sp.STRUCTURE_TEST}::" in result.stdout, result.stdout[-3000:]
    for name in SAMPLE_UNIT_TESTS:
        assert f"PASSED tests/{name}.py::" in result.stdout, name
