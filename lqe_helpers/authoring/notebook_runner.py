"""Execute notebooks top to bottom in a fresh kernel and save them, ready to commit.

``python -m lqe_helpers.authoring.notebook_runner notebooks/*.ipynb`` (or ``make notebooks``).
The saved notebooks carry outputs but no widget state and no execution timings,
so a re-run with unchanged code gives a byte-identical file.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Sequence
from pathlib import Path

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError

#: Seconds one cell may run before the execution is abandoned.
CELL_TIMEOUT = 300
#: Output mimetype of a displayed ipywidget.
WIDGET_VIEW_MIMETYPE = "application/vnd.jupyter.widget-view+json"

# Terminal colour codes, as IPython puts them in tracebacks.
_ANSI_COLOUR = re.compile(r"\x1b\[[0-9;]*m")


def execute_notebook(path: Path | str, timeout: int = CELL_TIMEOUT,
                     kernel_name: str = "python3", *,
                     allow_errors: bool = False) -> nbformat.NotebookNode:
    """Run every cell of the notebook at ``path`` in a new kernel; return the result.

    Widget state is not stored (it would break across ipywidgets versions), timings
    are not recorded, and the kernel's working directory is the notebook's folder.

    Parameters
    ----------
    path : Path or str
        The notebook (read only; the result is returned, not written).
    timeout : int
        Seconds one cell may run.
    kernel_name : str
        Kernel to start.
    allow_errors : bool
        Keep going after a cell raises: its error (with the traceback) is left in
        that cell's outputs. By default the first error stops the run.

    Raises
    ------
    nbclient.exceptions.CellExecutionError
        If a cell raises (not tagged ``raises-exception``) and ``allow_errors`` is false.
    """
    path = Path(path)
    notebook = nbformat.read(path, as_version=4)
    client = NotebookClient(
        notebook, timeout=timeout, kernel_name=kernel_name,
        resources={"metadata": {"path": str(path.parent.resolve())}},
        store_widget_state=False, record_timing=False, allow_errors=allow_errors,
    )
    client.execute()
    notebook.metadata.pop("widgets", None)
    _stabilise_widget_ids(notebook)
    return notebook


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


def fail(message: object) -> int:
    """Print ``error: <message>`` on stderr; return the exit code of a failed command (1).

    The one way the pack's command lines (this one, ``handouts``,
    ``student_edition``) report bad input or a failed build.
    """
    print(f"error: {message}", file=sys.stderr)
    return 1


def main(argv: Sequence[str] | None = None) -> int:
    """Execute each notebook named on the command line and write it back in place.

    Every path is checked before any notebook runs, so a bad argument rewrites
    nothing. A notebook whose cell raises is not written; the run stops there
    (exit code 1, the traceback on stderr).
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("notebooks", nargs="+", type=Path)
    args = parser.parse_args(argv)
    bad = [str(path) for path in args.notebooks if path.suffix != ".ipynb" or not path.is_file()]
    if bad:
        return fail(f"notebooks must be existing .ipynb files, got {', '.join(bad)}")
    for path in args.notebooks:
        print(f"executing {path}", flush=True)
        try:
            notebook = execute_notebook(path)
        except CellExecutionError as error:
            return fail(f"{path}: {_ANSI_COLOUR.sub('', str(error)).strip()}")
        nbformat.write(notebook, path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
