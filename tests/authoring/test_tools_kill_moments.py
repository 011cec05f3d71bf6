"""Every tool that swaps a folder, killed at every step of its swap (≥ 20), then run again.

Issue 26: a tool killed at any moment of its run must leave, after its next run, a whole
folder, that run saying in one line whether it finished or rolled back the killed build.
Here the tool's ``main(argv)`` runs in a child forked from this test process (the tool
imported once, so a run costs its work, not an interpreter's start-up), which SIGKILLs
itself at step k of the swap (``LQE_KILL_AT_STEP``: the temporary folder, each staged file,
the journal, each rename and link, the tidying up), for every k until a run completes, in
a rebuild and in a first build into a new folder. After each kill the folder, recovered
alone, must be wholly old or wholly new, and the next run (another forked child) must end
with the whole new folder and one ``warning: recovered …`` line saying which way it went
(:class:`kill_scenarios.Scenario`).

The notebooks a tool executes (handouts, notebook_runner) are "executed" in the children by
:func:`stand_in_execution`, which gives each code cell a fixed output without a kernel: a
kernel per notebook per run would cost ~1 s each, and the kills are in the save, after the
execution. ``tests/authoring/test_tools_kill_cli.py`` kills each tool through its real
command line (``python -m``, real kernels) at a few steps and at a few moments in time.
"""

from __future__ import annotations

import contextlib
import importlib
import io
import os
import sys
import traceback
import warnings
from pathlib import Path

import nbformat
import pytest
from kill_scenarios import SETUPS, Scenario
from nbformat.v4 import new_output

from lqe_helpers.authoring import swap

#: A build must be killed at this many moments at least.
MOMENTS = 20


def stand_in_execution(path: Path | str, *args: object, **kwargs: object) -> nbformat.NotebookNode:
    """The notebook at ``path`` as if executed: each code cell numbered, printing its source."""
    notebook = nbformat.read(path, as_version=4)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    for number, cell in enumerate(code, start=1):
        cell.execution_count = number
        cell.outputs = [new_output("stream", name="stdout", text=f"{cell.source}\n")]
    return notebook


class ForkedTool:
    """Runs (:data:`kill_scenarios.Run`) of ``tool``'s ``main``, each in a child forked from
    this process, its stderr kept in ``stderr_file``."""

    def __init__(self, tool: str, stderr_file: Path) -> None:
        self.module = importlib.import_module(f"lqe_helpers.authoring.{tool}")
        self.stderr_file = stderr_file

    def warm_up(self, args: list[str]) -> None:
        """Run the tool once in this process, so that what it does once per process (its
        lazy imports, nbformat's schema) is done before the children are forked."""
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            assert self.module.main(args) == 0

    def __call__(self, args: list[str], kill_at: int | None) -> tuple[int, str]:
        pid = os.fork()
        if pid == 0:  # the child: never returns into pytest
            status = 99
            try:
                with open(self.stderr_file, "w", encoding="utf-8") as stderr, \
                        open(os.devnull, "w", encoding="utf-8") as stdout:
                    sys.stderr, sys.stdout = stderr, stdout
                    warnings.resetwarnings()  # a fresh interpreter's filters
                    warnings.simplefilter("default")
                    swap._steps[0] = 0
                    os.environ.pop(swap.KILL_AT_STEP, None)
                    if kill_at is not None:
                        os.environ[swap.KILL_AT_STEP] = str(kill_at)
                    try:
                        status = self.module.main(args)
                    except BaseException:
                        traceback.print_exc()
                    stderr.flush()
            finally:
                os._exit(status)
        _, status = os.waitpid(pid, 0)
        code = -os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)
        return code, self.stderr_file.read_text(encoding="utf-8")


def killed_at_every_step(scenario: Scenario) -> list[str]:
    """Kill ``scenario``'s build at step 1, 2, … until a run completes; each folder's way."""
    ways: list[str] = []
    for step in range(1, 500):
        way = scenario.kill_and_rerun(step)
        if way is None:  # past the last step: the build completed
            return ways
        ways += way
    pytest.fail("the build never completed")


@pytest.mark.slow
@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork (POSIX)")
@pytest.mark.parametrize("tool", sorted(SETUPS))
def test_a_tool_killed_at_every_step_of_its_swap_recovers_on_its_next_run(tmp_path, tool,
                                                                          monkeypatch):
    run = ForkedTool(tool, tmp_path / "stderr.txt")
    if hasattr(run.module, "execute_notebook"):  # handouts, notebook_runner: no kernel
        monkeypatch.setattr(run.module, "execute_notebook", stand_in_execution)
    run.warm_up(SETUPS[tool](tmp_path / "warm-up", new=False))
    moments = 0
    firsts = (False,) if tool == "notebook_runner" else (False, True)  # the runner saves
    for first in firsts:                                  # notebooks that exist: no first build
        ways = killed_at_every_step(Scenario(tool, tmp_path / f"first-{first}", run,
                                             first=first))
        assert "old" in ways and "new" in ways  # killed before and after the journal
        moments += len(ways) // (2 if tool == "notebook_runner" else 1)
    assert moments >= MOMENTS, f"{tool}: killed at only {moments} moments"
    print(f"{tool}: killed at {moments} moments")
