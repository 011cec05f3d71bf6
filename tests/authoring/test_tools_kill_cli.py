"""Every tool killed through its command line, at steps of its swap and at moments in time.

Issues 26 and 27: a tool killed while it moved its files into place (or in a first build
into a new folder) left a folder the next run refused, blaming the user. Here each tool
runs as ``python -m lqe_helpers.authoring.<tool>`` (real kernels for the handouts and the
runner) with ``LQE_KILL_AT_STEP=k``, which makes it SIGKILL itself at step k of its swap:
before the journal (step 2: the temporary folder made, not yet stamped) and in the middle
of the moves (:func:`mid_move_step`); and the student edition is killed by this test at
seeded moments in time, as the issue's reproduction does. After each kill the folder,
recovered alone, is wholly old or wholly new, and the tool run again ends with the whole
new folder, saying in one ``warning: recovered …`` line whether it finished or rolled back
(:class:`kill_scenarios.Scenario`). Every step of every tool's swap (≥ 20 moments each) is
killed in ``test_tools_kill_moments.py``; ``LQE_KILL_EVERY_STEP=1`` kills every step here
too, through the command line (minutes).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time

import numpy as np
import pytest
from kill_scenarios import MANIFEST, RUNNER_NOTEBOOKS, Scenario
from tools_helpers import python_command, run_tool, tools_environment

from lqe_helpers.authoring.swap import KILL_AT_STEP

EVERY_STEP = bool(os.environ.get("LQE_KILL_EVERY_STEP"))


def command_line_run(tool: str):
    """A run (:data:`kill_scenarios.Run`) of ``python -m lqe_helpers.authoring.<tool>``."""
    def run(args: list[str], kill_at: int | None) -> tuple[int, str]:
        result = run_tool(tool, *args, env={} if kill_at is None else {KILL_AT_STEP: str(kill_at)})
        return result.returncode, result.stderr
    return run


def mid_move_step(scenario: Scenario) -> int:
    """The step of the swap right before the first new file is linked in (its old file
    moved aside): every folder staged (made, stamped, one step per file), then the journal
    and the first move aside."""
    if scenario.tool == "notebook_runner":
        per_folder = [sum(name.startswith(f"{part}/") for name in RUNNER_NOTEBOOKS)
                      for part in scenario.parts]
    else:
        per_folder = [len(json.loads(scenario.new[MANIFEST])["files"]) + 1]
    return sum(2 + files for files in per_folder) + 3


@pytest.mark.slow
@pytest.mark.kernel
@pytest.mark.parametrize(("tool", "first"), [
    ("student_edition", False), ("student_edition", True), ("marking_guide", False),
    ("handouts", False), ("student_pack", False), ("notebook_runner", False)])
def test_a_tool_killed_through_its_command_line_recovers_on_its_next_run(tmp_path, tool,
                                                                         first):
    scenario = Scenario(tool, tmp_path, command_line_run(tool), first=first)
    middle = mid_move_step(scenario)
    kernels = tool in ("handouts", "notebook_runner")  # each run starts kernels: one kill
    steps = range(1, 500) if EVERY_STEP else (middle,) if kernels else (2, middle)
    ways = []
    for step in steps:
        way = scenario.kill_and_rerun(step)
        if way is None:
            break
        ways.append(way)
    else:
        assert not EVERY_STEP, "the build never completed"
    if not EVERY_STEP:  # killed before the journal: rolled back; mid-move: finished (the
        # runner's second folder, not yet journalled, rolled back)
        assert ways[-1][0] == "new" and ways[-1][1:] == ["old"] * (len(scenario.parts) - 1)
        assert kernels or ways[0] == ["old"]


@pytest.mark.slow
def test_a_build_killed_at_moments_in_time_recovers_on_its_next_run(tmp_path):
    """The issue's reproduction: ``sleep t; kill -9`` at seeded times across a whole run."""
    tool = "student_edition"
    durations = []

    def timed(args: list[str], kill_at: int | None) -> tuple[int, str]:
        start = time.monotonic()
        result = command_line_run(tool)(args, kill_at)
        durations.append(time.monotonic() - start)
        return result

    scenario = Scenario(tool, tmp_path, timed, first=False)
    duration = durations[-1]  # of the build (its reference run)
    rng, ways = np.random.default_rng(26), []
    for delay in sorted(rng.uniform(0.1, duration, size=4)):
        scenario.restore()
        process = subprocess.Popen(python_command("-m", f"lqe_helpers.authoring.{tool}",
                                                  *scenario.args),
                                   env=tools_environment(), stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        time.sleep(delay)
        process.send_signal(signal.SIGKILL)
        process.wait(timeout=60)
        ways.append(scenario.recovered_after(process.returncode, "", delay))
    assert ways.count(None) < len(ways)  # killed before the run ended, at least once
