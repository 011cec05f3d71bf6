"""The cells a source notebook marks for the student edition, and what each becomes.

One convention for the whole pack (see :mod:`lqe_helpers.authoring.student_edition`):
a code cell tagged ``solution`` starts with a ``# Task:`` comment block and becomes a
stub (:func:`stub_source`); a markdown cell tagged ``answer`` becomes a prompt
(:func:`prompt_source`); :func:`check_cell_tags` refuses any cell that breaks the
convention. The marking guide reads the same cells (:mod:`lqe_helpers.authoring.marking_guide`).
"""

from __future__ import annotations

import ast
import difflib
import io
import re
import tokenize

import nbformat

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
#: How the instruction at the top of a solution cell starts.
TASK_PREFIX = "# Task:"
#: A comment line that looks like a task instruction, however it is spelt or spaced.
TASK_LIKE = re.compile(r"#+\s*task\s*:", re.IGNORECASE)
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


def cell_tags(cell: nbformat.NotebookNode) -> list[str]:
    """The tags of ``cell`` (``metadata.tags``; none → ``[]``)."""
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
        without ``nbval-ignore-output``, or if it is a code cell with a task instruction
        on any line (:func:`task_line`) without the ``solution`` tag.
    """
    tags = cell_tags(cell)
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
    line = task_line(cell.source) if cell.cell_type == "code" and not is_solution else None
    if line is not None:
        raise ValueError(f"{where}: holds a task instruction ('# Task:' comment, line {line}) "
                         f"but is not tagged {SOLUTION_TAG!r}, so its worked code would be "
                         f"handed out; tag it {SOLUTION_TAG!r} and put the '# Task:' comment "
                         f"at its top")


def task_line(source: str) -> int | None:
    """The number (from 1) of a code cell's first comment line that reads like a task
    instruction (:data:`TASK_LIKE`: ``# Task:`` in any case, spacing or number of
    ``#``), wherever it is in the cell (after an import line, say); ``None`` if none."""
    return next((number for number, line in enumerate(source.splitlines(), 1)
                 if TASK_LIKE.match(line.strip())), None)
