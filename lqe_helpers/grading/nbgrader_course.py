"""Write an nbgrader course folder from the worked notebooks.

``python -m lqe_helpers.grading.nbgrader_course [--source notebooks] [--out build/nbgrader]``
(``make nbgrader``) writes ``source/lqe/<notebook>.ipynb`` for the graded questions
(01–05, (a)–(e); :data:`GRADED`) and ``nbgrader_config.py``. Each notebook is the core path
of the worked notebook (``## Going further`` is optional and carries no points: it stays in
the student pack) with nbgrader cell metadata:

- a ``solution`` cell becomes an autograded answer: its ``# Task:`` comment, then the worked
  code between ``### BEGIN SOLUTION`` / ``### END SOLUTION`` (inside each function's body,
  so the released stub keeps signature and docstring, as the student edition does);
- the check cell after it becomes a locked autograder test with its points;
- an ``answer`` cell becomes a manually graded answer with its points (headings kept);
- every other cell is read-only.

Points: :mod:`lqe_helpers.authoring.points`. nbgrader itself is not needed to write the
folder (``pip install -e '.[grading]'`` to run it). Files are written atomically, only these
files, only under ``--out``; an ``nbgrader_config.py`` already there is kept (with a warning
if it differs from the one this tool would write).
"""

from __future__ import annotations

from lqe_helpers.authoring.command_line import interrupt_exits_quietly

with interrupt_exits_quietly(__name__):  # Ctrl-C while importing: one line
    import argparse
    import ast
    import copy
    import warnings
    from collections.abc import Sequence
    from pathlib import Path

    import nbformat

    from lqe_helpers.authoring.command_line import CommandLineParser, run_command
    from lqe_helpers.authoring.errors import shown
    from lqe_helpers.authoring.files import atomic_write_text
    from lqe_helpers.authoring.marking_guide import question_and_marks
    from lqe_helpers.authoring.notebook_io import notebook_bytes, read_notebook, source_notebooks
    from lqe_helpers.authoring.points import core_end, graded_cells
    from lqe_helpers.authoring.task_cells import (
        ANSWER_PROMPT,
        ANSWER_PROMPT_TAG,
        ANSWER_TAG,
        SOLUTION_TAG,
        STUB_MESSAGE,
        TASK_TAG,
        answer_headings,
        cell_tags,
        task_instruction,
    )
    from lqe_helpers.grading.rules import SAVED_FUNCTIONS

#: The nbgrader assignment (and course) name.
ASSIGNMENT = "lqe"
#: Notebooks put in the assignment, by number: the tutorial's questions (a)–(e).
GRADED = ("01", "02", "03", "04", "05")
#: Seconds one cell may run when nbgrader autogrades (``Execute.timeout``).
CELL_TIMEOUT = 60
BEGIN, END = "### BEGIN SOLUTION", "### END SOLUTION"
#: Markdown solution delimiters (HTML comments: invisible in the rendered source).
MD_BEGIN, MD_END = "<!-- BEGIN SOLUTION -->", "<!-- END SOLUTION -->"
#: The released code stub: the student edition's line.
CODE_STUB = f'raise NotImplementedError("{STUB_MESSAGE}")'
#: Closing cell of each assignment notebook.
GOING_FURTHER_NOTE = ("## Going further\n\nThe optional *Going further* part of this notebook "
                      "is in the student pack's edition. It carries no points.")

CONFIG = f'''\
"""nbgrader configuration of the LQE course (written by lqe_helpers.grading.nbgrader_course)."""
import importlib.util

if importlib.util.find_spec("lqe_helpers") is None:  # the kernel must import the pack
    raise SystemExit("error: the course pack is not installed in this environment; run "
                     "pip install -e '.[grading]' in the course pack's folder")

c = get_config()  # noqa: F821 (nbgrader defines it)
c.CourseDirectory.course_id = "{ASSIGNMENT}"
# The released stubs are the student edition's.
c.ClearSolutions.code_stub = {{"python": {CODE_STUB!r}}}
c.ClearSolutions.text_stub = {ANSWER_PROMPT!r}
c.ClearSolutions.begin_solution_delimeter = "BEGIN SOLUTION"
c.ClearSolutions.end_solution_delimeter = "END SOLUTION"
# A cell past its limit is interrupted and graded 0; the run goes on with the next cell.
c.Execute.timeout = {CELL_TIMEOUT}
c.Execute.interrupt_on_timeout = True
c.Execute.allow_errors = True
# A check cell a student edited is restored from source/ (nbgrader's OverwriteCells).
# {SAVED_FUNCTIONS}/ is made by each run of 01 (my_filter) and 05 (compensate): ignored, so
# the worked my_filter that running source/{ASSIGNMENT}/ writes there is never released nor
# copied over a submission, and a submitted copy is not used: autograde runs the notebooks
# in order in one folder, so 02-05 load the my_filter the submission's own 01 saves.
c.CourseDirectory.ignore = [".ipynb_checkpoints", "*.pyc", "__pycache__", "feedback",
                            "{SAVED_FUNCTIONS}"]
'''


def solution_source(source: str) -> str:
    """A ``solution`` cell's source with its worked code between solution delimiters.

    Each top-level function keeps its signature and docstring and has its body inside
    :data:`BEGIN` / :data:`END`; each run of other statements is one region (so, released,
    the cell is the student edition's stub when its functions come first); a cell that
    cannot be parsed has all its code after the ``# Task:`` comment in one region.
    """
    instruction = task_instruction(source)
    lines = source.splitlines()[len(instruction):]
    try:
        body = ast.parse("\n".join(lines)).body
    except SyntaxError:
        body = []
    regions: list[tuple[int, int, str]] = []  # line slices [begin, end) and indent
    block, previous_end = None, 0
    for node in body:
        if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            block = (block[0] if block else previous_end, node.end_lineno)
            previous_end = node.end_lineno
            continue
        if block:
            regions.append((block[0], block[1], ""))
            block = None
        docstring = ast.get_docstring(node, clean=False) is not None
        first = node.body[1] if docstring and len(node.body) > 1 else node.body[0]
        if first.lineno == node.lineno or (docstring and len(node.body) == 1):
            return "\n".join([*instruction, BEGIN, *lines, END])  # a one-line def
        begin = node.body[0].end_lineno if docstring else first.lineno - 1
        regions.append((begin, node.end_lineno, " " * first.col_offset))
        previous_end = node.end_lineno
    if block:
        regions.append((block[0], len(lines), ""))
    if not regions:
        return "\n".join([*instruction, BEGIN, *lines, END])
    for begin, end, indent in reversed(regions):
        lines[begin:end] = [indent + BEGIN, *lines[begin:end], indent + END]
    return "\n".join([*instruction, *lines])


def nbgrader_metadata(grade_id: str, *, grade: bool = False, solution: bool = False,
                      locked: bool = True, points: float | None = None) -> dict:
    """nbgrader's cell metadata (schema 3)."""
    meta = {"grade": grade, "grade_id": grade_id, "locked": locked, "schema_version": 3,
            "solution": solution, "task": False}
    if points is not None:
        meta["points"] = points
    return meta


def nbgrader_notebook(notebook: nbformat.NotebookNode, name: str) -> nbformat.NotebookNode:
    """The nbgrader source of one worked notebook: its core path with nbgrader metadata.

    Raises
    ------
    ValueError
        If its marks are not the tutorial's or a cell breaks the task convention.
    """
    _, marks = question_and_marks(notebook, name)
    notebook = copy.deepcopy(notebook)
    plan = {cell.index: cell for cell in graded_cells(notebook, marks)}
    notebook.cells = notebook.cells[:core_end(notebook)]
    notebook.cells.append(nbformat.v4.new_markdown_cell(GOING_FURTHER_NOTE))
    notebook.cells[-1].id = "going-further-note"
    for index, cell in enumerate(notebook.cells):
        graded = plan.get(index)
        tags = cell_tags(cell)
        meta = nbgrader_metadata(f"cell-{index}")
        if graded is not None and graded.kind == "task":
            cell.source = solution_source(cell.source)
            meta = nbgrader_metadata(graded.grade_id, solution=True, locked=False)
        elif graded is not None and graded.kind == "check":
            meta = nbgrader_metadata(graded.grade_id, grade=True, points=graded.points)
        elif graded is not None:
            headings = answer_headings(cell.source)
            text = "\n".join(line for line in cell.source.splitlines()
                             if line.rstrip() not in headings).strip()
            cell.source = "\n\n".join([*headings, f"{MD_BEGIN}\n{text}\n{MD_END}"])
            meta = nbgrader_metadata(graded.grade_id, grade=True, solution=True, locked=False,
                                     points=graded.points)
        renamed = {SOLUTION_TAG: TASK_TAG, ANSWER_TAG: ANSWER_PROMPT_TAG}
        cell.metadata = {"nbgrader": meta,
                         **({"tags": [renamed.get(tag, tag) for tag in tags]} if tags else {})}
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None
    notebook.metadata = {key: value for key, value in notebook.metadata.items()
                         if key in {"kernelspec", "language_info", "lqe"}}
    return notebook


def build_course(source_dir: Path, out_dir: Path,
                 numbers: Sequence[str] = GRADED) -> list[Path]:
    """Write ``source/lqe/*.ipynb`` and ``nbgrader_config.py`` into ``out_dir``.

    Every notebook is converted before anything is written. Returns the files written.

    Raises
    ------
    ValueError
        If ``source_dir`` has no notebook of a number in ``numbers``, ``out_dir`` lies
        inside ``source_dir``, or a notebook is unusable (:func:`nbgrader_notebook`).
    """
    source_dir, out_dir = Path(source_dir), Path(out_dir)
    if out_dir.resolve().is_relative_to(source_dir.resolve()):
        raise ValueError(f"--out must not lie inside --source, got {shown(out_dir)} in "
                         f"{shown(source_dir)}")
    paths = [path for path in source_notebooks(source_dir) if path.name[:2] in numbers]
    missing = sorted(set(numbers) - {path.name[:2] for path in paths})
    if missing:
        raise ValueError(f"--source {shown(source_dir)} has no notebook numbered "
                         f"{', '.join(missing)}")
    built = {path.name: notebook_bytes(nbgrader_notebook(read_notebook(path), path.name))
             for path in paths}
    folder = out_dir / "source" / ASSIGNMENT
    folder.mkdir(parents=True, exist_ok=True)
    written = [atomic_write_text(folder / name, data.decode("utf-8"))
               for name, data in built.items()]
    config = out_dir / "nbgrader_config.py"
    if not config.exists():
        written.append(atomic_write_text(config, CONFIG))
    elif config.read_text(encoding="utf-8") != CONFIG:
        warnings.warn(f"kept your {shown(config)}, which differs from the one this tool "
                      f"writes (delete it to get the current one)", stacklevel=2)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: write the nbgrader course folder and list the files written."""
    parser = CommandLineParser(prog="python -m lqe_helpers.grading.nbgrader_course",
                               description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, default=Path("notebooks"),
                        help="folder of the worked notebooks (default: notebooks)")
    parser.add_argument("--out", type=Path, default=Path("build/nbgrader"),
                        help="the nbgrader course folder (default: build/nbgrader)")
    parser.add_argument("--notebooks", nargs="+", default=list(GRADED), metavar="NN",
                        help="numbers of the notebooks to include (default: 01 02 03 04 05)")

    def command(args: argparse.Namespace) -> int:
        for path in build_course(args.source, args.out, args.notebooks):
            print(shown(path))
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
