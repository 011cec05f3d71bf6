"""Grade a class's submitted notebooks without nbgrader: a grade table and feedback pages.

``python -m lqe_helpers.grading.grade SUBMISSIONS_DIR --out build/grades [--source notebooks]``

``SUBMISSIONS_DIR`` holds one folder per student with the notebooks they submitted (named
as the course's, e.g. ``alice/01_vision_only.ipynb``). Each notebook is graded in its own
process on a fresh kernel, top to bottom, its saved outputs and execution order ignored,
``--jobs`` at a time (default: every core), within ``--cell-timeout`` seconds per cell (a cell
past it is interrupted and the run goes on) and ``--notebook-timeout`` per notebook (then it
is stopped and its checks get 0). As under nbgrader, a notebook loads the functions that the
grading runs of the student's earlier notebooks saved (02–05 the ``my_filter`` of their own
01, once it is graded); a submitted ``my_functions/`` is not used.
Only the core path is run (up to ``## Going further``); explorer cells are left out (they
only draw), and every cell of the worked notebook other than a task (check cells included)
is restored from ``--source``, so an edited check cannot pass. A check earns its points
(:mod:`lqe_helpers.authoring.points`) when it runs without raising.

Writes, only under ``--out``: ``results/<student>/<notebook>.json`` (one per submission, as
soon as it is graded, atomically; a rerun skips those whose submission is unchanged, so a
killed run resumes; a notebook is graded again when a notebook whose saved functions it
loads changed), then ``grades.csv`` (student, notebook, question, automatic points, out
of, and per check ``passed`` or its one-line cause) and ``feedback/<student>.html``. Every
submission gets a row, whatever it holds (not a notebook, invalid JSON, empty, too large).
"""

from __future__ import annotations

from lqe_helpers.authoring.command_line import interrupt_exits_quietly

with interrupt_exits_quietly(__name__):  # Ctrl-C while importing: one line
    import argparse
    import csv
    import hashlib
    import html
    import io
    import json
    import os
    import shutil
    import signal
    import subprocess
    import sys
    import tempfile
    import time
    from collections.abc import Sequence
    from pathlib import Path

    import nbformat

    from lqe_helpers.authoring.command_line import CommandLineParser, run_command
    from lqe_helpers.authoring.errors import error_line, first_line, shown, strip_colour
    from lqe_helpers.authoring.execution import positive_seconds
    from lqe_helpers.authoring.files import atomic_write_text
    from lqe_helpers.authoring.marking_guide import question_and_marks
    from lqe_helpers.authoring.notebook_io import read_notebook, source_notebooks
    from lqe_helpers.authoring.points import core_end, graded_cells
    from lqe_helpers.authoring.task_cells import (
        EXPLORER_TAG,
        SOLUTION_TAG,
        TASK_PREFIX,
        TASK_TAG,
        cell_tags,
    )
    from lqe_helpers.grading.rules import QUESTION_LABELS, SAVED_FUNCTIONS, saves_functions

CELL_TIMEOUT, NOTEBOOK_TIMEOUT = 60.0, 600.0
PASSED = "passed"
#: Run first in every grading kernel: figures are built as the notebook asks, but not
#: rendered to PNG (they carry no points; rendering is a third of 01's run).
PRELUDE = """\
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as _plt
import lqe_helpers.plotting as _plotting
_plotting.show_figure = (lambda close: lambda figure, description: close(figure))(_plt.close)
del matplotlib, _plt, _plotting"""


def graded_copy(submission: nbformat.NotebookNode, worked: nbformat.NotebookNode,
                marks: int) -> tuple[nbformat.NotebookNode, set[str]]:
    """The notebook to run: the submission's core path, every worked cell but the tasks
    restored (matched by cell id, a check cell else by the check it calls), explorers left
    out, :data:`PRELUDE` first. Returns it and the grade ids of checks missing from the
    submission."""
    plan = graded_cells(worked, marks)
    tasks = {worked.cells[g.index].get("id") for g in plan if g.kind == "task"}
    checks = {worked.cells[g.index].source: g.grade_id for g in plan if g.kind == "check"}
    by_id = {cell.get("id"): cell for cell in worked.cells[:core_end(worked)]
             if cell.get("id") not in tasks}
    cells, found = [nbformat.v4.new_code_cell(PRELUDE)], set()
    for cell in submission.cells[:core_end(submission)]:
        source = by_id.get(cell.get("id"))
        if source is None and cell.get("id") not in tasks \
                and not {TASK_TAG, SOLUTION_TAG} & set(cell_tags(cell)):
            source = next((worked_cell for text, grade_id in checks.items()
                           if f"checks.{grade_id}(" in cell.source
                           for worked_cell in worked.cells if worked_cell.source == text), None)
        if source is not None:
            cell = source
        if cell.cell_type != "code" or EXPLORER_TAG in cell_tags(cell):
            continue
        found |= {checks[cell.source]} if cell.source in checks else set()
        cells.append(nbformat.v4.new_code_cell(cell.source))
    run = nbformat.v4.new_notebook(cells=cells, metadata={"kernelspec": worked.metadata.get(
        "kernelspec", {"name": "python3", "display_name": "Python 3", "language": "python"})})
    return run, set(checks.values()) - found


def cause(cell: nbformat.NotebookNode, task: nbformat.NotebookNode | None = None) -> str:
    """``passed``, or the one-line cause of the first error a cell's outputs hold; for a
    check cell whose ``task`` cell stopped with an error too, that error is named after it
    (a ``NameError`` of the check then says why the name was never made)."""
    for output in cell.get("outputs", []):
        if output.output_type == "error":
            line = first_line(strip_colour(f"{output.ename}: {output.evalue}"))
            line = line.replace("\n", " ").strip()
            before = PASSED if task is None else cause(task)
            return line if before == PASSED else f"{line} (its task cell stopped: {before})"
    return PASSED


def grade_one(path: Path, worked_path: Path, cell_timeout: float, result_path: Path,
              functions_from: Sequence[Path] = ()) -> dict:
    """Run one submission in a fresh kernel; return its result (see the module docstring).

    The kernel runs in a temporary folder beside ``result_path``, which also gets the
    kernel's process id while it runs (:func:`_side_files`), for :func:`_stop`, and the
    functions saved by the grading runs whose results are ``functions_from`` (in order; a
    later one replaces an earlier), in :data:`SAVED_FUNCTIONS`. The result of a notebook
    that saves functions holds, under ``"saved"``, that folder's files after its run."""
    from nbclient import NotebookClient

    worked = read_notebook(worked_path)
    _, marks = question_and_marks(worked, worked_path.name)
    points = {g.grade_id: g.points for g in graded_cells(worked, marks) if g.kind == "check"}
    result = {"checks": dict.fromkeys(points, "not run"), "points": 0.0,
              "out_of": sum(points.values()), "error": ""}
    try:
        run, missing = graded_copy(read_notebook(path), worked, marks)
    except Exception as error:  # any unreadable submission gets its row, with the cause
        return {**result, "error": f"not graded: {error_line(error)}"}
    result["checks"].update(dict.fromkeys(missing, "check cell missing from the submission"))
    pid_file, work_prefix = _side_files(result_path)
    with tempfile.TemporaryDirectory(dir=result_path.parent, prefix=work_prefix) as work:
        saved = Path(work) / SAVED_FUNCTIONS
        for provider in functions_from:
            _write_saved(saved, _saved_functions(provider))
        client = NotebookClient(run, timeout=cell_timeout, allow_errors=True,
                                interrupt_on_timeout=True, store_widget_state=False,
                                error_on_timeout={"ename": "TimeoutError", "evalue":
                                                  f"the cell ran longer than the time limit "
                                                  f"of {cell_timeout:g} s", "traceback": []},
                                resources={"metadata": {"path": work}},
                                on_notebook_start=lambda **_: atomic_write_text(
                                    pid_file, str(client.km.provisioner.pid)))
        try:
            client.execute()
        except Exception as error:  # the kernel died: what ran is still graded
            result["error"] = error_line(error)
        finally:
            pid_file.unlink(missing_ok=True)
        if saves_functions(worked) and saved.is_dir():
            result["saved"] = {file.name: file.read_text(encoding="utf-8", errors="replace")
                               for file in sorted(saved.glob("*.py")) if file.is_file()}
    task = None  # the latest task cell run (a check judges what it made)
    for cell in run.cells:
        task = cell if cell.source.lstrip().startswith(TASK_PREFIX) else task
        grade_id = next((gid for gid in points if f"checks.{gid}(" in cell.source), None)
        if grade_id and cell.get("execution_count") is not None:
            result["checks"][grade_id] = cause(cell, task)
    result["points"] = sum(points[g] for g, outcome in result["checks"].items()
                           if outcome == PASSED)
    return result


def _saved_functions(result_path: Path) -> dict[str, str]:
    """The functions a saved result says its run left in :data:`SAVED_FUNCTIONS` (none if
    it has no usable result)."""
    try:
        saved = json.loads(result_path.read_text(encoding="utf-8")).get("saved", {})
    except (OSError, ValueError, AttributeError):
        return {}
    return saved if isinstance(saved, dict) else {}


def _write_saved(folder: Path, saved: dict[str, str]) -> None:
    """Write ``saved`` (file name: text) into ``folder``; only plain ``*.py`` names."""
    for name, text in saved.items():
        if isinstance(text, str) and Path(name).name == name and name.endswith(".py"):
            folder.mkdir(exist_ok=True)
            atomic_write_text(folder / name, text)


def submissions(folder: Path, source_dir: Path) -> list[tuple[str, str, Path | None, Path | None]]:
    """(student, notebook, submitted file, worked notebook) for every submission found."""
    worked = {path.name: path for path in source_notebooks(source_dir)}
    found = []
    for student in sorted(folder.iterdir()):
        if not student.is_dir() or student.is_symlink():
            found.append((student.name, "", student, None))
            continue
        notebooks = sorted(p for p in student.iterdir() if p.suffix == ".ipynb")
        found += [(student.name, p.name, p, worked.get(p.name) or next(
            (w for name, w in worked.items() if name[:2] == p.name[:2]), None))
                  for p in notebooks]
        if not notebooks:
            found.append((student.name, "", None, None))
    return found


def grade_all(folder: Path, out: Path, source_dir: Path, *, jobs: int,
              cell_timeout: float, notebook_timeout: float) -> tuple[Path, int, int]:
    """Grade every submission not yet graded; write the table and the feedback pages.

    Returns the CSV's path, how many submissions were graded now and how many skipped.
    """
    folder, out, source_dir = Path(folder), Path(out), Path(source_dir)
    if not folder.is_dir():
        raise ValueError(f"SUBMISSIONS_DIR must be an existing folder, got {shown(folder)}")
    if out.resolve().is_relative_to(folder.resolve()):
        raise ValueError(f"--out must not lie inside SUBMISSIONS_DIR, got {shown(out)}")
    out.mkdir(parents=True, exist_ok=True)
    rows, todo, skipped = [], [], 0
    saves: dict[Path, bool] = {}  # worked notebook: whether it saves functions for later ones
    providers: dict[str, list[tuple[Path, str]]] = {}  # student: (result, digest) of those
    for student, name, path, worked in submissions(folder, source_dir):
        result_path = out / "results" / student / f"{name or 'no-notebook'}.json"
        digest = _digest(path) if path and path.is_file() else ""
        earlier = list(providers.setdefault(student, []))
        if digest and earlier:  # graded again when a notebook it loads functions from changed
            digest = hashlib.sha256(" ".join([digest, *(d for _, d in earlier)]).encode()
                                    ).hexdigest()
        if worked is not None and digest:
            if worked not in saves:
                saves[worked] = saves_functions(read_notebook(worked))
            if saves[worked]:
                providers[student].append((result_path, digest))
        rows.append((student, name, result_path, worked))
        if _saved_digest(result_path) == digest:
            skipped += 1
            continue
        if path is None or worked is None or not path.is_file():
            why = ("no notebook submitted" if path is None else
                   "not in a student's folder (SUBMISSIONS_DIR/<student>/<notebook>.ipynb)"
                   if path.parent == folder else "not a file" if not path.is_file() else
                   "no notebook of the course has this name")
            _save(result_path, {"checks": {}, "points": 0.0, "out_of": 0.0, "sha256": digest,
                                "error": f"not graded: {why}"})
            continue
        todo.append((path, worked, result_path, digest, [result for result, _ in earlier]))
    graded = len(todo)
    _run_workers(todo, jobs, cell_timeout, notebook_timeout)
    return _write_reports(rows, out), graded, skipped


def _digest(path: Path) -> str:
    """SHA-256 of a file, read in blocks (a submission may be huge)."""
    digest = hashlib.sha256()
    with path.open("rb") as file:
        while block := file.read(1 << 20):
            digest.update(block)
    return digest.hexdigest()


def _saved_digest(path: Path) -> str | None:
    """The submission digest a saved result records (None: no usable result)."""
    try:
        return json.loads(path.read_text(encoding="utf-8")).get("sha256")
    except (OSError, ValueError, AttributeError):
        return None


def _save(path: Path, result: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, json.dumps(result, ensure_ascii=False, indent=1))


def _run_workers(todo: list, jobs: int, cell_timeout: float, notebook_timeout: float) -> None:
    """Grade each submission in a child process, ``jobs`` at a time, each within its limit;
    one whose functions come from other submissions' results starts once they are saved."""
    running: dict[subprocess.Popen, tuple] = {}
    try:
        while todo or running:
            while len(running) < jobs:
                pending = {item[2] for item in [*todo, *running.values()]}
                item = next((item for item in todo if not pending & set(item[4])), None)
                if item is None:
                    break
                todo.remove(item)
                path, worked, result_path, digest, functions_from = item
                _remove_side_files(result_path)
                command = [sys.executable, "-m", "lqe_helpers.grading.grade", "--one",
                           str(path), "--worked", str(worked), "--result", str(result_path),
                           "--sha256", digest, "--cell-timeout", str(cell_timeout),
                           *(arg for result in functions_from
                             for arg in ("--functions-from", str(result)))]
                child = subprocess.Popen(command, stdout=subprocess.DEVNULL,
                                         stderr=subprocess.PIPE, start_new_session=True)
                running[child] = (path, worked, result_path, digest, time.monotonic())
            time.sleep(0.1)
            for child, (_, worked, result_path, digest, start) in list(running.items()):
                late = time.monotonic() - start > notebook_timeout
                if child.poll() is None and not late:
                    continue
                if late and child.poll() is None:
                    _stop(child, result_path)
                del running[child]
                stderr = child.communicate()[1].decode("utf-8", "replace").strip()
                if late or child.returncode:
                    why = (f"stopped: ran longer than the time limit of {notebook_timeout:g} s "
                           f"per notebook" if late else
                           first_line(stderr.splitlines()[-1] if stderr else "grader failed"))
                    points = _plan(worked)
                    _save(result_path, {"checks": dict.fromkeys(points, "not run"),
                                        "points": 0.0, "out_of": sum(points.values()),
                                        "sha256": digest, "error": why})
    finally:
        for child, item in running.items():
            _stop(child, item[2])


def _side_files(result_path: Path) -> tuple[Path, str]:
    """The kernel's process-id file and the prefix of its working folder, for one result."""
    return (result_path.with_name(f".{result_path.stem}.kernel-pid"),
            f".work-{result_path.stem}-")


def _stop(child: subprocess.Popen, result_path: Path) -> None:
    """Kill a worker, its kernel (in a session of its own) and the kernel's folder."""
    pid_file = _side_files(result_path)[0]
    for pid_of in (lambda: child.pid, lambda: int(pid_file.read_text())):
        try:
            os.killpg(pid_of(), signal.SIGKILL)
        except (OSError, ValueError):
            pass  # gone already, or no kernel started
    child.wait()
    _remove_side_files(result_path)


def _remove_side_files(result_path: Path) -> None:
    """Remove a grading's kernel folder and process-id file (a killed run leaves them)."""
    pid_file, work_prefix = _side_files(result_path)
    pid_file.unlink(missing_ok=True)
    for work in result_path.parent.glob(f"{work_prefix}*"):
        shutil.rmtree(work, ignore_errors=True)


def _plan(worked: Path) -> dict[str, float]:
    notebook = read_notebook(worked)
    marks = question_and_marks(notebook, worked.name)[1]
    return {g.grade_id: g.points for g in graded_cells(notebook, marks) if g.kind == "check"}


def _write_reports(rows: list, out: Path) -> Path:
    """``grades.csv`` and ``feedback/<student>.html`` from every saved result."""
    results = [(student, name, json.loads(path.read_text(encoding="utf-8")))
               for student, name, path, _ in rows]
    check_ids = list(dict.fromkeys(g for _, _, r in results for g in r["checks"]))
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(["student", "notebook", "question", "automatic points", "out of", "error",
                     *check_ids])
    for student, name, result in results:
        writer.writerow([student, name, QUESTION_LABELS.get(name[:2], ""),
                         f"{result['points']:g}", f"{result['out_of']:g}",
                         result["error"], *(result["checks"].get(g, "") for g in check_ids)])
    table = atomic_write_text(out / "grades.csv", text.getvalue())
    (out / "feedback").mkdir(exist_ok=True)
    for student in dict.fromkeys(student for student, _, _ in results):
        atomic_write_text(out / "feedback" / f"{student}.html",
                          feedback_page(student, [(n, r) for s, n, r in results if s == student]))
    return table


def feedback_page(student: str, results: list[tuple[str, dict]]) -> str:
    """One student's feedback: per notebook, each check passed or its cause, and points."""
    parts = [f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
             f"Feedback: {html.escape(student)}</title></head><body>",
             f"<h1>Feedback for {html.escape(student)}</h1>",
             "<p>Automatic points come from the check cells, run top to bottom in a fresh "
             "kernel. Written answers are marked by hand.</p>"]
    for name, result in results:
        parts.append(f"<h2>{html.escape(name or 'no notebook')}: {result['points']:g} of "
                     f"{result['out_of']:g} automatic points</h2>")
        if result["error"]:
            parts.append(f"<p>{html.escape(result['error'])}</p>")
        rows = "".join(f"<tr><td>{html.escape(g)}</td><td>{html.escape(outcome)}</td></tr>"
                       for g, outcome in result["checks"].items())
        if rows:
            parts.append(f"<table><tr><th>Check</th><th>Result</th></tr>{rows}</table>")
    return "\n".join([*parts, "</body></html>\n"])


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: grade SUBMISSIONS_DIR into --out (or, with --one, one submission)."""
    parser = CommandLineParser(prog="python -m lqe_helpers.grading.grade",
                               description=__doc__.splitlines()[0])
    parser.add_argument("submissions", type=Path, nargs="?", metavar="SUBMISSIONS_DIR")
    parser.add_argument("--out", type=Path, default=Path("build/grades"))
    parser.add_argument("--source", type=Path, default=Path("notebooks"),
                        help="folder of the worked notebooks (default: notebooks)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                        help="notebooks graded at once (default: every core)")
    parser.add_argument("--cell-timeout", type=positive_seconds, default=CELL_TIMEOUT)
    parser.add_argument("--notebook-timeout", type=positive_seconds, default=NOTEBOOK_TIMEOUT)
    for hidden in ("--one", "--worked", "--result", "--sha256"):  # a worker's own options
        parser.add_argument(hidden, help=argparse.SUPPRESS)
    parser.add_argument("--functions-from", action="append", default=[], help=argparse.SUPPRESS)

    def command(args: argparse.Namespace) -> int:
        if args.one:
            result_path = Path(args.result)
            result_path.parent.mkdir(parents=True, exist_ok=True)
            result = grade_one(Path(args.one), Path(args.worked), args.cell_timeout,
                               result_path, [Path(p) for p in args.functions_from])
            _save(Path(args.result), {**result, "sha256": args.sha256})
            return 0
        if args.submissions is None:
            raise ValueError("SUBMISSIONS_DIR is required")
        if args.jobs < 1:
            raise ValueError(f"--jobs must be >= 1, got {args.jobs}")
        table, graded, skipped = grade_all(
            args.submissions, args.out, args.source, jobs=args.jobs,
            cell_timeout=args.cell_timeout, notebook_timeout=args.notebook_timeout)
        if skipped:
            print(f"skipped {skipped} submission(s) graded by an earlier run (unchanged)")
        print(f"graded {graded} submission(s); {shown(table)}")
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
