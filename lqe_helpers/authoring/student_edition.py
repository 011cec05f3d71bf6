"""Build the student edition: the notebooks with their worked solutions taken out.

``python -m lqe_helpers.authoring.student_edition [--source notebooks] [--out build/student]``
(or ``make student``) writes one ``.ipynb`` per source notebook into the output folder.

The source notebooks mark what is a solution with cell tags (one convention for the
whole pack):

``solution``
    A code cell holding a worked answer. Its first lines are comments, the first of
    which starts with ``# Task:``; that leading comment block is the instruction. In
    the student edition the cell keeps only those comment lines, followed by
    ``raise NotImplementedError(...)``, and its tag becomes ``task``.
``answer``
    A markdown cell holding a written answer. In the student edition it becomes an
    answer prompt ("**Your answer:** ...") tagged ``answer-prompt``; headings at the
    top of the cell are kept, the rest of its text is not.
``explorer``
    A code cell that displays an interactive explorer. It is self-contained and kept
    as it is, so the sliders work in the student edition too.

Every output and execution count is cleared, and notebook metadata other than the
kernel and language (widget state included) is dropped. The source notebooks are
only read, never written. Any other ``*.ipynb`` file directly in the output folder
(the edition of a notebook since renamed or removed) is deleted, so the folder holds
exactly the current edition; nothing else there is touched.

A source notebook with no ``solution`` cell stops the build: its student edition
would hand out every worked answer as it stands. ``--allow-without-solutions``
builds it anyway, with a warning.
"""

from __future__ import annotations

import argparse
import copy
import sys
import warnings
from collections.abc import Collection, Sequence
from pathlib import Path
from typing import Any

import nbformat
from nbconvert.exporters import NotebookExporter
from nbconvert.preprocessors import (
    ClearMetadataPreprocessor,
    ClearOutputPreprocessor,
    Preprocessor,
)
from traitlets import Unicode

from lqe_helpers.authoring.notebook_runner import fail

#: Tag of a code cell holding a worked solution (source notebooks).
SOLUTION_TAG = "solution"
#: Tag of a markdown cell holding a written answer (source notebooks).
ANSWER_TAG = "answer"
#: Tag of a code cell showing an interactive explorer (kept in the student edition).
EXPLORER_TAG = "explorer"
#: Tag of the stub that replaces a solution cell (student edition).
TASK_TAG = "task"
#: Tag of the prompt that replaces an answer cell (student edition).
ANSWER_PROMPT_TAG = "answer-prompt"
#: Tag of the note on how to use the student edition, inserted after the title cell.
NOTE_TAG = "student-note"

#: How the instruction at the top of a solution cell starts.
TASK_PREFIX = "# Task:"
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


def stub_source(source: str) -> str:
    """The student-edition stub for a solution cell: its task comment, then a raise."""
    return "\n".join([*task_instruction(source), f'raise NotImplementedError("{STUB_MESSAGE}")'])


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


class StudentEditionPreprocessor(Preprocessor):
    """Turn marked solution cells into stubs and marked answers into prompts.

    Keyed on cell tags: a code cell tagged ``solution`` keeps its leading
    ``# Task:`` comment block followed by ``raise NotImplementedError(...)``; a
    markdown cell tagged ``answer`` becomes an answer prompt (its headings kept).
    Everything else,
    explorer cells included, passes through unchanged. A note on how to use the
    student edition is inserted after the first cell.

    Raises
    ------
    ValueError
        If a tag sits on the wrong kind of cell, an explorer is also marked as a
        solution or answer, or a solution cell lacks its ``# Task:`` line. The
        message names the notebook and the cell.
    """

    solution_tag = Unicode(SOLUTION_TAG, help="Tag of worked-solution code cells.").tag(
        config=True)
    answer_tag = Unicode(ANSWER_TAG, help="Tag of written-answer markdown cells.").tag(
        config=True)
    explorer_tag = Unicode(EXPLORER_TAG, help="Tag of explorer code cells.").tag(config=True)
    task_tag = Unicode(TASK_TAG, help="Tag given to the stubs.").tag(config=True)
    answer_prompt_tag = Unicode(ANSWER_PROMPT_TAG, help="Tag given to the prompts.").tag(
        config=True)

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
        """Stub a solution cell, turn an answer cell into a prompt, keep the rest."""
        tags = _tags(cell)
        is_solution = self.solution_tag in tags
        is_answer = self.answer_tag in tags
        if not (is_solution or is_answer):
            return cell, resources
        where = f"{resources.get('metadata', {}).get('name', 'notebook')}, cell {index}"
        if is_solution and is_answer:
            raise ValueError(f"{where}: a cell cannot be tagged both "
                             f"{self.solution_tag!r} and {self.answer_tag!r}")
        if self.explorer_tag in tags:
            raise ValueError(f"{where}: an {self.explorer_tag!r} cell must not also be "
                             f"tagged {self.solution_tag if is_solution else self.answer_tag!r}")
        if is_solution:
            if cell.cell_type != "code":
                raise ValueError(f"{where}: tag {self.solution_tag!r} is for code cells, "
                                 f"got a {cell.cell_type} cell")
            try:
                cell.source = stub_source(cell.source)
            except ValueError as error:
                raise ValueError(f"{where}: {error}") from None
            new_tag = self.task_tag
        else:
            if cell.cell_type != "markdown":
                raise ValueError(f"{where}: tag {self.answer_tag!r} is for markdown cells, "
                                 f"got a {cell.cell_type} cell")
            cell.source = prompt_source(cell.source)
            cell.pop("attachments", None)
            new_tag = self.answer_prompt_tag
        old = {self.solution_tag, self.answer_tag}
        cell.metadata["tags"] = [new_tag, *(tag for tag in tags if tag not in old)]
        return cell, resources


def student_exporter() -> NotebookExporter:
    """A notebook-to-notebook exporter that produces the student edition."""
    exporter = NotebookExporter()
    exporter.register_preprocessor(ClearOutputPreprocessor(), enabled=True)
    exporter.register_preprocessor(StudentEditionPreprocessor(), enabled=True)
    exporter.register_preprocessor(
        ClearMetadataPreprocessor(
            preserve_nb_metadata_mask={"kernelspec", "language_info"},
            preserve_cell_metadata_mask={"tags"},
        ),
        enabled=True,
    )
    return exporter


def source_notebooks(source_dir: Path) -> list[Path]:
    """The ``*.ipynb`` files directly in ``source_dir``, in name order.

    Raises
    ------
    ValueError
        If ``source_dir`` is not a folder or holds no notebook.
    """
    source_dir = Path(source_dir)
    if not source_dir.is_dir():
        raise ValueError(f"source_dir must be an existing folder, got {source_dir}")
    notebooks = sorted(source_dir.glob("*.ipynb"))
    if not notebooks:
        raise ValueError(f"source_dir must hold at least one .ipynb file, got none in "
                         f"{source_dir}")
    return notebooks


def check_out_dir(source_dir: Path, out_dir: Path) -> None:
    """Refuse an output folder that would overwrite the source notebooks."""
    if Path(out_dir).resolve() == Path(source_dir).resolve():
        raise ValueError(f"out_dir must differ from source_dir, got {out_dir} for both")


def remove_stale(folder: Path, pattern: str, keep: Collection[str] = ()) -> list[Path]:
    """Delete the files directly in ``folder`` that match ``pattern``, except ``keep``.

    Used by the builds to clear what an earlier build wrote (the page or notebook
    of a notebook since renamed) before they write. Only files (and symbolic links)
    matching ``pattern`` go; sub-folders and every other file stay.

    Parameters
    ----------
    folder : Path
        The output folder; nothing happens if it does not exist.
    pattern : str
        Glob pattern of the files the build writes there (``"*.html"``).
    keep : collection of str
        Names of files to leave in place (the ones about to be overwritten anyway).

    Returns
    -------
    list of Path
        The deleted files, in name order.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    stale = [path for path in sorted(folder.glob(pattern))
             if (path.is_file() or path.is_symlink()) and path.name not in keep]
    for path in stale:
        path.unlink()
    return stale


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
    message = (f"{name}: no cell is tagged {SOLUTION_TAG!r}, so its student edition would "
               f"contain every worked answer. Tag the solution cells (see the README), or "
               f"build with --allow-without-solutions to hand it out as it is")
    if not allow_without_solutions:
        raise MissingSolutionsError(message)
    warnings.warn(message, MissingSolutionsWarning, stacklevel=3)


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

    Every notebook is checked before anything is written, so a refused build
    leaves ``out_dir`` as it was. Otherwise every ``*.ipynb`` file directly in
    ``out_dir`` that is not written by this build (left by an earlier build of a
    notebook since renamed or removed) is deleted; other files are left alone.

    Parameters
    ----------
    source_dir : Path
        Folder of the source notebooks (read only).
    out_dir : Path
        Folder for the student notebooks (created if needed); files of the same
        name are overwritten.
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
        If the folders are unusable or a notebook breaks the tag convention.
    """
    source_dir, out_dir = Path(source_dir), Path(out_dir)
    paths = source_notebooks(source_dir)
    check_out_dir(source_dir, out_dir)
    editions = []
    for path in paths:
        notebook = nbformat.read(path, as_version=4)
        check_has_solutions(notebook, path.name,
                            allow_without_solutions=allow_without_solutions)
        editions.append((out_dir / path.name, student_edition(notebook, path.stem)))
    out_dir.mkdir(parents=True, exist_ok=True)
    remove_stale(out_dir, "*.ipynb", keep={target.name for target, _ in editions})
    for target, text in editions:
        target.write_text(text, encoding="utf-8")
    return [target for target, _ in editions]


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: build the student edition and list the files written."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, default=Path("notebooks"),
                        help="folder of the source notebooks (default: notebooks)")
    parser.add_argument("--out", type=Path, default=Path("build/student"),
                        help="folder for the student notebooks (default: build/student); "
                             "any other .ipynb file directly in it is deleted")
    parser.add_argument("--allow-without-solutions", action="store_true",
                        help="build notebooks that have no 'solution' cell (with a warning) "
                             "instead of refusing")
    args = parser.parse_args(argv)
    try:
        written = build_student_edition(args.source, args.out,
                                        allow_without_solutions=args.allow_without_solutions)
    except ValueError as error:
        return fail(error)
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
