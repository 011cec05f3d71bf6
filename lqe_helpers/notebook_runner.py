"""Execute notebooks top to bottom in a fresh kernel and save them, ready to commit.

``python -m lqe_helpers.notebook_runner notebooks/*.ipynb`` (or ``make notebooks``).
The saved notebooks carry outputs but no widget state and no execution timings,
so a re-run with unchanged code gives a byte-identical file.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import nbformat
from nbclient import NotebookClient

#: Seconds one cell may run before the execution is abandoned.
CELL_TIMEOUT = 300
#: Output mimetype of a displayed ipywidget.
WIDGET_VIEW_MIMETYPE = "application/vnd.jupyter.widget-view+json"


def execute_notebook(path: Path | str, timeout: int = CELL_TIMEOUT,
                     kernel_name: str = "python3") -> nbformat.NotebookNode:
    """Run every cell of the notebook at ``path`` in a new kernel; return the result.

    Widget state is not stored (it would break across ipywidgets versions), timings
    are not recorded, and the kernel's working directory is the notebook's folder.
    """
    path = Path(path)
    notebook = nbformat.read(path, as_version=4)
    client = NotebookClient(
        notebook, timeout=timeout, kernel_name=kernel_name,
        resources={"metadata": {"path": str(path.parent.resolve())}},
        store_widget_state=False, record_timing=False,
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


def main(argv: list[str] | None = None) -> int:
    """Execute each notebook named on the command line and write it back in place."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("notebooks", nargs="+", type=Path)
    args = parser.parse_args(argv)
    for path in args.notebooks:
        if path.suffix != ".ipynb" or not path.is_file():
            parser.error(f"notebooks must be existing .ipynb files, got {path}")
        print(f"executing {path}", flush=True)
        nbformat.write(execute_notebook(path), path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
