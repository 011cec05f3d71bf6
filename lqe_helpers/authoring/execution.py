"""Run one notebook top to bottom in a fresh kernel, within its time limit.

:func:`execute_notebook` is what the notebook runner and the handouts build execute a
notebook with. nbclient runs the kernel in a worker thread while the calling thread
watches it, so that:

- ``--timeout`` holds: nbclient stops a cell past its limit; should anything else hold
  the run up (the kernel never starting, the client stuck on an output), the run is
  stopped :data:`GRACE_SECONDS` later all the same;
- Ctrl-C and SIGTERM (:class:`~lqe_helpers.authoring.errors.Terminated`, once the tool's
  command line turned SIGTERM into one) stop the kernel at once and end the run with one
  line naming the notebook and the cell;
- pieces of one stream (stdout, stderr) are merged into one output per cell
  (:func:`merge_streams`) in time linear in their length. nbclient's own merging runs a
  regular expression whose time grows with the square of a line's length (100 k
  characters on one line: about 10 s; 1 MB: about a quarter of an hour, with no way to
  stop it), so it is not used.
"""

from __future__ import annotations

import argparse
import os
import signal
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

from lqe_helpers.authoring.errors import Terminated, ToolError, shown, strip_colour
from lqe_helpers.authoring.notebook_io import read_notebook

#: Default for the seconds one cell may run before the run is abandoned (``--timeout``).
CELL_TIMEOUT = 300
#: The longest time limit a cell may be given (a week, in seconds); nbclient fails on
#: limits near the largest float.
MAX_TIMEOUT = 7 * 24 * 3600
#: Output mimetype of a displayed ipywidget.
WIDGET_VIEW_MIMETYPE = "application/vnd.jupyter.widget-view+json"
#: Seconds past a cell's time limit (or the kernel's start-up limit) after which the run
#: is stopped even if nbclient has not stopped it.
GRACE_SECONDS = 15.0
#: Seconds to wait for nbclient to notice a stopped kernel and tidy up.
STOP_WAIT_SECONDS = 10.0


class NotebookRunError(ToolError, RuntimeError):
    """A notebook did not run to its end: a cell raised or timed out, or the kernel died.

    The first line of the message names the notebook, the cell and what happened; the
    cell's traceback, if any, follows on the next lines.
    """


def positive_seconds(text: str) -> float:
    """``--timeout``'s type: a number of seconds > 0 and at most :data:`MAX_TIMEOUT`."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value <= MAX_TIMEOUT:
        raise argparse.ArgumentTypeError(f"must be a number of seconds > 0, got {text!r} (at "
                                         f"most {MAX_TIMEOUT}, a week)")
    return value


def cell_label(notebook: nbformat.NotebookNode, index: int | None) -> str:
    """``"cell N (first line of its source)"``, or ``"a cell"`` if unknown."""
    if index is None or not 0 <= index < len(notebook.cells):
        return "a cell"
    first = next((line.strip() for line in notebook.cells[index].source.splitlines()
                  if line.strip()), "")
    return f"cell {index}" + (f" ({shown(first[:60])})" if first else "")


def without_overwritten_text(text: str) -> str:
    """``text`` as a terminal leaves it: on each line, what a carriage return overwrote
    is dropped (``"10%\\r50%\\n"`` → ``"50%\\n"``; ``"\\r\\n"`` is kept).

    The same result as nbclient's ``re.sub(r".*\\r(?=[^\\n])", "", text)``, in time linear
    in the length of ``text``.
    """
    lines = text.split("\n")
    for number, line in enumerate(lines):
        cut = line.rfind("\r", 0, len(line) - 1)  # a \r with something after it on the line
        if cut >= 0:
            lines[number] = line[cut + 1:]
    return "\n".join(lines)


def merge_streams(outputs: list[Any]) -> list[Any]:
    """A cell's outputs with each stream (stdout, stderr) merged into one output.

    Each stream keeps the place of its first piece; its text is every piece's text in
    order, with overwritten text dropped (:func:`without_overwritten_text`); a stderr
    output right before a stdout one is put after it. This is what nbclient's
    ``coalesce_streams`` does (its step for backspaces never changes the text), in time
    linear in the length of the output, so that how the kernel happened to chunk its
    output does not make two runs of the same notebook differ.
    """
    merged: list[Any] = []
    pieces: dict[str, list[str]] = {}
    first: dict[str, Any] = {}
    for output in outputs:
        if output.get("output_type") == "stream":
            name = output["name"]
            if name not in first:
                first[name] = output
                pieces[name] = []
                merged.append(output)
            pieces[name].append(output["text"])
        else:
            merged.append(output)
    for name, output in first.items():
        output["text"] = without_overwritten_text("".join(pieces[name]))
    for index, output in enumerate(merged):  # as nbclient orders the two streams
        if output["output_type"] == "stream" and output["name"] == "stderr" and (
                len(merged) >= index + 2 and merged[index + 1]["output_type"] == "stream"
                and merged[index + 1]["name"] == "stdout"):
            merged.insert(index, merged.pop(index + 1))
    return merged


class _KernelRun:
    """One notebook executed by nbclient in a worker thread, watched by the caller's."""

    def __init__(self, notebook: nbformat.NotebookNode, path: Path, timeout: float,
                 kernel_name: str, allow_errors: bool) -> None:
        self.notebook, self.path, self.timeout = notebook, path, timeout
        self.cell: int | None = None
        self.since = time.monotonic()
        self.stopping = False
        self.error: BaseException | None = None
        self.client = NotebookClient(
            notebook, timeout=timeout, kernel_name=kernel_name,
            resources={"metadata": {"path": str(path.parent.resolve())}},
            store_widget_state=False, record_timing=False, allow_errors=allow_errors,
            coalesce_streams=False,  # merged afterwards, in linear time (merge_streams)
            on_cell_start=self._cell_started,
        )

    def _cell_started(self, cell: Any, cell_index: int) -> None:
        if self.stopping:
            raise RuntimeError("the run was stopped")
        self.cell, self.since = cell_index, time.monotonic()

    def _work(self, stderr: int) -> None:
        try:
            self.client.execute(stderr=stderr)
        except BaseException as error:  # handed to the watching thread
            self.error = error

    def _deadline(self) -> float:
        limit = self.timeout if self.cell is not None else max(self.timeout,
                                                               self.client.startup_timeout)
        return self.since + limit + GRACE_SECONDS

    def _stop_kernel(self) -> None:
        """Kill the kernel process (and its process group, if it has its own)."""
        self.stopping = True
        provisioner = getattr(self.client.km, "provisioner", None)
        pid, group = getattr(provisioner, "pid", None), getattr(provisioner, "pgid", None)
        try:
            if group and hasattr(os, "killpg") and group != os.getpgrp():
                os.killpg(group, signal.SIGKILL)
            elif pid:
                os.kill(pid, signal.SIGKILL)
        except OSError:
            pass  # gone already

    def where(self) -> str:
        return f"{shown(self.path)}: {cell_label(self.notebook, self.cell)}"

    def execute(self) -> None:
        """Run the notebook; raise :class:`NotebookRunError`, KeyboardInterrupt or
        :class:`Terminated` (each naming the notebook and the cell) if it does not end."""
        with tempfile.TemporaryFile() as kernel_stderr:
            worker = threading.Thread(target=self._work, args=(kernel_stderr.fileno(),),
                                      name=f"kernel for {self.path.name}", daemon=True)
            worker.start()
            try:
                while worker.is_alive():
                    worker.join(0.2)
                    if worker.is_alive() and time.monotonic() > self._deadline():
                        raise NotebookRunError(
                            f"{self.where()} ran longer than the time limit of "
                            f"{self.timeout:g} s per cell (--timeout); the kernel was stopped")
            except BaseException as stop:
                self._stop_kernel()
                self._wait_for(worker)
                if isinstance(stop, KeyboardInterrupt):
                    raise KeyboardInterrupt(f"interrupted while running {self.where()}; the "
                                            f"kernel was stopped") from None
                if isinstance(stop, Terminated):
                    raise Terminated(f"stopped by SIGTERM while running {self.where()}; the "
                                     f"kernel was stopped") from None
                raise
            if isinstance(self.error, CellTimeoutError | DeadKernelError | CellExecutionError):
                kernel_stderr.seek(0)
                log = kernel_stderr.read().decode("utf-8", "replace").strip()
                raise self._run_error(self.error, log) from self.error
            if self.error is not None:
                raise self.error

    def _wait_for(self, worker: threading.Thread) -> None:
        """Let nbclient notice the stopped kernel and tidy up (a while at most)."""
        end = time.monotonic() + STOP_WAIT_SECONDS
        while worker.is_alive() and time.monotonic() < end:
            worker.join(0.2)
            self._stop_kernel()  # in case it was still starting

    def _run_error(self, error: Exception, kernel_log: str) -> NotebookRunError:
        """The :class:`NotebookRunError` for a run stopped by ``error``: the notebook, the
        cell and what happened; then the cell's traceback and the kernel's own output."""
        if isinstance(error, CellTimeoutError):
            first = (f"{self.where()} ran longer than the time limit of {self.timeout:g} s per "
                     f"cell (--timeout)")
        elif isinstance(error, DeadKernelError):
            first = f"{shown(self.path)}: the kernel died while running " \
                    f"{cell_label(self.notebook, self.cell)}"
        else:
            first = f"{self.where()} raised {error.ename}: {error.evalue}"
        details = [strip_colour(error.traceback).strip()] \
            if isinstance(error, CellExecutionError) else []
        if kernel_log:
            details.append(f"The kernel's own output:\n{kernel_log}")
        return NotebookRunError("\n".join([first, *details]))


def execute_notebook(path: Path | str, timeout: float = CELL_TIMEOUT,
                     kernel_name: str = "python3", *,
                     allow_errors: bool = False) -> nbformat.NotebookNode:
    """Run every cell of the notebook at ``path`` in a new kernel; return the result.

    Widget state is not stored (it would break across ipywidgets versions), timings
    are not recorded, the pieces of each stream (stdout, stderr) are merged into one
    output per cell (:func:`merge_streams`), and the kernel's working directory is the
    notebook's folder.

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
    KeyboardInterrupt, Terminated
        On Ctrl-C or SIGTERM: the kernel is stopped first; the message names the
        notebook and the cell.
    ValueError
        If ``timeout`` is not a number of seconds > 0 and at most :data:`MAX_TIMEOUT`.
    """
    if isinstance(timeout, bool) or not isinstance(timeout, int | float) \
            or not 0 < timeout <= MAX_TIMEOUT:
        raise ValueError(f"timeout must be a number of seconds > 0, got {timeout!r} (at most "
                         f"{MAX_TIMEOUT}, a week)")
    path = Path(path)
    notebook = read_notebook(path)
    _KernelRun(notebook, path, timeout, kernel_name, allow_errors).execute()
    for cell in notebook.cells:
        if cell.get("outputs"):
            cell.outputs = merge_streams(cell.outputs)
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
