"""Grading a class, end to end: real nbgrader and the grade tool on simulated submissions.

Once per module (about a minute): ``make nbgrader``'s course folder for notebook 01 (the
core path only: Going further carries no points), ``nbgrader generate_assignment``,
``autograde`` of the submissions of ``grading_submissions`` (a small per-cell time limit for
the endless loop), ``generate_feedback`` and ``export``; then the grade tool on the same
submissions plus broken files. Every test reads those results.
"""

from __future__ import annotations

import csv
import html
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import nbformat
import pytest
from grading_submissions import BROKEN, NAME, SUBMISSIONS, WORKED, edition, filled, submission

from lqe_helpers.authoring import grade, nbgrader_course

pytestmark = [pytest.mark.slow, pytest.mark.kernel]

#: Seconds a cell may run here: well above 01's slowest worked cell, short for the loop.
CELL_TIMEOUT = 15
NBGRADER_STUDENTS = tuple(SUBMISSIONS)
#: Given to the grade tool only: the worked notebook itself, the student pack's edition filled.
EXTRA = {"worked": lambda: WORKED.read_text(encoding="utf-8"),
         "pack": lambda: nbformat.writes(filled(edition()))}
PASSES = {**{student: expected for student, (_, expected) in SUBMISSIONS.items()},
          **{key: {"check_filter": True, "check_vision_trial": True} for key in EXTRA}}


def nbgrader(course: Path, *args: str) -> subprocess.CompletedProcess:
    """Run the nbgrader command line in ``course`` (its alembic needs the venv's bin)."""
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    done = subprocess.run([sys.executable, "-m", "nbgrader", *args], cwd=course, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return done


@pytest.fixture(scope="module")
def graded(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """Both routes run once on the same submissions; their outputs and timings."""
    base = tmp_path_factory.mktemp("grading")
    course, plain = base / "course", base / "submissions"
    nbgrader_course.build_course(WORKED.parent, course, ["01"])
    start = time.monotonic()
    nbgrader(course, "generate_assignment", "lqe", "--force")
    release = nbformat.read(course / "release" / "lqe" / NAME, as_version=4)
    for student in SUBMISSIONS:
        (plain / student).mkdir(parents=True)
        (plain / student / NAME).write_text(submission(student, release), encoding="utf-8")
        folder = course / "submitted" / student / "lqe"
        folder.mkdir(parents=True)
        shutil.copy(plain / student / NAME, folder / NAME)
    for student, make in EXTRA.items():
        (plain / student).mkdir()
        (plain / student / NAME).write_text(make(), encoding="utf-8")
    for student, data in BROKEN.items():
        (plain / student).mkdir()
        (plain / student / NAME).write_bytes(data)
    tool_start = time.monotonic()  # the grade tool on one core, nbgrader on the other
    tool = subprocess.Popen(
        [sys.executable, "-m", "lqe_helpers.authoring.grade", str(plain), "--out",
         str(base / "grades"), "--source", str(WORKED.parent), "--jobs", "1",
         "--cell-timeout", str(CELL_TIMEOUT), "--notebook-timeout", "300"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        autograde = nbgrader(course, "autograde", "lqe", f"--Execute.timeout={CELL_TIMEOUT}")
        nbgrader_seconds = time.monotonic() - start
        nbgrader(course, "generate_feedback", "lqe")
        nbgrader(course, "export", "--exporter=lqe_helpers.authoring.nbgrader_export."
                 "QuestionPointsExport", "--to=questions.csv")
        _, stderr = tool.communicate(timeout=900)
    finally:
        tool.kill()
    tool_seconds = time.monotonic() - tool_start
    assert tool.returncode == 0, stderr
    with (base / "grades" / "grades.csv").open(encoding="utf-8") as table:
        tool_rows = {row["student"]: row for row in csv.DictReader(table)}
    with (course / "questions.csv").open(encoding="utf-8") as table:
        export_rows = {row["student"]: row for row in csv.DictReader(table)}
    return {"base": base, "course": course, "plain": plain, "autograde": autograde,
            "nbgrader_seconds": nbgrader_seconds, "tool_seconds": tool_seconds,
            "tool": tool_rows, "export": export_rows, "grades": base / "grades"}


def expected_points(student: str) -> float:
    return sum(4.5 for passed in PASSES[student].values() if passed)


def test_nbgrader_release_holds_the_student_editions_stubs(graded: dict) -> None:
    release = (graded["course"] / "release" / "lqe" / NAME).read_text(encoding="utf-8")
    assert release.count(nbgrader_course.CODE_STUB.replace('"', '\\"')) == 2
    assert "np.linalg.solve" not in release and "BEGIN SOLUTION" not in release


@pytest.mark.parametrize("student", NBGRADER_STUDENTS)
def test_nbgrader_autograde_gives_each_submission_its_points(graded: dict,
                                                             student: str) -> None:
    assert graded["export"][student]["(a) automatic"] == f"{expected_points(student):g}"
    assert graded["export"][student]["(a) by hand"] == ""  # written answers: not yet marked


def test_nbgrader_export_has_one_row_per_student(graded: dict) -> None:
    assert sorted(graded["export"]) == sorted(NBGRADER_STUDENTS)
    assert list(next(iter(graded["export"].values()))) == ["student", "(a) automatic",
                                                          "(a) by hand"]


def test_the_loop_does_not_stop_the_batch(graded: dict) -> None:
    """The loop is interrupted at the cell limit; every submission is graded."""
    autograded = graded["course"] / "autograded" / "loop" / "lqe" / NAME
    assert "CellTimeoutError" in autograded.read_text(encoding="utf-8")
    assert graded["nbgrader_seconds"] < 5 * 60
    print(f"nbgrader generate_assignment + autograde of {len(NBGRADER_STUDENTS)} "
          f"submissions: {graded['nbgrader_seconds']:.0f} s")


def test_nbgrader_feedback_names_causes_and_holds_no_worked_code(graded: dict) -> None:
    feedback = graded["course"] / "feedback"
    wrong = (feedback / "wrong" / "lqe" / "01_vision_only.html").read_text(encoding="utf-8")
    for check in ("check_filter", "check_vision_trial"):  # the causes the grade tool found
        cause = graded["tool"]["wrong"][check].removeprefix("CheckFailed: ")
        assert html.escape(cause[:60], quote=False) in wrong, cause
    for student in NBGRADER_STUDENTS:
        page = (feedback / student / "lqe" / "01_vision_only.html").read_text(encoding="utf-8")
        assert "np.linalg.solve" not in page  # the worked my_filter's own line
        assert "BEGIN SOLUTION" not in page and "BEGIN HIDDEN" not in page
    untouched = (feedback / "untouched" / "lqe" / "01_vision_only.html").read_text("utf-8")
    assert "✓ all right" not in untouched  # saved outputs are not what is graded


@pytest.mark.parametrize("student", list(PASSES))
def test_grade_tool_gives_each_submission_its_points(graded: dict, student: str) -> None:
    row = graded["tool"][student]
    for check, passed in PASSES[student].items():
        assert (row[check] == grade.PASSED) == passed, (check, row[check])
    assert row["automatic points"] == f"{expected_points(student):g}"
    assert (row["question"], row["out of"]) == ("(a)", "9")


def test_grade_tool_and_nbgrader_agree(graded: dict) -> None:
    for student in NBGRADER_STUDENTS:
        assert graded["tool"][student]["automatic points"] == \
            graded["export"][student]["(a) automatic"]


def test_grade_tool_rows_name_one_line_causes(graded: dict) -> None:
    rows = graded["tool"]
    assert rows["wrong"]["check_filter"].startswith("CheckFailed: ")
    assert "\n" not in "".join(rows["wrong"].values())
    assert rows["loop"]["check_vision_trial"].startswith("NameError")
    for broken in BROKEN:
        assert rows[broken]["error"].startswith("not graded: "), rows[broken]
        assert rows[broken]["automatic points"] == "0"


def test_grade_tool_feedback_pages(graded: dict) -> None:
    pages = graded["grades"] / "feedback"
    assert sorted(path.stem for path in pages.iterdir()) == sorted([*PASSES, *BROKEN])
    wrong = (pages / "wrong.html").read_text(encoding="utf-8")
    assert "CheckFailed" in wrong and "0 of 9 automatic points" in wrong
    for page in pages.iterdir():
        text = page.read_text(encoding="utf-8")
        assert "np.linalg.solve" not in text and "def my_filter" not in text


def test_grade_tool_writes_only_under_out(graded: dict) -> None:
    assert sorted(path.name for path in graded["base"].iterdir()) == [
        "course", "grades", "submissions"]
    assert not any(path.name.startswith(".work-") for path in graded["grades"].rglob("*"))
    assert not list(graded["plain"].rglob("my_functions"))


def test_grade_tool_rerun_skips_graded_and_regrades_changed(graded: dict,
                                                           tmp_path: Path) -> None:
    """A second run (as after a kill) grades only what has no result or changed."""
    plain, out = tmp_path / "submissions", tmp_path / "grades"
    shutil.copytree(graded["plain"], plain)
    shutil.copytree(graded["grades"], out)
    (plain / "untouched" / NAME).write_text("[]", "utf-8")  # changed since: graded again
    (out / "results" / "invalid" / f"{NAME}.json").unlink()  # as if killed before it
    done = subprocess.run(
        [sys.executable, "-m", "lqe_helpers.authoring.grade", str(plain), "--out", str(out),
         "--source", str(WORKED.parent), "--cell-timeout", str(CELL_TIMEOUT)],
        capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert f"skipped {len(PASSES) + len(BROKEN) - 2} submission" in done.stdout
    assert "graded 2 submission" in done.stdout
    with (out / "grades.csv").open(encoding="utf-8") as table:
        rows = {row["student"]: row for row in csv.DictReader(table)}
    assert rows["invalid"]["error"].startswith("not graded: ")
    assert rows["untouched"]["error"].startswith("not graded: ")
    assert rows["filled"]["automatic points"] == "9"  # kept from the first run
    print(f"grade tool, {len(PASSES) + len(BROKEN)} submissions on 1 job: "
          f"{graded['tool_seconds']:.0f} s")


def test_nbgrader_runs_the_explorer_headless(graded: dict) -> None:
    """The explorer cell ran in autograde (no widget frontend) and ended without an error."""
    autograded = nbformat.read(graded["course"] / "autograded" / "filled" / "lqe" / NAME,
                               as_version=4)
    [explorer] = [cell for cell in autograded.cells if "explore_vision(" in cell.source]
    assert explorer.outputs
    assert not [output for output in explorer.outputs if output.output_type == "error"]
