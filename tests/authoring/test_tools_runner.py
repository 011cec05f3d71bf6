"""The notebook runner under attack: edits during a run, long lines, SIGTERM, odd JSON.

Issue 19: the runner overwrote an edit an author saved while it ran; one long output
line hung it (and the handouts) past ``--timeout`` and SIGTERM; it rewrote a JSON file
that was not a notebook. Each case is provoked for real, in a fresh interpreter where
signals are involved.
"""

from __future__ import annotations

import asyncio
import json
import os
import random
import re
import signal
import subprocess
import threading
import time
from pathlib import Path

import nbformat
import pytest
from nbclient.client import _RGX_CARRIAGERETURN
from nbformat.v4 import new_output
from tools_helpers import (
    code_notebook,
    error_lines,
    python_command,
    run_tool,
    snapshot,
    tools_environment,
)

from lqe_helpers.authoring import execution
from lqe_helpers.authoring.execution import (
    NotebookRunError,
    execute_notebook,
    merge_streams,
    without_overwritten_text,
)


def started(tool: str, arguments: list[str], cwd: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(python_command("-m", f"lqe_helpers.authoring.{tool}", *arguments),
                            cwd=cwd, env=tools_environment(), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def wait_for(path: Path, seconds: float = 120) -> None:
    end = time.monotonic() + seconds
    while not path.exists():
        assert time.monotonic() < end, f"{path} never appeared"
        time.sleep(0.1)


def gone(pid: int, seconds: float = 10) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.1)
    return False


# --- an edit saved while the runner runs --------------------------------------------------------

EDITED = nbformat.writes(nbformat.v4.new_notebook(cells=[nbformat.v4.new_markdown_cell(
    "# The author's edit, saved from JupyterLab during the run")])) + "\n"


@pytest.mark.kernel
@pytest.mark.parametrize("how", ["new content", "same size and time"])
def test_an_edit_saved_during_the_run_is_kept(tmp_path, how):
    """The notebook's own cell saves over its file, as JupyterLab would mid-run."""
    path = tmp_path / "01_edited.ipynb"
    if how == "new content":
        save = f"open({path.name!r}, 'w').write({EDITED!r})"
    else:  # same length, same modification time: only the checksum tells
        save = (f"import os\ndata = open({path.name!r}, 'rb').read()\n"
                f"before = os.stat({path.name!r})\n"
                f"open({path.name!r}, 'wb').write(data.replace(b'kernel', b'KERNEL'))\n"
                f"os.utime({path.name!r}, ns=(before.st_atime_ns, before.st_mtime_ns))")
    code_notebook(path, "print('the kernel ran')", save)
    original = path.read_bytes()
    other = code_notebook(tmp_path / "02_other.ipynb", "print('two')")
    result = run_tool("notebook_runner", str(path), str(other))
    assert result.returncode == 1, result.stderr
    [line] = result.stderr.splitlines()
    assert line.startswith(f"error: kept {path} as it is on disk: it changed while the run")
    assert result.stdout.splitlines()[-1] == f"saved {other}"
    saved_by_the_author = (EDITED.encode() if how == "new content"
                           else original.replace(b"kernel", b"KERNEL"))
    assert path.read_bytes() == saved_by_the_author
    assert nbformat.read(other, as_version=4).cells[0].outputs[0]["text"] == "two\n"


# --- a JSON file that is not a notebook -----------------------------------------------------------

@pytest.mark.parametrize("content", [
    {"nbformat": 4, "nbformat_minor": 99, "metadata": {}, "cells": [],
     "name": "my-package", "dependencies": {"left-pad": "1.0"}},
    {"nbformat": 3, "nbformat_minor": 0, "metadata": {}, "worksheets": []},
    {"nbformat": 4, "nbformat_minor": -1, "metadata": {}, "cells": []},
    {"nbformat": True, "nbformat_minor": 5, "metadata": {}, "cells": []},
])
@pytest.mark.slow
def test_json_that_is_not_a_notebook_is_refused_before_anything_runs(tmp_path, content):
    good = code_notebook(tmp_path / "01_good.ipynb", "print('ran')")
    odd = tmp_path / "02_package.ipynb"
    odd.write_text(json.dumps(content))
    before = snapshot(tmp_path)
    result = run_tool("notebook_runner", str(good), str(odd))
    assert result.returncode == 1
    assert result.stdout == ""  # nothing executed
    [line] = result.stderr.splitlines()
    assert line.startswith(f"error: {odd} is not a valid notebook: "), line
    assert snapshot(tmp_path) == before


@pytest.mark.slow
def test_a_fifo_named_like_a_notebook_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "01_pipe.ipynb"
    os.mkfifo(fifo)
    result = run_tool("notebook_runner", str(fifo), timeout=30)
    assert result.returncode == 1
    assert error_lines(result.stderr) == [
        f"error: notebooks must be existing .ipynb files, got {fifo}"]


@pytest.mark.slow
def test_a_deeply_nested_notebook_names_the_file(tmp_path):
    deep = tmp_path / "01_deep.ipynb"
    deep.write_text('{"nbformat": 4, "nbformat_minor": 5, "cells": [], "metadata": {"a": '
                    + "[" * 5000 + "]" * 5000 + "}}")
    result = run_tool("notebook_runner", str(deep))
    assert result.returncode == 1
    [line] = result.stderr.splitlines()
    assert line.startswith(f"error: {deep} is not a valid notebook: its JSON is nested"), line


# --- long output lines ---------------------------------------------------------------------------

def reference_merge(outputs: list[dict]) -> list[dict]:
    """nbclient 0.11's coalesce_streams, as written in nbclient/client.py (quadratic)."""
    new_outputs, streams = [], {}
    for output in outputs:
        if output["output_type"] == "stream":
            if output["name"] in streams:
                streams[output["name"]]["text"] += output["text"]
            else:
                new_outputs.append(output)
                streams[output["name"]] = output
        else:
            new_outputs.append(output)
    for output in streams.values():
        output["text"] = _RGX_CARRIAGERETURN.sub("", output["text"])
    for i, output in enumerate(new_outputs):
        if output["output_type"] == "stream" and output["name"] == "stderr" and (
                len(new_outputs) >= i + 2 and new_outputs[i + 1]["output_type"] == "stream"
                and new_outputs[i + 1]["name"] == "stdout"):
            stdout = new_outputs.pop(i + 1)
            new_outputs.insert(i, stdout)
    return new_outputs


def random_outputs(rng: random.Random) -> list[dict]:
    outputs = []
    for _ in range(rng.randint(0, 6)):
        kind = rng.choice(["stdout", "stderr", "stdout", "display"])
        if kind == "display":
            outputs.append(new_output("display_data", data={"text/plain": "x"}))
        else:
            text = "".join(rng.choice("ab\r\n\x08 ") for _ in range(rng.randint(0, 12)))
            outputs.append(new_output("stream", name=kind, text=text))
    return outputs


@pytest.mark.slow
def test_the_linear_merge_gives_what_nbclient_gives():
    rng = random.Random(19)
    for _ in range(5000):
        outputs = random_outputs(rng)
        ours = merge_streams([nbformat.from_dict(dict(output)) for output in outputs])
        theirs = reference_merge([nbformat.from_dict(dict(output)) for output in outputs])
        assert ours == theirs, outputs


@pytest.mark.parametrize("text", ["", "\r", "a\r", "a\rb", "a\r\nb", "10%\r50%\r100%\n",
                                  "x\r\ry", "\r\r\n", "a\rb\rc\nd\re"])
def test_overwritten_text_is_dropped_as_nbclient_drops_it(text):
    assert without_overwritten_text(text) == _RGX_CARRIAGERETURN.sub("", text)


def test_the_merge_of_one_long_line_takes_linear_time():
    line = "x" * 10_000_000 + "\r" + "y" * 10 + "\n"
    begin = time.perf_counter()
    assert without_overwritten_text(line) == "y" * 10 + "\n"
    assert time.perf_counter() - begin < 1.0  # nbclient's regex: hours


def test_the_merge_of_100k_pieces_takes_linear_time():
    """A cell printing 100 k short lines, flushed one by one: nbclient's merge (one string
    grown piece by piece) takes about 16 s here; ours a fraction of a second."""
    pieces = [{"output_type": "stream", "name": "stdout", "text": f"line {i}\r{i}\n"}
              for i in range(100_000)]
    begin = time.perf_counter()
    [merged] = merge_streams(pieces)
    assert time.perf_counter() - begin < 2.0
    assert merged["text"] == "".join(f"{i}\n" for i in range(100_000))


@pytest.mark.slow
@pytest.mark.kernel
def test_a_one_megabyte_line_is_saved_in_seconds(tmp_path):
    path = code_notebook(tmp_path / "01_long.ipynb",
                         "print('x' * 1_000_000)\nprint('10%\\r100%')")
    begin = time.monotonic()
    result = run_tool("notebook_runner", str(path), "--timeout", "60", timeout=240)
    assert result.returncode == 0, result.stderr
    assert time.monotonic() - begin < 120  # before: about a quarter of an hour
    [output] = nbformat.read(path, as_version=4).cells[0].outputs
    assert output["text"] == "x" * 1_000_000 + "\n100%\n"


@pytest.mark.slow
@pytest.mark.kernel
def test_handouts_of_a_one_megabyte_line_are_built_in_seconds(tmp_path):
    source = tmp_path / "notebooks"
    code_notebook(source / "01_long.ipynb", "# A long line\nprint('x' * 1_000_000)")
    out = tmp_path / "handouts"
    begin = time.monotonic()
    result = run_tool("handouts", "--source", str(source), "--out", str(out),
                      "--mathjax-url", "", "--timeout", "60", timeout=240)
    assert result.returncode == 0, result.stderr
    assert time.monotonic() - begin < 120
    assert "x" * 1_000_000 in (out / "01_long.html").read_text()


# --- --timeout and SIGTERM end a run with one line ------------------------------------------------

# The pid file appears whole (written aside, then renamed), so the test never reads it empty.
ENDLESS = ("import os, time\nopen('kernel.pid.part', 'w').write(str(os.getpid()))\n"
           "os.replace('kernel.pid.part', 'kernel.pid')\nwhile True:\n    time.sleep(0.1)")


@pytest.mark.kernel
@pytest.mark.parametrize(("how", "status", "said"), [
    (signal.SIGTERM, 143, "stopped by SIGTERM while running"),
    (signal.SIGINT, 130, "interrupted while running"),
])
@pytest.mark.parametrize("tool", ["notebook_runner", "handouts"])
def test_a_signal_stops_the_kernel_and_ends_the_run_with_one_line(tmp_path, how, status, said,
                                                                  tool):
    source = tmp_path / "notebooks"
    path = code_notebook(source / "01_endless.ipynb", "print('start')", ENDLESS)
    before = snapshot(tmp_path)
    out = tmp_path / "handouts"
    arguments = ([str(path)] if tool == "notebook_runner"
                 else ["--source", str(source), "--out", str(out), "--mathjax-url", ""])
    process = started(tool, [*arguments, "--timeout", "600"], tmp_path)
    wait_for(source / "kernel.pid")
    kernel = int((source / "kernel.pid").read_text())
    time.sleep(0.5)
    process.send_signal(how)
    _, err = process.communicate(timeout=60)
    assert process.returncode == status, err
    [line] = err.splitlines()
    assert line == (f"error: {said} {path}: cell 1 (import os, time); the kernel was "
                    f"stopped"), line
    assert gone(kernel), "the kernel is still running"
    (source / "kernel.pid").unlink()
    assert snapshot(tmp_path) == before  # no notebook changed, no output folder


@pytest.mark.slow
@pytest.mark.kernel
@pytest.mark.parametrize(("tool", "how", "said"), [
    ("notebook_runner", signal.SIGINT, "interrupted while running"),
    ("handouts", signal.SIGINT, "interrupted while running"),
])
def test_a_signal_sent_twice_is_still_one_line(tmp_path, tool, how, said):
    """Issue 27: Ctrl-C twice added 17–33 lines of nbclient's exit tracebacks; SIGTERM
    twice named no notebook or cell. The second signal comes while the kernel is stopped."""
    source = tmp_path / "notebooks"
    path = code_notebook(source / "01_endless.ipynb", ENDLESS)
    arguments = ([str(path)] if tool == "notebook_runner" else
                 ["--source", str(source), "--out", str(tmp_path / "out"), "--mathjax-url", ""])
    process = started(tool, arguments, tmp_path)
    wait_for(source / "kernel.pid")
    kernel = int((source / "kernel.pid").read_text())
    process.send_signal(how)
    time.sleep(0.05)
    process.send_signal(how)
    _, err = process.communicate(timeout=60)
    assert err.splitlines() == [f"error: {said} {path}: cell 0 (import os, time); the kernel "
                                f"was stopped"], err
    # Killed by the second signal once its work was done, or exited: a shell says 128 + it.
    assert process.returncode in (128 + how, -how)
    assert gone(kernel), "the kernel is still running"


@pytest.mark.slow
@pytest.mark.kernel
def test_the_time_limit_on_a_kernel_that_ignores_ctrl_c_is_one_line(tmp_path):
    """Issue 27: nbclient left a task pending, and asyncio printed 'Task was destroyed'."""
    path = code_notebook(tmp_path / "01_deaf.ipynb", "import signal, time\n"
                         "signal.signal(signal.SIGINT, signal.SIG_IGN)\nwhile True:\n"
                         "    time.sleep(0.1)")
    result = run_tool("notebook_runner", str(path), "--timeout", "2")
    assert result.returncode == 1
    assert result.stderr.splitlines() == [
        f"error: {path}: cell 0 (import signal, time) ran longer than the time limit of 2 s "
        f"per cell (--timeout) (--verbose shows the rest)"], result.stderr


@pytest.mark.slow
def test_the_time_limit_holds_even_if_the_client_hangs(tmp_path, monkeypatch):
    """nbclient stuck in a cell (here: it never returns from it, whatever its own time
    limit says): the run stops a grace period past the limit all the same."""
    path = code_notebook(tmp_path / "01.ipynb", "1 + 1")
    release = threading.Event()

    async def stuck(self, **kwargs):
        self.on_cell_start(cell=self.nb.cells[0], cell_index=0)
        while not release.is_set():
            await asyncio.sleep(0.05)

    monkeypatch.setattr(execution.NotebookClient, "async_execute", stuck)
    monkeypatch.setattr(execution, "GRACE_SECONDS", 0.5)
    monkeypatch.setattr(execution, "STOP_WAIT_SECONDS", 0.5)
    begin = time.monotonic()
    try:
        with pytest.raises(NotebookRunError, match=re.escape(
                f"{path}: cell 0 (1 + 1) ran longer than the time limit of 1 s per cell "
                f"(--timeout); the kernel was stopped")):
            execute_notebook(path, timeout=1)
    finally:
        release.set()
    assert time.monotonic() - begin < 10
