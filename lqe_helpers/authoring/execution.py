"""Run one notebook top to bottom in a fresh kernel, within its time limit.

:func:`execute_notebook` is what the notebook runner and the handouts build execute a
notebook with: nbclient as it is, in a worker thread (its own event loop, run by
:func:`asyncio.run`), while the calling thread waits, so that:

- ``--timeout`` is nbclient's time limit per cell; should anything else hold the run up
  (the kernel never starting, the client stuck), it is stopped :data:`GRACE_SECONDS`
  later all the same;
- Ctrl-C and SIGTERM (:class:`~lqe_helpers.authoring.errors.Terminated`, once the tool's
  command line turned SIGTERM into one) reach the calling thread, which kills the kernel
  and ends the run with one line naming the notebook and the cell (a second signal only
  cuts the wait for nbclient to tidy up short);
- pieces of one stream (stdout, stderr) are merged into one output per cell
  (:func:`merge_streams`) in time linear in their length. nbclient's own merging runs a
  regular expression whose time grows with the square of a line's length (100 k
  characters on one line: about 10 s; 1 MB: about a quarter of an hour, with no way to
  stop it), so it is not used.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
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
        return _checked_timeout(float(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds > 0, got {text!r} (at "
                                         f"most {MAX_TIMEOUT}, a week)") from None


def _checked_timeout(timeout: object) -> float:
    if isinstance(timeout, bool) or not isinstance(timeout, int | float) \
            or not 0 < timeout <= MAX_TIMEOUT:
        raise ValueError(f"timeout must be a number of seconds > 0, got {timeout!r} (at most "
                         f"{MAX_TIMEOUT}, a week)")
    return timeout


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
    streams: dict[str, tuple[Any, list[str]]] = {}  # name: its first output, its pieces
    for output in outputs:
        if output.get("output_type") != "stream":
            merged.append(output)
        elif output["name"] in streams:
            streams[output["name"]][1].append(output["text"])
        else:
            streams[output["name"]] = (output, [output["text"]])
            merged.append(output)
    for output, pieces in streams.values():
        output["text"] = without_overwritten_text("".join(pieces))
    if {"stderr", "stdout"} <= streams.keys():  # stderr right before stdout: after it
        place = next(i for i, output in enumerate(merged) if output is streams["stderr"][0])
        if place + 1 < len(merged) and merged[place + 1] is streams["stdout"][0]:
            merged[place:place + 2] = merged[place + 1], merged[place]
    return merged


def _kill_kernel(client: NotebookClient) -> None:
    """Kill the kernel's process (its process group, if it has its own), if it started."""
    provisioner = getattr(client.km, "provisioner", None)
    pid, group = getattr(provisioner, "pid", None), getattr(provisioner, "pgid", None)
    with contextlib.suppress(OSError):  # gone already
        if group and group != os.getpgrp():
            os.killpg(group, signal.SIGKILL)
        elif pid:
            os.kill(pid, signal.SIGKILL)


def _run_error(error: BaseException, path: Path, cell: str, timeout: float,
               log: str) -> NotebookRunError:
    """The :class:`NotebookRunError` for nbclient's ``error`` in ``cell`` (its label): the
    notebook, the cell and what happened; then the cell's traceback and the kernel's own
    output, if any."""
    if isinstance(error, DeadKernelError):
        first = f"{shown(path)}: the kernel died while running {cell}"
    elif isinstance(error, CellExecutionError):
        first = f"{shown(path)}: {cell} raised {error.ename}: {error.evalue}"
    else:
        first = (f"{shown(path)}: {cell} ran longer than the time limit of {timeout:g} s per "
                 f"cell (--timeout)")
    details = [strip_colour(error.traceback).strip()] \
        if isinstance(error, CellExecutionError) else []
    return NotebookRunError("\n".join([first, *details, *(
        [f"The kernel's own output:\n{log}"] if log else [])]))


def execute_notebook(path: Path | str, timeout: float = CELL_TIMEOUT, *,
                     allow_errors: bool = False) -> nbformat.NotebookNode:
    """Run every cell of the notebook at ``path`` in a new ``python3`` kernel; return it.

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
    timeout = _checked_timeout(timeout)
    path = Path(path)
    notebook = read_notebook(path)
    running = [None, time.monotonic()]  # the cell running (its index) and since when

    def cell_started(cell: Any, cell_index: int) -> None:
        running[:] = [cell_index, time.monotonic()]

    client = NotebookClient(
        notebook, timeout=timeout, kernel_name="python3", on_cell_start=cell_started,
        resources={"metadata": {"path": str(path.parent.resolve())}},
        store_widget_state=False, record_timing=False, allow_errors=allow_errors,
        coalesce_streams=False)  # merged afterwards, in linear time (merge_streams)
    # nbclient's exit hook would stop a kernel stopped here already, and print tracebacks.
    client._cleanup_kernel = lambda: None
    failed: list[BaseException] = []
    with tempfile.TemporaryFile() as log:
        def work() -> None:  # asyncio.run: no task of nbclient's is left pending
            try:
                asyncio.run(client.async_execute(stderr=log.fileno()))
            except Exception as error:
                failed.append(error)

        worker = threading.Thread(target=work, name=f"kernel for {path.name}", daemon=True)
        worker.start()
        where = lambda: f"{shown(path)}: {cell_label(notebook, running[0])}"  # noqa: E731
        try:
            while worker.is_alive():
                worker.join(0.2)
                limit = timeout if running[0] is not None else max(timeout,
                                                                   client.startup_timeout)
                if worker.is_alive() and time.monotonic() > running[1] + limit + GRACE_SECONDS:
                    raise NotebookRunError(f"{where()} ran longer than the time limit of "
                                           f"{timeout:g} s per cell (--timeout); the kernel "
                                           f"was stopped")
        except BaseException as stop:
            with contextlib.suppress(KeyboardInterrupt, Terminated):  # a second signal
                end = time.monotonic() + STOP_WAIT_SECONDS
                while worker.is_alive() and time.monotonic() < end:
                    _kill_kernel(client)  # again, in case it was still starting
                    worker.join(0.2)
            if isinstance(stop, KeyboardInterrupt):
                raise KeyboardInterrupt(f"interrupted while running {where()}; the kernel "
                                        f"was stopped") from None
            if isinstance(stop, Terminated):
                raise Terminated(f"stopped by SIGTERM while running {where()}; the kernel "
                                 f"was stopped") from None
            raise
        if failed:
            if not isinstance(failed[0], CellTimeoutError | DeadKernelError | CellExecutionError):
                raise failed[0]
            log.seek(0)
            raise _run_error(failed[0], path, cell_label(notebook, running[0]), timeout,
                             log.read().decode("utf-8", "replace").strip()) from failed[0]
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
