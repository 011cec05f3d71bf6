"""Execute notebooks top to bottom in a fresh kernel and save them, ready to commit.

``python -m lqe_helpers.authoring.notebook_runner notebooks/*.ipynb`` (or ``make notebooks``).
The saved notebooks carry outputs but no widget state and no execution timings,
so a re-run with unchanged code gives a byte-identical file.

Every notebook is read and checked first, then every one is executed, and only when
all have run to the end are they saved, all together and atomically (each to a
temporary file beside it, then moved into place; if one move fails the others are
undone). So a failure anywhere (a bad file, a cell that raises, a cell past its time
limit, a kernel that dies, a full disk) leaves every notebook byte-identical.
"""

from __future__ import annotations

import argparse
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

from lqe_helpers.authoring.command_line import CommandLineParser, fail, run_command
from lqe_helpers.authoring.errors import NotebookFileError, ToolError, strip_colour
from lqe_helpers.authoring.files import atomic_write_many, refuse_symlink
from lqe_helpers.authoring.notebook_io import notebook_bytes, read_notebook

__all__ = ["CELL_TIMEOUT", "WIDGET_VIEW_MIMETYPE", "NotebookRunError", "execute_notebook",
           "fail", "main", "positive_seconds", "run_notebooks"]

#: Default for the seconds one cell may run before the run is abandoned (``--timeout``).
CELL_TIMEOUT = 300
#: Output mimetype of a displayed ipywidget.
WIDGET_VIEW_MIMETYPE = "application/vnd.jupyter.widget-view+json"


class NotebookRunError(ToolError, RuntimeError):
    """A notebook did not run to its end: a cell raised or timed out, or the kernel died.

    The first line of the message names the notebook, the cell and what happened; the
    cell's traceback, if any, follows on the next lines.
    """


def _cell_label(notebook: nbformat.NotebookNode, index: int | None) -> str:
    """``"cell N (first line of its source)"``, or ``"a cell"`` if unknown."""
    if index is None or not 0 <= index < len(notebook.cells):
        return "a cell"
    first = next((line.strip() for line in notebook.cells[index].source.splitlines()
                  if line.strip()), "")
    return f"cell {index}" + (f" ({first[:60]})" if first else "")


def execute_notebook(path: Path | str, timeout: float = CELL_TIMEOUT,
                     kernel_name: str = "python3", *,
                     allow_errors: bool = False) -> nbformat.NotebookNode:
    """Run every cell of the notebook at ``path`` in a new kernel; return the result.

    Widget state is not stored (it would break across ipywidgets versions), timings
    are not recorded, consecutive pieces of one stream (stdout, stderr) are merged
    into one output, and the kernel's working directory is the notebook's folder.

    Parameters
    ----------
    path : Path or str
        The notebook (read only; the result is returned, not written).
    timeout : float
        Seconds one cell may run (> 0).
    kernel_name : str
        Kernel to start.
    allow_errors : bool
        Keep going after a cell raises: its error (with the traceback) is left in
        that cell's outputs. By default the first error stops the run.

    Raises
    ------
    NotebookFileError
        If ``path`` is missing or not a valid notebook.
    NotebookRunError
        If a cell raises (not tagged ``raises-exception``, and ``allow_errors`` is
        false), a cell runs longer than ``timeout`` seconds, or the kernel dies.
    ValueError
        If ``timeout`` is not a positive number of seconds.
    """
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not timeout > 0:
        raise ValueError(f"timeout must be a number of seconds > 0, got {timeout!r}")
    path = Path(path)
    notebook = read_notebook(path)
    current: list[int] = []
    client = NotebookClient(
        notebook, timeout=timeout, kernel_name=kernel_name,
        resources={"metadata": {"path": str(path.parent.resolve())}},
        store_widget_state=False, record_timing=False, allow_errors=allow_errors,
        # One output per stream: how the kernel happened to chunk its output must not
        # make two runs of the same notebook differ.
        coalesce_streams=True,
        on_cell_start=lambda cell, cell_index: current.append(cell_index),
    )
    # The kernel process's own stderr (start-up notices, a crash report) is kept aside
    # and shown only after the one-line message of a failed run (with --verbose).
    with tempfile.TemporaryFile() as kernel_stderr:
        try:
            client.execute(stderr=kernel_stderr.fileno())
        except (CellTimeoutError, DeadKernelError, CellExecutionError) as error:
            kernel_stderr.seek(0)
            log = kernel_stderr.read().decode("utf-8", "replace").strip()
            raise _run_error(path, notebook, current, timeout, error, log) from error
    notebook.metadata.pop("widgets", None)
    _stabilise_widget_ids(notebook)
    return notebook


def _run_error(path: Path, notebook: nbformat.NotebookNode, started: list[int], timeout: float,
               error: Exception, kernel_log: str) -> NotebookRunError:
    """The :class:`NotebookRunError` for a run stopped by ``error``.

    Its first line names the notebook, the cell (the last of ``started``) and what
    happened; the cell's traceback and the kernel process's own output follow.
    """
    where = _cell_label(notebook, started[-1] if started else None)
    if isinstance(error, CellTimeoutError):
        first = (f"{path}: {where} ran longer than the time limit of {timeout:g} s per cell "
                 f"(--timeout)")
    elif isinstance(error, DeadKernelError):
        first = f"{path}: the kernel died while running {where}"
    else:
        first = f"{path}: {where} raised {error.ename}: {error.evalue}"
    details = [strip_colour(error.traceback).strip()] if isinstance(error, CellExecutionError) \
        else []
    if kernel_log:
        details.append(f"The kernel's own output:\n{kernel_log}")
    return NotebookRunError("\n".join([first, *details]))


def _stabilise_widget_ids(notebook: nbformat.NotebookNode) -> None:
    """Replace the random id of each saved widget view with one derived from its cell.

    The id only names a widget model inside a live kernel session; saved to disk it
    points at nothing, and a fresh random value on every run would make re-executed
    notebooks differ for no reason.
    """
    for index, cell in enumerate(notebook.cells):
        for output in cell.get("outputs", []):
            view = output.get("data", {}).get(WIDGET_VIEW_MIMETYPE)
            if view is not None:
                view["model_id"] = f"saved-output-of-cell-{index}"


def _check_paths(paths: Sequence[Path]) -> list[Path]:
    """The notebooks to run (duplicates of one file dropped), after checking every path.

    Raises
    ------
    NotebookFileError
        Naming every path that is not an existing ``.ipynb`` file, or the first one
        that is a symbolic link or not a valid notebook.
    """
    bad = [str(path) for path in paths if path.suffix != ".ipynb" or not path.is_file()]
    if bad:
        raise NotebookFileError(f"notebooks must be existing .ipynb files, got {', '.join(bad)}")
    unique: dict[str, Path] = {}
    for path in paths:
        refuse_symlink(path)
        read_notebook(path)
        unique.setdefault(os.path.normcase(os.path.realpath(path)), path)
    return list(unique.values())


def run_notebooks(paths: Sequence[Path | str], *, timeout: float = CELL_TIMEOUT,
                  kernel_name: str = "python3", log: bool = True) -> list[Path]:
    """Execute each notebook and save it in place, all or none.

    Every path is checked, then every notebook executed; only if all run to the end
    are they saved, together and atomically (:func:`~lqe_helpers.authoring.files.
    atomic_write_many`). A notebook whose file would not change is not rewritten.

    Parameters
    ----------
    paths : sequence of Path or str
        The notebooks (``.ipynb`` files; not symbolic links).
    timeout : float
        Seconds one cell may run.
    kernel_name : str
        Kernel to start for each notebook.
    log : bool
        Print ``executing <path>`` before each run.

    Returns
    -------
    list of Path
        The notebooks whose file changed.

    Raises
    ------
    NotebookFileError, NotebookRunError, OSError
        As :func:`execute_notebook` and :func:`atomic_write_many`; no file is changed.
    """
    checked = _check_paths([Path(path) for path in paths])
    results: dict[Path, bytes] = {}
    for path in checked:
        if log:
            print(f"executing {path}", flush=True)
        content = notebook_bytes(execute_notebook(path, timeout, kernel_name))
        if path.read_bytes() != content:
            results[path] = content
        elif log:
            print(f"unchanged {path} (not rewritten)", flush=True)
    atomic_write_many(results)
    return list(results)


def positive_seconds(text: str) -> float:
    """``--timeout``'s type: a finite number of seconds > 0."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a number of seconds > 0, got {text!r}")
    return value


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: execute the notebooks named, then save them all (or none)."""
    parser = CommandLineParser(
        prog="python -m lqe_helpers.authoring.notebook_runner",
        description="Execute notebooks top to bottom in a fresh kernel each; once every one "
                    "has run to the end, save them all in place (atomically). Any failure "
                    "changes no file.")
    parser.add_argument("notebooks", nargs="+", type=Path, metavar="NOTEBOOK",
                        help=".ipynb file to execute and save")
    parser.add_argument("--timeout", type=positive_seconds, default=CELL_TIMEOUT,
                        metavar="SECONDS",
                        help=f"seconds one cell may run before the run stops "
                             f"(default: {CELL_TIMEOUT})")

    def command(args: argparse.Namespace) -> int:
        for path in run_notebooks(args.notebooks, timeout=args.timeout):
            print(f"saved {path}")
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
