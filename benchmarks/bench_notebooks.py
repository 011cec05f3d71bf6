"""How long each notebook takes to execute fresh, top to bottom, in a new kernel.

Run: ``.venv/bin/python benchmarks/bench_notebooks.py`` (or ``make bench``).

The peer, run in the same process, is a notebook with one ``import numpy`` cell: the
fixed cost of starting a kernel, which every notebook pays. The target is the five
question notebooks (01-05) in under 30 s in total.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import nbformat

from lqe_helpers.authoring.execution import execute_notebook

NOTEBOOK_DIR = Path(__file__).resolve().parent.parent / "notebooks"
QUESTION_PREFIXES = ("01", "02", "03", "04", "05")
TARGET_S = 30.0


def seconds_to_execute(path: Path) -> float:
    """Wall-clock seconds to execute the notebook at ``path`` in a fresh kernel."""
    start = time.perf_counter()
    execute_notebook(path)
    return time.perf_counter() - start


def kernel_start_seconds() -> float:
    """Seconds to execute a one-cell notebook: the kernel start every notebook pays."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "peer.ipynb"
        nbformat.write(nbformat.v4.new_notebook(
            cells=[nbformat.v4.new_code_cell("import numpy")],
            metadata={"kernelspec": {"name": "python3", "display_name": "Python 3",
                                     "language": "python"}}), path)
        return seconds_to_execute(path)


def main() -> int:
    peer = kernel_start_seconds()
    print(f"Fresh execution of every notebook (kernel start alone: {peer:.1f} s)")
    questions = 0.0
    total = 0.0
    for path in sorted(NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb")):
        seconds = seconds_to_execute(path)
        total += seconds
        if path.name.startswith(QUESTION_PREFIXES):
            questions += seconds
        print(f"  {path.name:36s} {seconds:5.1f} s  ({seconds / peer:4.1f}x a kernel start)")
    verdict = "ok" if questions <= TARGET_S else "SLOW"
    print(f"question notebooks 01-05: {questions:.1f} s (target <= {TARGET_S:.0f} s) {verdict}")
    print(f"all notebooks: {total:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
