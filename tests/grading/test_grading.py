"""Grading without a kernel: the points, the nbgrader source folder, the grade tool's edges."""

from __future__ import annotations

import itertools
import re
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest
from grading_submissions import NAME, WORKED, WRONG_FILTER, edition, endless_loop, raises_first

from lqe_helpers.authoring import points
from lqe_helpers.authoring.marking_guide import QUESTION_MARKS, question_and_marks
from lqe_helpers.authoring.student_edition import student_edition
from lqe_helpers.authoring.task_cells import stub_source
from lqe_helpers.grading import grade, nbgrader_course, rules

NOTEBOOKS = sorted((Path(__file__).resolve().parents[2] / "notebooks").glob("*.ipynb"))


def plan(path: Path) -> list[points.GradedCell]:
    notebook = nbformat.read(path, as_version=4)
    return points.graded_cells(notebook, question_and_marks(notebook, path.name)[1])


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_points_add_up_to_the_tutorials_marks(path: Path) -> None:
    """(a) 15 … (e) 30 for 01–05, 40 % to the written answers; 00 and 06 carry none."""
    cells = plan(path)
    checks = [cell.points for cell in cells if cell.kind == "check"]
    answers = [cell.points for cell in cells if cell.kind == "answer"]
    marks = {"01": 15, "02": 15, "03": 25, "04": 15, "05": 30}.get(path.name[:2], 0)
    assert sum(checks) + sum(answers) == pytest.approx(marks, abs=1e-12)
    assert sum(answers) == pytest.approx(0.4 * marks, abs=1e-12)
    assert checks and len(set(checks)) == 1  # every core task has a check, equal shares
    assert sum(QUESTION_MARKS.values()) == 100


def test_points_of_01() -> None:
    assert [(c.kind, c.grade_id, c.points) for c in plan(WORKED)] == [
        ("task", "task-1", 0.0), ("check", "check_filter", 4.5), ("task", "task-2", 0.0),
        ("check", "check_vision_trial", 4.5), ("answer", "answer-1", 6.0)]


def test_points_refuse_bad_marks() -> None:
    with pytest.raises(ValueError, match=r"marks must be >= 0, got -1"):
        points.graded_cells(nbformat.read(WORKED, as_version=4), -1)


def clear_solutions(source: str) -> str:
    """What nbgrader's ClearSolutions makes of a solution region (its algorithm, in short)."""
    lines, out, inside = source.split("\n"), [], False
    for line in lines:
        if "BEGIN SOLUTION" in line:
            inside = True
            out.append(re.match(r"\s*", line).group(0) + nbgrader_course.CODE_STUB)
        elif "END SOLUTION" in line:
            inside = False
        elif not inside:
            out.append(line)
    return "\n".join(out)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_nbgrader_source_releases_the_student_editions_stubs(path: Path) -> None:
    """Each core task, released, is the student edition's stub (no worked code left)."""
    source = nbgrader_course.nbgrader_notebook(nbformat.read(path, as_version=4), path.name)
    worked = nbformat.read(path, as_version=4)
    tasks = [c for c in plan(path) if c.kind == "task"]
    released = [cell for cell in source.cells if cell.metadata["nbgrader"]["solution"]
                and cell.cell_type == "code"]
    def lines(source: str) -> list[str]:  # blank lines between blocks may differ
        return [line for line in source.splitlines() if line.strip()]

    assert [lines(clear_solutions(cell.source)) for cell in released] == [
        lines(stub_source(worked.cells[task.index].source)) for task in tasks]


def test_nbgrader_metadata_of_01() -> None:
    source = nbgrader_course.nbgrader_notebook(nbformat.read(WORKED, as_version=4), NAME)
    meta = {cell.metadata["nbgrader"]["grade_id"]: cell.metadata["nbgrader"]
            for cell in source.cells}
    assert len(meta) == len(source.cells)  # every grade id unique
    assert meta["check_filter"] | {} == {"grade": True, "grade_id": "check_filter",
                                         "locked": True, "points": 4.5, "schema_version": 3,
                                         "solution": False, "task": False}
    assert meta["task-1"]["solution"] and not meta["task-1"]["locked"]
    assert meta["answer-1"]["grade"] and meta["answer-1"]["solution"]
    assert meta["answer-1"]["points"] == 6.0
    others = [m for gid, m in meta.items() if gid.startswith("cell-")]
    assert others and all(m["locked"] and not m["grade"] and not m["solution"]
                          for m in others)
    assert source.cells[-1].source.startswith("## Going further")  # the note, no tasks after
    answer = next(c for c in source.cells if c.metadata["nbgrader"]["grade_id"] == "answer-1")
    assert clear_solutions(answer.source).count(nbgrader_course.CODE_STUB) == 1


def test_build_course_writes_source_and_config_and_keeps_an_edited_config(
        tmp_path: Path) -> None:
    written = nbgrader_course.build_course(WORKED.parent, tmp_path / "course")
    names = sorted(path.relative_to(tmp_path / "course").as_posix() for path in written)
    assert names == ["nbgrader_config.py", *(f"source/lqe/{p.name}" for p in NOTEBOOKS
                                             if p.name[:2] in nbgrader_course.GRADED)]
    config = (tmp_path / "course" / "nbgrader_config.py").read_text(encoding="utf-8")
    assert "c.Execute.timeout = 60" in config and "NotImplementedError" in config
    compile(config, "nbgrader_config.py", "exec")
    (tmp_path / "course" / "nbgrader_config.py").write_text(config + "# mine\n")
    with pytest.warns(UserWarning, match="kept your"):
        again = nbgrader_course.build_course(WORKED.parent, tmp_path / "course", ["01"])
    assert [path.name for path in again] == [NAME]
    assert (tmp_path / "course" / "nbgrader_config.py").read_text().endswith("# mine\n")


def test_build_course_refuses_a_missing_notebook_and_out_inside_source(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="no notebook numbered 07"):
        nbgrader_course.build_course(WORKED.parent, tmp_path, ["01", "07"])
    with pytest.raises(ValueError, match="must not lie inside --source"):
        nbgrader_course.build_course(WORKED.parent, WORKED.parent / "x")
    assert not (WORKED.parent / "x").exists()


def test_graded_copy_restores_cells_and_leaves_explorers_out() -> None:
    worked = nbformat.read(WORKED, as_version=4)
    run, missing = grade.graded_copy(raises_first(edition()), worked, 15)
    sources = [cell.source for cell in run.cells]
    assert missing == set()
    assert not any("my own first cell" in s or "edited by the student" in s for s in sources)
    assert "checks.check_vision_trial(vision_trial)" in sources
    assert not any("explore_vision" in s for s in sources)
    assert not any("smoother" in s for s in sources)  # Going further is not run


def test_graded_copy_names_a_deleted_check() -> None:
    notebook = edition()
    notebook.cells = [c for c in notebook.cells if "check_filter(" not in c.source]
    _, missing = grade.graded_copy(notebook, nbformat.read(WORKED, as_version=4), 15)
    assert missing == {"check_filter"}


@pytest.mark.slow
def test_grade_tool_refuses_bad_input_with_one_line(tmp_path: Path) -> None:
    def run(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "lqe_helpers.grading.grade", *args],
                              capture_output=True, text=True, timeout=60)

    missing = run(str(tmp_path / "nowhere"), "--out", str(tmp_path / "out"))
    assert missing.returncode == 1
    assert missing.stderr.strip().splitlines() == [
        f"error: SUBMISSIONS_DIR must be an existing folder, got {tmp_path / 'nowhere'}"]
    (tmp_path / "subs").mkdir()
    inside = run(str(tmp_path / "subs"), "--out", str(tmp_path / "subs" / "grades"))
    assert inside.returncode == 1 and inside.stderr.startswith("error: --out must not lie")
    jobs = run(str(tmp_path / "subs"), "--jobs", "0", "--out", str(tmp_path / "out"))
    assert jobs.stderr.strip() == "error: --jobs must be >= 1, got 0"
    assert not (tmp_path / "out").exists() and not (tmp_path / "subs" / "grades").exists()


def test_grade_tool_gives_every_odd_submission_a_row(tmp_path: Path) -> None:
    """No notebook, a stray file, a notebook the course does not have: one row each."""
    subs = tmp_path / "subs"
    (subs / "nobody").mkdir(parents=True)
    (subs / "loose.ipynb").write_text("{}")
    (subs / "carol").mkdir()
    (subs / "carol" / "99_mine.ipynb").write_text(student_edition(
        nbformat.read(WORKED, as_version=4), "x"))
    table, graded, skipped = grade.grade_all(subs, tmp_path / "out", WORKED.parent, jobs=1,
                                             cell_timeout=10, notebook_timeout=10)
    text = table.read_text(encoding="utf-8")
    assert (graded, skipped) == (0, 0)
    assert "carol,99_mine.ipynb,,0,0,not graded: no notebook of the course has this name" \
        in text
    assert "nobody,,,0,0,not graded: no notebook submitted" in text
    assert "loose.ipynb,,,0,0,not graded: not in a student's folder" in text
    assert sorted(p.name for p in (tmp_path / "out" / "feedback").iterdir()) == [
        "carol.html", "loose.ipynb.html", "nobody.html"]


def test_marking_guide_states_the_points() -> None:
    from lqe_helpers.authoring import marking_guide as mg

    guide = mg.render([mg.notebook_guide(nbformat.read(WORKED, as_version=4), NAME)])
    assert guide.count("- **Points:** 4.5 (automatic)") == 2
    assert "Points: 6, marked by hand." in guide
    assert "40 % of a question's marks go to its written answers" in guide


@pytest.mark.slow
@pytest.mark.kernel
def test_grade_tool_stops_a_notebook_past_its_limit_with_its_kernel(tmp_path: Path) -> None:
    """The loop runs past the notebook's limit: its row says so, no kernel is left running."""
    psutil = pytest.importorskip("psutil")
    subs = tmp_path / "subs"
    (subs / "dave").mkdir(parents=True)
    looping = endless_loop(edition())
    (subs / "dave" / NAME).write_text(nbformat.writes(looping), encoding="utf-8")
    table, graded, _ = grade.grade_all(subs, tmp_path / "out", WORKED.parent, jobs=1,
                                       cell_timeout=600, notebook_timeout=8)
    row = table.read_text(encoding="utf-8").splitlines()[1]
    assert graded == 1
    assert row.startswith("dave,01_vision_only.ipynb,(a),0,9,stopped: ran longer than the time "
                          "limit of 8 s per notebook,not run,not run")
    left = []
    for process in psutil.process_iter(["cwd"]):
        if str(tmp_path) in (process.info["cwd"] or ""):
            left.append(process)
    assert not left, left
    assert sorted(p.name for p in (tmp_path / "out" / "results" / "dave").iterdir()) == [
        f"{NAME}.json"]


def test_graded_copy_keeps_a_task_that_calls_its_check() -> None:
    """A student who calls the check in their own task cell keeps their code."""
    notebook = edition()
    task = next(c for c in notebook.cells if "def my_filter" in c.source)
    task.source = WRONG_FILTER + "\nchecks.check_filter(my_filter)\n"
    task.id = "the-students-own"
    run, _ = grade.graded_copy(notebook, nbformat.read(WORKED, as_version=4), 15)
    assert any(cell.source == task.source for cell in run.cells)


@pytest.mark.slow
def test_grade_tool_gives_a_huge_submission_its_row(tmp_path: Path) -> None:
    """A 300 MB file (sparse: no disk used) is refused by size, with its row; the kernel
    folder a killed run left is removed."""
    subs = tmp_path / "subs"
    (subs / "erin").mkdir(parents=True)
    with (subs / "erin" / NAME).open("wb") as file:
        file.truncate(300 * 2**20)
    stale = tmp_path / "out" / "results" / "erin" / f".work-{NAME}-left-by-a-killed-run"
    stale.mkdir(parents=True)
    table, graded, _ = grade.grade_all(subs, tmp_path / "out", WORKED.parent, jobs=1,
                                       cell_timeout=10, notebook_timeout=60)
    row = table.read_text(encoding="utf-8").splitlines()[1]
    assert graded == 1
    assert row.startswith("erin,01_vision_only.ipynb,(a),0,9,\"not graded: ")
    assert "is 300 MB, larger than the 256 MB the tools read as a notebook" in row
    assert [p.name for p in stale.parent.iterdir()] == [f"{NAME}.json"]


def test_question_labels() -> None:
    assert [rules.question_label(p.name) for p in NOTEBOOKS] == [
        NOTEBOOKS[0].name, "(a)", "(b)", "(c)", "(d)", "(e)", NOTEBOOKS[-1].name]


def test_nbgrader_config_ignores_saved_functions() -> None:
    """my_functions/ never goes from source/ to release/ or a graded copy, nor from a
    submission: nbgrader's defaults plus it (the folder student_code saves into)."""
    from traitlets.config import Config

    from lqe_helpers import student_code

    config = Config()
    exec(nbgrader_course.CONFIG, {"get_config": lambda: config})  # as nbgrader loads it
    assert rules.SAVED_FUNCTIONS == student_code.SAVE_FOLDER
    assert config.CourseDirectory.ignore == [".ipynb_checkpoints", "*.pyc", "__pycache__",
                                             "feedback", rules.SAVED_FUNCTIONS]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_saves_functions_finds_the_notebooks_that_save(path: Path) -> None:
    """01 saves my_filter and 05 compensate, for the later notebooks (and their explorers)."""
    saves = rules.saves_functions(nbformat.read(path, as_version=4))
    assert saves == (path.name[:2] in {"01", "05"})


def test_cause_of_a_check_names_its_task_cells_error() -> None:
    """A check that fails because its task cell stopped says why the task stopped."""
    def cell(source: str, ename: str | None = None, evalue: str = "") -> nbformat.NotebookNode:
        code = nbformat.v4.new_code_cell(source)
        if ename:
            code.outputs = [nbformat.v4.new_output("error", ename=ename, evalue=evalue,
                                                   traceback=[])]
        return code

    check = cell("checks.check_delay_signals(late_readings)", "NameError",
                 "name 'late_readings' is not defined")
    task = cell("# Task: ...", "NotSavedYet", "my_filter is not saved yet: notebook 01 …")
    assert grade.cause(check, task) == (
        "NameError: name 'late_readings' is not defined (its task cell stopped: "
        "NotSavedYet: my_filter is not saved yet: notebook 01 …)")
    assert grade.cause(check, cell("# Task: ...")) == grade.cause(check) == \
        "NameError: name 'late_readings' is not defined"
    assert grade.cause(cell("checks.check_x()"), task) == grade.PASSED


def test_grade_tool_starts_a_notebook_once_the_functions_it_loads_are_saved(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A student's 05 waits for their 01 (whose run saves my_filter); the others go on."""
    started, finished = [], set()

    class Child:  # a worker that ends at its first poll
        def __init__(self, command: list[str], **_: object) -> None:
            self.result = Path(command[command.index("--result") + 1])
            loads = [Path(p) for flag, p in itertools.pairwise(command)
                     if flag == "--functions-from"]
            started.append((self.result.name, [p.name for p in loads],
                            all(p in finished for p in loads)))
            self.pid, self.returncode = 0, None

        def poll(self) -> int:
            self.returncode = 0
            finished.add(self.result)
            return 0

        def communicate(self) -> tuple[bytes, bytes]:
            return b"", b""

    monkeypatch.setattr(grade.subprocess, "Popen", Child)
    item = lambda name, loads=(): (tmp_path / name, WORKED, tmp_path / name, "",  # noqa: E731
                                   [tmp_path / load for load in loads])
    grade._run_workers([item("alice-01"), item("alice-05", ["alice-01"]), item("bob-01")],
                       2, 60, 600)
    assert started == [("alice-01", [], True), ("bob-01", [], True),
                       ("alice-05", ["alice-01"], True)]
