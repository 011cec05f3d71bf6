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
``nbval-ignore-output``, or a code cell with a ``# Task:`` comment on any line but not
tagged ``solution`` stops the build with the notebook and the cell named: a silent pass
would hand out a worked answer.

Every output and execution count is cleared, and notebook metadata other than the
kernel, the language and the pack's own ``lqe`` entry (question, marks, core minutes)
is dropped (widget state included). The source notebooks are
only read, never written. The output folder must not be, contain or lie inside the
source folder. It is written all together or not at all, and its manifest
``.lqe-manifest.json`` lists what the build wrote (:mod:`lqe_helpers.authoring.output_folder`): a
rebuild replaces or deletes only those files (the edition of a notebook since renamed
goes), and only while they are unchanged. Any other file there (an instructor's
``my_grading_notes.ipynb``, a hand-edited copy, a symbolic link) is never touched; one in
the way of the build stops it before anything is written.

A source notebook with no ``solution`` cell stops the build: its student edition
would hand out every worked answer as it stands. ``--allow-without-solutions``
builds it anyway, with a warning.
"""

from __future__ import annotations

from lqe_helpers.authoring.command_line import interrupt_exits_quietly

with interrupt_exits_quietly(__name__):  # Ctrl-C while importing: one line
    import argparse
    import copy
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

    from lqe_helpers.authoring.command_line import CommandLineParser, run_command
    from lqe_helpers.authoring.errors import shown
    from lqe_helpers.authoring.notebook_io import read_notebook, source_notebooks
    from lqe_helpers.authoring.output_folder import build_output_folder
    from lqe_helpers.authoring.task_cells import (
        ANSWER_PROMPT_TAG,
        ANSWER_TAG,
        EXPLORER_TAG,
        IGNORE_OUTPUT_TAG,
        SOLUTION_TAG,
        TASK_TAG,
        cell_place,
        cell_tags,
        check_cell_tags,
        prompt_source,
        stub_source,
    )

#: Name the student edition records in its output folder's manifest.
TOOL_NAME = "student_edition"

#: Tag of the note on how to use the student edition, inserted after the title cell.
NOTE_TAG = "student-note"
#: The tags a student notebook carries (what the student pack's tests allow).
STUDENT_TAGS = frozenset({TASK_TAG, ANSWER_PROMPT_TAG, NOTE_TAG, EXPLORER_TAG,
                          IGNORE_OUTPUT_TAG})

#: Markdown inserted after the first cell of every student notebook.
STUDENT_NOTE = (
    "> **Student edition.** Cells starting with `# Task:` are yours to write: replace "
    "their `raise NotImplementedError(...)` line with code that does what the comment "
    "asks, and run the notebook from the top. Write your answers where it says "
    "**Your answer**. An explorer runs once the first code cell has run; one that runs "
    "your own function (`my_filter` from notebook 01, `compensate`) shows its figure once "
    "that function passes its check, and until then says what to do. A check judges your "
    "own code: values made by the pack's own function for that task (in the task cell, or "
    "in a cell of yours run before it) are refused, and the message says how to start again."
)


class MissingSolutionsError(ValueError):
    """A source notebook has no ``solution`` cell, so it has nothing to take out."""


class MissingSolutionsWarning(UserWarning):
    """A student notebook was built from a source with no ``solution`` cell."""


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
        tags = cell_tags(cell)
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
    return sum(SOLUTION_TAG in cell_tags(cell) for cell in notebook.cells)


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
    ValueError
        If a cell breaks the tag convention (:func:`check_cell_tags`), checked first: a
        misspelt ``solution`` tag is named as such, not reported as a missing one.
    MissingSolutionsError
        If no cell is tagged ``solution`` and ``allow_without_solutions`` is false.
    """
    for index, cell in enumerate(notebook.cells):
        check_cell_tags(cell, cell_place(name.removesuffix(".ipynb"), index, cell))
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
    are written together (:func:`~lqe_helpers.authoring.output_folder.build_output_folder`), so
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

    def editions() -> dict[str, str]:
        built = {}
        for path in paths:
            notebook = read_notebook(path)
            check_has_solutions(notebook, path.name,
                                allow_without_solutions=allow_without_solutions)
            built[path.name] = student_edition(notebook, path.stem)
        return built

    return build_output_folder(out_dir, [path.name for path in paths], editions,
                               tool=TOOL_NAME, sources=[source_dir])


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
            print(shown(path))
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
