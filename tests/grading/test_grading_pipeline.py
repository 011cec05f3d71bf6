"""Grading a class, end to end: real nbgrader and the grade tool on simulated submissions.

Once per module (about a minute and a half): ``make nbgrader``'s course folder (01–05, the
core path only: Going further carries no points), with the worked ``my_functions/`` that the
instructor's own run of ``source/lqe/`` leaves there, ``nbgrader generate_assignment``,
``autograde`` of the submissions of ``grading_submissions`` (notebook 01; a small per-cell
time limit for the endless loop), of the whole assignment worked (``filled``: 02–05 load the
``my_filter`` its own 01 saves) and of 05 beside the wrong ``my_filter`` (``wrong``, with a
worked ``my_functions/my_filter.py`` that must not be used), ``generate_feedback`` and
``export``; the grade tool on the same submissions plus broken files, on the other core.
Every test reads those results.
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
from grading_submissions import (
    BROKEN,
    NAME,
    SUBMISSIONS,
    WORKED,
    edition,
    filled,
    filled_as,
    submission,
)

from lqe_helpers.grading import grade, nbgrader_course, rules

pytestmark = [pytest.mark.slow, pytest.mark.kernel]

#: Seconds a cell may run here: well above 01's slowest worked cell, short for the loop.
CELL_TIMEOUT = 15
NBGRADER_STUDENTS = tuple(SUBMISSIONS)
#: Given to the grade tool only: the worked notebook itself, the student pack's edition filled.
EXTRA = {"worked": lambda: WORKED.read_text(encoding="utf-8"),
         "pack": lambda: nbformat.writes(filled(edition()))}
PASSES = {**{student: expected for student, (_, expected) in SUBMISSIONS.items()},
          **{key: {"check_filter": True, "check_vision_trial": True} for key in EXTRA}}
#: The assignment's notebooks (make nbgrader's default: 01–05) and the question of each.
ASSIGNMENT = {path.name: rules.question_label(path.name) for path in
              sorted(WORKED.parent.glob("0[1-5]_*.ipynb"))}
#: Later notebooks submitted filled as the worked ones, and their expected automatic points:
#: ``filled`` the whole assignment; ``wrong`` (its my_filter fails 01's check, so 01 saves
#: none) 05, whose one-trial task runs my_filter: its check loses its 6 points.
LATER = {"filled": {"02_initial_covariance.ipynb": 9, "03_fusion.ipynb": 15,
                    "04_noisier_proprioception.ipynb": 9, "05_sensory_delay.ipynb": 18},
         "wrong": {"05_sensory_delay.ipynb": 12}}
#: What ``wrong`` also submits: a worked my_filter.py (stale, or a friend's), not to be used.
SAVED = WORKED.parent / rules.SAVED_FUNCTIONS


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
    nbgrader_course.build_course(WORKED.parent, course)
    # The instructor ran source/lqe/01 (and 05): the worked functions are saved there.
    shutil.copytree(SAVED, course / "source" / "lqe" / SAVED.name)
    start = time.monotonic()
    nbgrader(course, "generate_assignment", "lqe", "--force")
    release = course / "release" / "lqe"
    for student in SUBMISSIONS:
        folder = course / "submitted" / student / "lqe"
        for where in (plain / student, folder):
            where.mkdir(parents=True)
            where.joinpath(NAME).write_text(
                submission(student, nbformat.read(release / NAME, as_version=4)), "utf-8")
            for name in LATER.get(student, {}):
                where.joinpath(name).write_text(nbformat.writes(
                    filled_as(nbformat.read(release / name, as_version=4), name)), "utf-8")
    for where in (plain / "wrong", course / "submitted" / "wrong" / "lqe"):
        (where / SAVED.name).mkdir()
        shutil.copy(SAVED / "my_filter.py", where / SAVED.name)
    for student, make in EXTRA.items():
        (plain / student).mkdir()
        (plain / student / NAME).write_text(make(), encoding="utf-8")
    for student, data in BROKEN.items():
        (plain / student).mkdir()
        (plain / student / NAME).write_bytes(data)
    tool_start = time.monotonic()  # the grade tool on one core, nbgrader on the other
    tool = subprocess.Popen(
        [sys.executable, "-m", "lqe_helpers.grading.grade", str(plain), "--out",
         str(base / "grades"), "--source", str(WORKED.parent), "--jobs", "1",
         "--cell-timeout", str(CELL_TIMEOUT), "--notebook-timeout", "300"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        autograde = nbgrader(course, "autograde", "lqe", f"--Execute.timeout={CELL_TIMEOUT}")
        nbgrader_seconds = time.monotonic() - start
        nbgrader(course, "generate_feedback", "lqe")
        nbgrader(course, "export", "--exporter=lqe_helpers.grading.nbgrader_export."
                 "QuestionPointsExport", "--to=questions.csv")
        _, stderr = tool.communicate(timeout=900)
    finally:
        tool.kill()
    tool_seconds = time.monotonic() - tool_start
    assert tool.returncode == 0, stderr
    with (base / "grades" / "grades.csv").open(encoding="utf-8") as table:
        all_rows = {(row["student"], row["notebook"]): row for row in csv.DictReader(table)}
    tool_rows = {student: row for (student, name), row in all_rows.items() if name == NAME}
    with (course / "questions.csv").open(encoding="utf-8") as table:
        export_rows = {row["student"]: row for row in csv.DictReader(table)}
    return {"base": base, "course": course, "plain": plain, "autograde": autograde,
            "nbgrader_seconds": nbgrader_seconds, "tool_seconds": tool_seconds,
            "tool": tool_rows, "tool_all": all_rows, "export": export_rows,
            "grades": base / "grades"}


def expected_points(student: str) -> float:
    return sum(4.5 for passed in PASSES[student].values() if passed)


def expected_questions(student: str) -> dict[str, float]:
    """Automatic points per question of a student's whole submission (0: not submitted)."""
    return {ASSIGNMENT[name]: LATER.get(student, {}).get(name, 0)
            for name in ASSIGNMENT if name != NAME} | {"(a)": expected_points(student)}


def test_nbgrader_release_holds_the_student_editions_stubs(graded: dict) -> None:
    release = (graded["course"] / "release" / "lqe" / NAME).read_text(encoding="utf-8")
    assert release.count(nbgrader_course.CODE_STUB.replace('"', '\\"')) == 2
    assert "np.linalg.solve" not in release and "BEGIN SOLUTION" not in release


def test_nbgrader_never_releases_nor_uses_saved_functions(graded: dict) -> None:
    """The worked my_functions/ in source/lqe/ is not released nor copied into a graded
    submission, and a submitted one is not used: 02–05 load what the submission's own 01
    saved in autograde (none for the wrong my_filter)."""
    release = graded["course"] / "release" / "lqe"
    assert sorted(path.name for path in release.iterdir()) == sorted(ASSIGNMENT)
    assert not [path for path in release.iterdir()
                if "np.linalg.solve" in path.read_text(encoding="utf-8")]
    autograded = graded["course"] / "autograded"
    assert sorted(path.name for path in (autograded / "wrong" / "lqe" / SAVED.name).iterdir()
                  ) == ["compensate.py"]  # saved by its own 05; its my_filter never passed
    saved = (autograded / "filled" / "lqe" / SAVED.name / "my_filter.py").read_text("utf-8")
    assert saved.startswith("# Written by lqe_helpers.student_code.save")  # by its own 01


@pytest.mark.parametrize("student", NBGRADER_STUDENTS)
def test_nbgrader_autograde_gives_each_submission_its_points(graded: dict,
                                                             student: str) -> None:
    row = graded["export"][student]
    assert {label: float(row[f"{label} automatic"]) for label in ASSIGNMENT.values()} == \
        expected_questions(student)
    assert graded["export"][student]["(a) by hand"] == ""  # written answers: not yet marked


def test_nbgrader_export_has_one_row_per_student(graded: dict) -> None:
    assert sorted(graded["export"]) == sorted(NBGRADER_STUDENTS)
    assert list(next(iter(graded["export"].values()))) == ["student", *(
        f"{label} {kind}" for label in ASSIGNMENT.values() for kind in ("automatic",
                                                                         "by hand"))]


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
    """Per question, for every notebook a student submitted (02–05 included)."""
    compared = 0
    for (student, name), row in graded["tool_all"].items():
        if student in NBGRADER_STUDENTS:
            assert (row["question"], row["automatic points"]) == (
                ASSIGNMENT[name], graded["export"][student][f"{ASSIGNMENT[name]} automatic"])
            compared += 1
    assert compared == len(NBGRADER_STUDENTS) + sum(map(len, LATER.values()))


@pytest.mark.parametrize("student", list(LATER))
def test_grade_tool_grades_later_notebooks_with_the_students_own_filter(graded: dict,
                                                                        student: str) -> None:
    """02–05 run the my_filter the student's own 01 saved in grading, never a submitted one:
    the wrong my_filter saved none, so 05's one-trial check fails and names why."""
    for name, points in LATER[student].items():
        row = graded["tool_all"][student, name]
        assert (row["question"], float(row["automatic points"])) == (ASSIGNMENT[name], points)
    if student == "wrong":
        cause = graded["tool_all"]["wrong", "05_sensory_delay.ipynb"]["check_delay_signals"]
        assert cause.startswith("NameError") and "my_filter is not saved yet" in cause
        page = graded["course"] / "feedback" / "wrong" / "lqe" / "05_sensory_delay.html"
        assert "my_filter is not saved yet" in page.read_text(encoding="utf-8")


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
    assert [path.relative_to(graded["plain"]) for path in graded["plain"].rglob("*")
            if SAVED.name in path.parts] == [Path("wrong", SAVED.name),
                                             Path("wrong", SAVED.name, "my_filter.py")]


def test_grade_tool_rerun_skips_graded_and_regrades_changed(graded: dict,
                                                           tmp_path: Path) -> None:
    """A second run (as after a kill) grades only what has no result or changed."""
    plain, out = tmp_path / "submissions", tmp_path / "grades"
    shutil.copytree(graded["plain"], plain)
    shutil.copytree(graded["grades"], out)
    (plain / "untouched" / NAME).write_text("[]", "utf-8")  # changed since: graded again
    (plain / "wrong" / NAME).write_text("[]", "utf-8")  # so is 05, which loads what 01 saves
    (out / "results" / "invalid" / f"{NAME}.json").unlink()  # as if killed before it
    done = subprocess.run(
        [sys.executable, "-m", "lqe_helpers.grading.grade", str(plain), "--out", str(out),
         "--source", str(WORKED.parent), "--cell-timeout", str(CELL_TIMEOUT)],
        capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    submitted = len(PASSES) + len(BROKEN) + sum(map(len, LATER.values()))
    assert f"skipped {submitted - 4} submission" in done.stdout
    assert "graded 4 submission" in done.stdout  # untouched, invalid, wrong's 01 and 05
    with (out / "grades.csv").open(encoding="utf-8") as table:
        rows = {row["student"]: row for row in csv.DictReader(table) if row["notebook"] == NAME}
    assert rows["invalid"]["error"].startswith("not graded: ")
    assert rows["untouched"]["error"].startswith("not graded: ")
    assert rows["filled"]["automatic points"] == "9"  # kept from the first run
    print(f"grade tool, {submitted} submissions on 1 job: "
          f"{graded['tool_seconds']:.0f} s")


def test_nbgrader_runs_the_explorer_headless(graded: dict) -> None:
    """The explorer cell ran in autograde (no widget frontend) and ended without an error."""
    autograded = nbformat.read(graded["course"] / "autograded" / "filled" / "lqe" / NAME,
                               as_version=4)
    [explorer] = [cell for cell in autograded.cells if "explore_vision(" in cell.source]
    assert explorer.outputs
    assert not [output for output in explorer.outputs if output.output_type == "error"]
