"""Build the student edition: the notebooks with their worked solutions taken out.

``python -m lqe_helpers.authoring.student_edition [--source notebooks] [--out build/student]``
(or ``make student``) writes one ``.ipynb`` per source notebook into the output folder.

The source notebooks mark what is a solution with cell tags (one convention for the
whole pack):

``solution``
    A code cell holding a worked answer. Its first lines are comments, the first of
    which starts with ``# Task:``; that leading comment block is the instruction. In
    the student edition the cell keeps those comment lines and the signature (and
    docstring) of every top-level ``def``, whose body becomes
    ``raise NotImplementedError(...)``; any other code becomes one
    ``raise NotImplementedError(...)`` line. Its tag becomes ``task``.
``answer``
    A markdown cell holding a written answer. In the student edition it becomes an
    answer prompt ("**Your answer:** ...") tagged ``answer-prompt``; headings at the
    top of the cell are kept, the rest of its text is not.
``explorer``
    A code cell that displays an interactive explorer, always also tagged
    ``nbval-ignore-output``. It is self-contained and kept as it is, so the sliders
    work in the student edition too.

These four are the only tags a source notebook may carry (:data:`ALLOWED_TAGS`). An
unknown or misspelt tag (``Solution``, ``answers``), an explorer without
``nbval-ignore-output``, or a code cell that starts like a task (``# Task:``) but is not
tagged ``solution`` stops the build with the notebook and the cell named: a silent pass
would hand out a worked answer.

Every output and execution count is cleared, and notebook metadata other than the
kernel, the language and the pack's own ``lqe`` entry (question, marks, core minutes)
is dropped (widget state included). The source notebooks are
only read, never written. The output folder must not be, contain or lie inside the
source folder. It is written all together or not at all, and its manifest
``.lqe-manifest.json`` lists what the build wrote (:mod:`lqe_helpers.authoring.files`): a
rebuild replaces or deletes only those files (the edition of a notebook since renamed
goes), and only while they are unchanged. Any other file there (an instructor's
``my_grading_notes.ipynb``, a hand-edited copy, a symbolic link) is never touched; one in
the way of the build stops it before anything is written.

A source notebook with no ``solution`` cell stops the build: its student edition
would hand out every worked answer as it stands. ``--allow-without-solutions``
builds it anyway, with a warning.
"""

from __future__ import annotations

import argparse
import ast
import copy
import difflib
import io
import re
import tokenize
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import nbformat
from nbconvert.exporters import NotebookExporter
from nbconvert.preprocessors import (
    ClearMetadataPreprocessor,
    ClearOutputPreprocessor,
    Preprocessor,
)

# MANIFEST_NAME and the Output*Error classes are re-exported: where the build records
# what it wrote, and what build_student_edition raises.
from lqe_helpers.authoring.files import (
    MANIFEST_NAME as MANIFEST_NAME,
)
from lqe_helpers.authoring.files import (
    CommandLineParser,
    check_out_dir,
    read_notebook,
    run_command,
    source_notebooks,
    write_output_folder,
)
from lqe_helpers.authoring.files import (
    OutputFolderError as OutputFolderError,
)
from lqe_helpers.authoring.files import (
    OutputWriteError as OutputWriteError,
)

#: Name the student edition records in its output folder's manifest.
TOOL_NAME = "student_edition"

#: Tag of a code cell holding a worked solution (source notebooks).
SOLUTION_TAG = "solution"
#: Tag of a markdown cell holding a written answer (source notebooks).
ANSWER_TAG = "answer"
#: Tag of a code cell showing an interactive explorer (kept in the student edition).
EXPLORER_TAG = "explorer"
#: nbval's tag for a cell whose output is not compared (every explorer carries it).
IGNORE_OUTPUT_TAG = "nbval-ignore-output"
#: The only tags a source notebook may carry; any other is an error in the build.
ALLOWED_TAGS = frozenset({SOLUTION_TAG, ANSWER_TAG, EXPLORER_TAG, IGNORE_OUTPUT_TAG})
#: Tag of the stub that replaces a solution cell (student edition).
TASK_TAG = "task"
#: Tag of the prompt that replaces an answer cell (student edition).
ANSWER_PROMPT_TAG = "answer-prompt"
#: Tag of the note on how to use the student edition, inserted after the title cell.
NOTE_TAG = "student-note"
#: The tags a student notebook carries (what the student pack's tests allow).
STUDENT_TAGS = frozenset({TASK_TAG, ANSWER_PROMPT_TAG, NOTE_TAG, EXPLORER_TAG,
                          IGNORE_OUTPUT_TAG})

#: How the instruction at the top of a solution cell starts.
TASK_PREFIX = "# Task:"
#: A first line that looks like a task instruction, however it is spelt or spaced.
TASK_LIKE = re.compile(r"#\s*task\s*:", re.IGNORECASE)
#: The heading that ends the core path of a notebook (what follows is optional).
GOING_FURTHER = "## Going further"
#: How the call in the check cell after a core task starts.
CHECK_CALL = "checks.check_"
#: What a stub raises.
STUB_MESSAGE = "Replace this line with your code for the task described above."
#: What an answer cell becomes.
ANSWER_PROMPT = (
    "**Your answer:** *Replace this line with your answer, backed by the numbers "
    "and figures your code produced.*"
)
#: Markdown inserted after the first cell of every student notebook.
STUDENT_NOTE = (
    "> **Student edition.** Cells starting with `# Task:` are yours to write: replace "
    "their `raise NotImplementedError(...)` line with code that does what the comment "
    "asks, and run the notebook from the top. Write your answers where it says "
    "**Your answer**. The interactive explorers work at any time: run the first code "
    "cell, then the explorer's cell."
)


class MissingSolutionsError(ValueError):
    """A source notebook has no ``solution`` cell, so it has nothing to take out."""


class MissingSolutionsWarning(UserWarning):
    """A student notebook was built from a source with no ``solution`` cell."""


def task_instruction(source: str) -> list[str]:
    """The instruction lines at the top of a solution cell.

    Parameters
    ----------
    source : str
        The cell's source code.

    Returns
    -------
    list of str
        The leading block of comment lines (up to the first line that is not a
        comment), the first of which starts with ``# Task:``.

    Raises
    ------
    ValueError
        If the cell does not start with a ``# Task:`` line.
    """
    lines = source.splitlines()
    if not lines or not lines[0].startswith(TASK_PREFIX):
        first = lines[0] if lines else ""
        raise ValueError(
            f"a solution cell must start with a '{TASK_PREFIX} ...' comment line, "
            f"got {first!r}"
        )
    block = []
    for line in lines:
        if not line.lstrip().startswith("#"):
            break
        block.append(line.rstrip())
    return block


def _header_end(lines: list[str], node: ast.FunctionDef | ast.AsyncFunctionDef) -> tuple[int, int]:
    """Line (1-based) and column just after the ``:`` that ends a ``def`` header."""
    text = "\n".join(lines[node.lineno - 1:]) + "\n"
    depth, started = 0, False
    for token in tokenize.generate_tokens(io.StringIO(text).readline):
        if not started:
            started = token.type == tokenize.NAME and token.string == "def"
        elif token.type == tokenize.OP and token.string in "([{":
            depth += 1
        elif token.type == tokenize.OP and token.string in ")]}":
            depth -= 1
        elif token.type == tokenize.OP and token.string == ":" and depth == 0:
            return node.lineno + token.end[0] - 1, token.end[1]
    raise ValueError(f"no ':' ends the header of def {node.name}")  # unreachable for valid code


def function_stub(lines: list[str], node: ast.FunctionDef | ast.AsyncFunctionDef) -> list[str]:
    """A top-level function with its body replaced by ``raise NotImplementedError(...)``.

    Parameters
    ----------
    lines : list of str
        The lines of the code the function was parsed from.
    node : ast.FunctionDef or ast.AsyncFunctionDef
        The function.

    Returns
    -------
    list of str
        Its decorators and signature exactly as written, its docstring (if it has one),
        then the raise. Comments and code of the body are dropped.
    """
    start = min([node.lineno, *(decorator.lineno for decorator in node.decorator_list)])
    end_line, end_column = _header_end(lines, node)
    stub = [*lines[start - 1:end_line - 1], lines[end_line - 1][:end_column]]
    first = node.body[0]
    on_own_line = first.lineno > end_line
    indent = " " * (first.col_offset if on_own_line else node.col_offset + 4)
    if ast.get_docstring(node, clean=False) is not None:  # as written, nothing after it
        stub.append(indent + ast.get_source_segment("\n".join(lines), first))
    stub.append(f'{indent}raise NotImplementedError("{STUB_MESSAGE}")')
    return stub


def stub_source(source: str) -> str:
    """The student-edition stub for a solution cell.

    Parameters
    ----------
    source : str
        The solution cell's source: a ``# Task:`` comment block, then the worked code.

    Returns
    -------
    str
        The comment block; then each top-level function's signature (and docstring)
        with its body replaced by ``raise NotImplementedError(...)``; then, if the cell
        holds any other code (or cannot be parsed), one ``raise NotImplementedError(...)``
        line in its place. So a cell that only defines functions runs (the check after
        it reports them "not written yet"); any other stub stops Run All at itself.

    Raises
    ------
    ValueError
        If the cell does not start with a ``# Task:`` line.
    """
    instruction = task_instruction(source)
    lines = source.splitlines()[len(instruction):]
    try:
        body = ast.parse("\n".join(lines)).body
    except SyntaxError:  # IPython syntax (magics) or a broken cell: stub it whole
        body = [ast.Pass()]
    parts = [function_stub(lines, node) for node in body
             if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)]
    if len(parts) < len(body) or not parts:
        parts.append([f'raise NotImplementedError("{STUB_MESSAGE}")'])
    blocks = ["\n".join(part) for part in parts]
    return "\n".join(instruction) + "\n" + "\n\n\n".join(blocks)


def answer_headings(source: str) -> list[str]:
    """The markdown headings at the top of an answer cell (kept in its prompt).

    Parameters
    ----------
    source : str
        The answer cell's markdown.

    Returns
    -------
    list of str
        The heading lines (``#`` ...) before the first line of other text; blank
        lines between them are skipped.
    """
    headings = []
    for line in source.splitlines():
        if line.startswith("#"):
            headings.append(line.rstrip())
        elif line.strip():
            break
    return headings


def prompt_source(source: str) -> str:
    """The student-edition prompt for an answer cell: its headings, then the prompt."""
    return "\n\n".join([*answer_headings(source), ANSWER_PROMPT])


def _tags(cell: nbformat.NotebookNode) -> list[str]:
    return list(cell.get("metadata", {}).get("tags", []))


def cell_place(name: str, index: int, cell: nbformat.NotebookNode) -> str:
    """Where a cell is, for messages: notebook, cell index and the cell's first line."""
    lines = cell.source.strip().splitlines()
    first = lines[0] if lines else ""
    return f"{name}, cell {index} ({first[:60]!r})"


def check_cell_tags(cell: nbformat.NotebookNode, where: str) -> None:
    """Refuse a cell that breaks the tag convention of the source notebooks.

    Parameters
    ----------
    cell : nbformat.NotebookNode
        A cell of a source notebook.
    where : str
        The cell's place (:func:`cell_place`), put at the start of the message.

    Raises
    ------
    ValueError
        If the cell carries a tag outside :data:`ALLOWED_TAGS` (the message suggests
        the nearest allowed one), a tag on the wrong kind of cell, ``solution`` and
        ``answer`` together, an explorer also marked as a solution or an answer or
        without ``nbval-ignore-output``, or if it is a code cell that starts like a
        task (``# Task:``) without the ``solution`` tag.
    """
    tags = _tags(cell)
    for tag in tags:
        if tag not in ALLOWED_TAGS:
            near = difflib.get_close_matches(tag.lower(), sorted(ALLOWED_TAGS), n=1, cutoff=0.6)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            raise ValueError(f"{where}: unknown tag {tag!r}{hint}; the allowed tags are "
                             f"{', '.join(sorted(ALLOWED_TAGS))}")
    is_solution, is_answer = SOLUTION_TAG in tags, ANSWER_TAG in tags
    if is_solution and is_answer:
        raise ValueError(f"{where}: a cell cannot be tagged both {SOLUTION_TAG!r} and "
                         f"{ANSWER_TAG!r}")
    if EXPLORER_TAG in tags:
        if is_solution or is_answer:
            raise ValueError(f"{where}: an {EXPLORER_TAG!r} cell must not also be tagged "
                             f"{SOLUTION_TAG if is_solution else ANSWER_TAG!r}")
        if cell.cell_type != "code":
            raise ValueError(f"{where}: tag {EXPLORER_TAG!r} is for code cells, got a "
                             f"{cell.cell_type} cell")
        if IGNORE_OUTPUT_TAG not in tags:
            raise ValueError(f"{where}: an {EXPLORER_TAG!r} cell must also be tagged "
                             f"{IGNORE_OUTPUT_TAG!r} (its widget output differs run to run)")
    if is_solution and cell.cell_type != "code":
        raise ValueError(f"{where}: tag {SOLUTION_TAG!r} is for code cells, got a "
                         f"{cell.cell_type} cell")
    if is_answer and cell.cell_type != "markdown":
        raise ValueError(f"{where}: tag {ANSWER_TAG!r} is for markdown cells, got a "
                         f"{cell.cell_type} cell")
    if (cell.cell_type == "code" and not is_solution
            and TASK_LIKE.match(cell.source.lstrip())):
        raise ValueError(f"{where}: starts like a task but is not tagged {SOLUTION_TAG!r}, "
                         f"so its worked code would be handed out; tag it {SOLUTION_TAG!r}")


class StudentEditionPreprocessor(Preprocessor):
    """Turn marked solution cells into stubs and marked answers into prompts.

    Keyed on cell tags (the module constants; every cell is first checked with
    :func:`check_cell_tags`): a code cell tagged ``solution`` becomes its stub
    (:func:`stub_source`), tagged ``task``; a markdown cell tagged ``answer``
    becomes an answer prompt (its headings kept), tagged ``answer-prompt``.
    Everything else, explorer cells included, passes through unchanged. A note on
    how to use the student edition is inserted after the first cell.

    Raises
    ------
    ValueError
        If a cell breaks the tag convention (:func:`check_cell_tags`) or a solution
        cell lacks its ``# Task:`` line. The message names the notebook, the cell's
        index and its first line.
    """

    def preprocess(self, nb: nbformat.NotebookNode,
                   resources: dict[str, Any]) -> tuple[nbformat.NotebookNode, dict[str, Any]]:
        """Transform every cell, then insert the note on how to use the edition."""
        nb, resources = super().preprocess(nb, resources)
        note = nbformat.v4.new_markdown_cell(STUDENT_NOTE, metadata={"tags": [NOTE_TAG]})
        note.id = NOTE_TAG  # a fixed id keeps the output identical from build to build
        nb.cells.insert(min(1, len(nb.cells)), note)
        return nb, resources

    def preprocess_cell(self, cell: nbformat.NotebookNode, resources: dict[str, Any],
                        index: int) -> tuple[nbformat.NotebookNode, dict[str, Any]]:
        """Check the cell's tags; stub a solution, turn an answer into a prompt."""
        where = cell_place(resources.get("metadata", {}).get("name", "notebook"), index, cell)
        check_cell_tags(cell, where)
        tags = _tags(cell)
        if SOLUTION_TAG in tags:
            try:
                cell.source = stub_source(cell.source)
            except ValueError as error:
                raise ValueError(f"{where}: {error}") from None
            new_tag = TASK_TAG
        elif ANSWER_TAG in tags:
            cell.source = prompt_source(cell.source)
            cell.pop("attachments", None)
            new_tag = ANSWER_PROMPT_TAG
        else:
            return cell, resources
        cell.metadata["tags"] = [new_tag, *(tag for tag in tags
                                            if tag not in {SOLUTION_TAG, ANSWER_TAG})]
        return cell, resources


def student_exporter() -> NotebookExporter:
    """A notebook-to-notebook exporter that produces the student edition."""
    exporter = NotebookExporter()
    exporter.register_preprocessor(ClearOutputPreprocessor(), enabled=True)
    exporter.register_preprocessor(StudentEditionPreprocessor(), enabled=True)
    exporter.register_preprocessor(
        ClearMetadataPreprocessor(
            preserve_nb_metadata_mask={"kernelspec", "language_info", "lqe"},
            preserve_cell_metadata_mask={"tags"},
        ),
        enabled=True,
    )
    return exporter


def count_solutions(notebook: nbformat.NotebookNode) -> int:
    """How many cells of ``notebook`` are tagged ``solution``."""
    return sum(SOLUTION_TAG in _tags(cell) for cell in notebook.cells)


def check_has_solutions(notebook: nbformat.NotebookNode, name: str, *,
                        allow_without_solutions: bool = False) -> None:
    """Refuse (or warn about) a source notebook with no ``solution`` cell.

    Without one the student edition would be the source with its outputs cleared:
    every worked answer handed out, and nothing to tell anyone so.

    Parameters
    ----------
    notebook : nbformat.NotebookNode
        The source notebook.
    name : str
        Its name, for the message.
    allow_without_solutions : bool
        Warn (:class:`MissingSolutionsWarning`) instead of raising.

    Raises
    ------
    MissingSolutionsError
        If no cell is tagged ``solution`` and ``allow_without_solutions`` is false.
    """
    if count_solutions(notebook):
        return
    if not allow_without_solutions:
        raise MissingSolutionsError(
            f"{name}: no cell is tagged {SOLUTION_TAG!r}, so its student edition would "
            f"contain every worked answer. Tag the solution cells (see the README), or run "
            f"python -m lqe_helpers.authoring.student_edition --allow-without-solutions to "
            f"hand it out as it is")
    warnings.warn(f"{name}: no cell is tagged {SOLUTION_TAG!r}; built anyway because of "
                  f"--allow-without-solutions, so its student edition contains every worked "
                  f"answer", MissingSolutionsWarning, stacklevel=3)


def student_edition(notebook: nbformat.NotebookNode, name: str = "notebook") -> str:
    """The student edition of one notebook, as the text of an ``.ipynb`` file.

    Parameters
    ----------
    notebook : nbformat.NotebookNode
        The source notebook (not modified).
    name : str
        Its name, used in error messages.

    Returns
    -------
    str
        The student notebook (nbformat 4 JSON).

    Raises
    ------
    ValueError
        If the notebook breaks the tag convention (the message names the cell).
    """
    resources = {"metadata": {"name": name}}
    text, _ = student_exporter().from_notebook_node(copy.deepcopy(notebook), resources)
    return text


def build_student_edition(source_dir: Path, out_dir: Path, *,
                          allow_without_solutions: bool = False) -> list[Path]:
    """Write the student edition of every notebook in ``source_dir`` to ``out_dir``.

    Every notebook is read and transformed before anything is written, and the files
    are written together (:func:`~lqe_helpers.authoring.files.write_output_folder`), so
    a refused or failed build leaves ``out_dir`` as it was. The folder's manifest
    (``.lqe-manifest.json``) lists what the build wrote; a rebuild replaces or deletes
    only those files, and only while unchanged (an edition of a notebook since renamed
    goes). Every other file there is left alone; one in the way stops the build.

    Parameters
    ----------
    source_dir : Path
        Folder of the source notebooks (read only).
    out_dir : Path
        Folder for the student notebooks (created if needed); must not be, contain or
        lie inside ``source_dir``.
    allow_without_solutions : bool
        Build a notebook that has no ``solution`` cell, with a warning, instead of
        refusing the whole build.

    Returns
    -------
    list of Path
        The written notebooks, in name order.

    Raises
    ------
    MissingSolutionsError
        If a notebook has no ``solution`` cell (unless allowed).
    ValueError
        If the source folder is unusable, a source file is not a valid notebook, or a
        notebook breaks the tag convention.
    OutputFolderError
        If ``out_dir`` is a file, overlaps ``source_dir``, or holds a file in the way
        that this tool did not write (or that was changed since, or is a link).
    OutputWriteError
        If writing fails (disk full, read-only folder); ``out_dir`` is as it was.
    """
    source_dir, out_dir = Path(source_dir), Path(out_dir)
    paths = source_notebooks(source_dir)
    check_out_dir(source_dir, out_dir)
    editions: dict[str, str] = {}
    for path in paths:
        notebook = read_notebook(path)
        check_has_solutions(notebook, path.name,
                            allow_without_solutions=allow_without_solutions)
        editions[path.name] = student_edition(notebook, path.stem)
    return write_output_folder(out_dir, editions, tool=TOOL_NAME, source_dir=source_dir)


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: build the student edition and list the files written."""
    parser = CommandLineParser(prog="python -m lqe_helpers.authoring.student_edition",
                               description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, default=Path("notebooks"),
                        help="folder of the source notebooks (default: notebooks)")
    parser.add_argument("--out", type=Path, default=Path("build/student"),
                        help="folder for the student notebooks (default: build/student); a "
                             "rebuild replaces only the files listed in its .lqe-manifest.json")
    parser.add_argument("--allow-without-solutions", action="store_true",
                        help="build notebooks that have no 'solution' cell (with a warning) "
                             "instead of refusing")

    def command(args: argparse.Namespace) -> int:
        for path in build_student_edition(
                args.source, args.out, allow_without_solutions=args.allow_without_solutions):
            print(path)
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
