"""The instructor's marking guide, built from the worked notebooks.

``python -m lqe_helpers.authoring.marking_guide [--source notebooks] [--out build/marking-guide]``
(run by ``make student``, beside the student edition, never inside the student pack)
writes one Markdown file, ``marking-guide.md``. For each notebook, in order:

- the tutorial question it answers and its marks, from the notebook metadata
  ``lqe`` (``{"question": "a", "marks": 15, "core_minutes": 45}``), else from the
  fallback tables :data:`NOTEBOOK_QUESTIONS` and :data:`QUESTION_MARKS` (the tutorial's
  marks: (a) 15, (b) 15, (c) 25, (d) 15, (e) 30; metadata that disagrees is an error);
- every task (cell tagged ``solution``), core or "Going further", with its ``# Task:``
  instruction, the check that follows it (its call, the tolerance the check states in
  its docstring, and what it printed when the worked notebook ran), and the expected
  values: what the worked solution printed, from the saved outputs of the executed
  notebook (``make notebooks``);
- every written answer (cell tagged ``answer``): its question and its worked text, the
  key points to look for.

Nothing is executed: the notebooks' saved outputs are read (nbval proves they are what
a fresh run prints). The source notebooks are only read. The file is written through
:mod:`lqe_helpers.authoring.output_folder` (atomically, into a folder the tool owns).
"""

from __future__ import annotations

from lqe_helpers.authoring.command_line import interrupt_exits_quietly

with interrupt_exits_quietly(__name__):  # Ctrl-C while importing: one line
    import argparse
    import inspect
    import re
    from collections.abc import Sequence
    from dataclasses import dataclass
    from pathlib import Path

    import nbformat

    from lqe_helpers.authoring.command_line import CommandLineParser, run_command
    from lqe_helpers.authoring.errors import shown
    from lqe_helpers.authoring.notebook_io import read_notebook, source_notebooks
    from lqe_helpers.authoring.output_folder import build_output_folder
    from lqe_helpers.authoring.points import CHECK_NAME, graded_cells, is_check_cell
    from lqe_helpers.authoring.task_cells import (
        ANSWER_TAG,
        CHECK_CALL,
        GOING_FURTHER,
        SOLUTION_TAG,
        answer_headings,
        cell_place,
        cell_tags,
        check_cell_tags,
        task_instruction,
    )

#: Name of the tool in the output folder's manifest.
TOOL_NAME = "marking_guide"
#: The file written in the output folder.
GUIDE_NAME = "marking-guide.md"
#: Marks of Tutorial 5's questions (the fallback when a notebook's metadata has none).
QUESTION_MARKS = {"a": 15, "b": 15, "c": 25, "d": 15, "e": 30}
#: Question of each notebook by its number (the fallback when its metadata has none).
NOTEBOOK_QUESTIONS = {"00": "background", "01": "a", "02": "b", "03": "c", "04": "d",
                      "05": "e", "06": "bonus"}
#: A tolerance constant named in a check's docstring (``:data:`MSE_RTOL```).
TOLERANCE_CONSTANT = re.compile(r":data:`(\w*TOL\w*)`")
#: A tolerance stated in words in a check's docstring ("relative tolerance 1e-6").
TOLERANCE_PHRASE = re.compile(r"(?:(?:relative|absolute) )?tolerance [^.;:()]*\d[^.;:()]*",
                              re.IGNORECASE)


@dataclass(frozen=True)
class Task:
    """A task of a worked notebook, as the guide shows it.

    Attributes
    ----------
    place : str
        Notebook, cell index and first line.
    instruction : str
        The ``# Task:`` comment block, without the comment marks.
    core : bool
        Whether it comes before ``## Going further``.
    check : str or None
        The source of the check cell right after it, if any.
    tolerance : str or None
        The tolerance that check states.
    check_printed : str
        What the check printed in the worked notebook.
    expected : list of str
        The worked solution's outputs, as Markdown blocks.
    """

    place: str
    instruction: str
    core: bool
    check: str | None
    tolerance: str | None
    check_printed: str
    expected: list[str]
    points: float = 0.0


@dataclass(frozen=True)
class Answer:
    """A written answer of a worked notebook: its question (heading) and its text."""

    place: str
    heading: str
    text: str
    core: bool
    points: float = 0.0


@dataclass(frozen=True)
class NotebookGuide:
    """What the guide says about one notebook."""

    name: str
    question: str
    marks: int
    core_minutes: int | None
    items: list[Task | Answer]


def question_and_marks(notebook: nbformat.NotebookNode, name: str) -> tuple[str, int]:
    """The tutorial question a notebook answers and its marks.

    Parameters
    ----------
    notebook : nbformat.NotebookNode
        The worked notebook.
    name : str
        Its file name (``01_vision_only.ipynb``); its first two characters pick the
        fallback question.

    Returns
    -------
    tuple of (str, int)
        The question ("a"–"e", "background", "bonus") and its marks (0 outside a–e).

    Raises
    ------
    ValueError
        If the notebook's ``lqe`` metadata is not a mapping or gives marks other than
        the tutorial's for its question, or neither the metadata nor the file name
        says which question.
    """
    meta = notebook.metadata.get("lqe", {})
    if not isinstance(meta, dict):
        raise ValueError(f"{name}: its metadata 'lqe' must be a mapping, such as "
                         f'{{"question": "a", "marks": 15, "core_minutes": 45}}, got '
                         f"{type(meta).__name__} {shown(repr(meta)[:60])}")
    question = meta.get("question", NOTEBOOK_QUESTIONS.get(name[:2]))
    if question is None:
        raise ValueError(f"{name}: no question in its metadata 'lqe' and none known for its "
                         f"number; set metadata lqe.question to one of a–e, background, bonus")
    expected = QUESTION_MARKS.get(question, 0)
    marks = meta.get("marks", expected)
    if marks != expected:
        raise ValueError(f"{name}: metadata lqe.marks is {marks!r} for question {question!r}, "
                         f"but the tutorial gives it {expected}")
    return question, marks


def check_tolerance(call: str) -> str:
    """The tolerance a check states, from :mod:`lqe_helpers.checks`.

    Parameters
    ----------
    call : str
        The check cell's source, e.g. ``checks.check_steady_state(forecast, coverage)``.

    Returns
    -------
    str
        Each tolerance constant the check's docstring names, with its value
        (``relative 1e-09 (checks.FUNCTION_RTOL)``); else the tolerances its docstring
        states in words ("relative tolerance 1e-6"); else a note that it states none.

    Raises
    ------
    ValueError
        If the cell calls no ``checks.check_…`` function, or one that
        :mod:`lqe_helpers.checks` does not define.
    """
    from lqe_helpers import checks  # only when a guide is built

    match = CHECK_NAME.search(call)
    if match is None:
        raise ValueError(f"a check cell must call {CHECK_CALL}…(…), got {call!r}")
    function = getattr(checks, match.group(1), None)
    if not callable(function):
        raise ValueError(f"the check cell calls checks.{match.group(1)}, which "
                         f"lqe_helpers.checks does not define")
    doc = inspect.getdoc(function) or ""
    parts = []
    for constant in dict.fromkeys(TOLERANCE_CONSTANT.findall(doc)):
        value = getattr(checks, constant, None)
        kind = ("relative" if "RTOL" in constant else "absolute" if "ATOL" in constant
                else "tolerance")
        parts.append(f"{kind} {value:g} (`checks.{constant}`)" if isinstance(value, float | int)
                     else f"`checks.{constant}`")
    if parts:
        return "; ".join(parts)
    stated = TOLERANCE_PHRASE.findall(" ".join(doc.split()))
    return "; ".join(phrase.strip() for phrase in stated) or "none stated in its docstring"


def output_blocks(cell: nbformat.NotebookNode, where: str) -> list[str]:
    """A code cell's saved outputs as Markdown: printed text fenced, tables as they are.

    Raises
    ------
    ValueError
        If the cell saved an error (the worked notebook is broken).
    """
    blocks = []
    for output in cell.get("outputs", []):
        if output.output_type == "error":
            raise ValueError(f"{where} saved an error ({output.ename}: {output.evalue}); "
                             f"fix the worked notebook and run `make notebooks`")
        if output.output_type == "stream":
            blocks.append(f"```text\n{output.text.rstrip()}\n```")
            continue
        data = output.get("data", {})
        if "text/markdown" in data:
            blocks.append(data["text/markdown"].strip())
        elif "image/png" in data:
            alt = output.get("metadata", {}).get("image/png", {}).get("alt")
            blocks.append(f"*Figure:* {alt or '(shown without a description)'}")
        elif "text/plain" in data:
            blocks.append(f"```text\n{data['text/plain'].rstrip()}\n```")
    return blocks


def notebook_guide(notebook: nbformat.NotebookNode, name: str) -> NotebookGuide:
    """What the guide says about one worked notebook (see the module docstring).

    Raises
    ------
    ValueError
        If the notebook was never executed (no expected values), a cell breaks the tag
        convention (a misspelt ``solution`` tag would drop its task from the guide), a
        cell saved an error, a check cell calls an unknown check, or its marks are wrong.
    """
    question, marks = question_and_marks(notebook, name)
    cells = notebook.cells
    if not any(cell.get("execution_count") for cell in cells if cell.cell_type == "code"):
        raise ValueError(f"{name} has not been executed, so its expected values are unknown; "
                         f"run `make notebooks` first")
    items: list[Task | Answer] = []
    core = True
    points = {cell.index - (cell.kind == "check"): cell.points
              for cell in graded_cells(notebook, marks) if cell.kind != "task"}
    for index, cell in enumerate(cells):
        tags = cell_tags(cell)
        where = cell_place(name, index, cell)
        check_cell_tags(cell, where)  # a misspelt tag would drop a task from the guide
        if cell.cell_type == "markdown" and cell.source.lstrip().startswith(GOING_FURTHER):
            core = False
        if SOLUTION_TAG in tags:
            instruction = " ".join(line.lstrip("#").strip()
                                   for line in task_instruction(cell.source))
            after = cells[index + 1] if index + 1 < len(cells) else None
            check = after.source.strip() if is_check_cell(after) else None
            printed = "".join(output.get("text", "") for output in after.get("outputs", [])
                              ).strip() if check else ""
            items.append(Task(where, instruction, core, check,
                              check_tolerance(check) if check else None, printed,
                              output_blocks(cell, where), points.get(index, 0.0)))
        elif ANSWER_TAG in tags:
            headings = answer_headings(cell.source)
            body = "\n".join(line for line in cell.source.splitlines()
                             if line.rstrip() not in headings).strip()
            heading = " ".join(line.lstrip("#").strip() for line in headings)
            items.append(Answer(where, heading, body, core, points.get(index, 0.0)))
    meta = notebook.metadata.get("lqe", {})
    return NotebookGuide(name, question, marks, meta.get("core_minutes"), items)


def _question_label(question: str) -> str:
    return f"({question})" if question in QUESTION_MARKS else question


def render(guides: Sequence[NotebookGuide], source: str = "notebooks") -> str:
    """The marking guide as Markdown."""
    total = sum(guide.marks for guide in guides)
    lines = [
        "# Marking guide: Tutorial 5, the Linear Quadratic Estimator",
        "",
        "> **For instructors only: do not hand out.** It holds the worked answers. Built by "
        f"`make student` from the worked notebooks in `{source}/` (their saved outputs); "
        "the student pack does not contain it.",
        "",
        "Marks are the tutorial's, per question. Each question's notebook lists its tasks "
        "(what the student writes) with the check that follows each task: a check that "
        "passes prints a line starting with ✓, so a student's notebook that ran to the end "
        "with every check passing has the code of the core path right. The written answers "
        "(the student's *Your answer* cells) carry the judgement; their worked text below "
        "gives the points to look for.",
        "",
        "Points (the two grading routes, docs/instructors.md): on the core path, 40 % of a "
        "question's marks go to its written answers (marked by hand), the rest is shared "
        "equally by its checks (automatic: a check earns its points when it runs without "
        "raising). Going further, notebook 00 and the bonus 06 carry no points.",
        "",
        "| Question | Marks | Notebook | Core time | Core tasks (with a check) | Written answers |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for guide in guides:
        tasks = [item for item in guide.items if isinstance(item, Task) and item.core]
        answers = [item for item in guide.items if isinstance(item, Answer)]
        minutes = f"{guide.core_minutes} min" if guide.core_minutes else "–"
        lines.append(f"| {_question_label(guide.question)} | {guide.marks} | `{guide.name}` | "
                     f"{minutes} | {len(tasks)} ({sum(t.check is not None for t in tasks)}) | "
                     f"{len(answers)} |")
    lines += [f"| **Total** | **{total}** | | | | |", ""]
    for guide in guides:
        lines += [f"## {_question_label(guide.question)}, {guide.marks} marks: `{guide.name}`",
                  ""]
        part = None
        for item in guide.items:
            if item.core != part:
                part = item.core
                lines += ["### Core" if part else "### Going further (optional, no marks)", ""]
            lines += _render_item(item)
    return "\n".join(lines).rstrip() + "\n"


def _render_item(item: Task | Answer) -> list[str]:
    if isinstance(item, Answer):
        quoted = "\n".join(f"> {line}".rstrip() for line in item.text.splitlines())
        return [f"#### Written answer: {item.heading or '(no heading)'}", "",
                f"*{item.place}.* Points: {item.points:g}, marked by hand. Key points of the "
                f"worked answer:", "", quoted, ""]
    lines = [f"#### Task: {item.instruction.removeprefix('Task:').strip()}", "",
             f"*{item.place}.*", ""]
    if item.check:
        lines += [f"- **Check:** `{item.check}`", f"- **Tolerance:** {item.tolerance}",
                  f"- **Points:** {item.points:g} (automatic)"]
        if item.check_printed:
            lines.append(f"- **The check printed:** {item.check_printed}")
    else:
        lines.append("- **Check:** none follows this task (mark it from the expected values)")
    lines += ["- **Expected (the worked solution's output):**" if item.expected
              else "- **Expected:** the worked solution prints nothing", ""]
    for block in item.expected:
        lines += [block, ""]
    return lines


def build_marking_guide(source_dir: Path, out_dir: Path) -> Path:
    """Write ``marking-guide.md`` for the worked notebooks of ``source_dir`` into ``out_dir``.

    Parameters
    ----------
    source_dir : Path
        Folder of the worked, executed notebooks (read only).
    out_dir : Path
        Folder for the guide (created if needed; the tool replaces only what it wrote
        there, see :func:`lqe_helpers.authoring.output_folder.build_output_folder`).

    Returns
    -------
    Path
        The written guide.

    Raises
    ------
    ValueError
        If a notebook is unusable for the guide (:func:`notebook_guide`) or the folders
        are (the message says which).
    """
    source_dir = Path(source_dir)
    paths = source_notebooks(source_dir)

    def guide() -> dict[str, str]:
        guides = [notebook_guide(read_notebook(path), path.name) for path in paths]
        return {GUIDE_NAME: render(guides, source_dir.as_posix())}

    [written] = build_output_folder(out_dir, [GUIDE_NAME], guide, tool=TOOL_NAME,
                                    sources=[source_dir])
    return written


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: build the marking guide and print its path."""
    parser = CommandLineParser(prog="python -m lqe_helpers.authoring.marking_guide",
                               description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, default=Path("notebooks"),
                        help="folder of the worked, executed notebooks (default: notebooks)")
    parser.add_argument("--out", type=Path, default=Path("build/marking-guide"),
                        help="folder for marking-guide.md (default: build/marking-guide)")

    def command(args: argparse.Namespace) -> int:
        print(shown(build_marking_guide(args.source, args.out)))
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
