"""The kill tests' shared pieces (tests/authoring/test_tools_kill_*.py): small inputs for
each tool that writes a folder through the swap, and the loop that kills a run at a moment,
checks the folder, and runs the tool again.

A *run* is a callable ``run(args, kill_at)`` → (status, stderr): ``kill_at`` is ``None``
(run to the end) or the step of the swap (``LQE_KILL_AT_STEP``) at which the run SIGKILLs
itself; ``status`` is the exit status, or ``-9`` if the run was killed. The command-line
test runs ``python -m …``; the moments test forks the test process.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import signal
import warnings
from collections.abc import Callable
from pathlib import Path

from tools_helpers import (
    MANIFEST,
    code_notebook,
    make_course,
    snapshot,
    worked_notebook,
    write_notebook,
)

from lqe_helpers.authoring.folder_lock import FolderLock
from lqe_helpers.authoring.swap import RecoveryWarning

#: A run of a tool: (its arguments, the swap step to be killed at or ``None``) → (status, stderr).
Run = Callable[[list[str], "int | None"], tuple[int, str]]
KILLED = -signal.SIGKILL
#: The notebooks of a source folder before and after the change a rebuild swaps in: two
#: changed, one deleted, five new (one in a new sub-folder): ≥ 20 steps, even for a first build.
OLD_NOTEBOOKS = ("01_a.ipynb", "02_b.ipynb", "03_c.ipynb")
NEW_NOTEBOOKS = ("01_a.ipynb", "02_b.ipynb", "04_d.ipynb", "05_e.ipynb", "06_f.ipynb",
                 "07_g.ipynb", "sub/08_h.ipynb")


def notebooks(source: Path, names: tuple[str, ...], variant: str = "") -> None:
    """Worked notebooks ``names`` in ``source`` (``variant`` changes their task)."""
    for name in names:
        notebook = worked_notebook(solution=f"# Task: compute x (cm).\nx = 1{variant}  # {name}")
        notebook.metadata["lqe"] = {"question": "background"}  # any number, for marking_guide
        write_notebook(source / name, notebook)


def setup_student_edition(work: Path, new: bool) -> list[str]:
    """Worked notebooks (the old set, or the new one); the arguments of a build."""
    source = work / "notebooks"
    if new:
        (source / "03_c.ipynb").unlink(missing_ok=True)  # its edition is deleted
    notebooks(source, NEW_NOTEBOOKS if new else OLD_NOTEBOOKS, "2" if new else "")
    return ["--source", str(source), "--out", str(work / "out")]


def setup_handouts(work: Path, new: bool) -> list[str]:
    """A small code notebook (then changed)."""
    source = work / "notebooks"
    for name in ("01_a.ipynb",):
        code_notebook(source / name, f"print('{name} {'new' if new else 'old'}')")
    return ["--source", str(source), "--out", str(work / "out"), "--mathjax-url", ""]


def setup_pack(work: Path, new: bool) -> list[str]:
    """A minimal course folder (its notebook then changed)."""
    if not new:
        make_course(work / "course")
    else:
        notebooks(work / "course" / "notebooks", ("01_first.ipynb",), "2")
    return ["--root", str(work / "course"), "--out", str(work / "out")]


#: The runner's notebooks: two folders of two (a save stages both folders, then swaps each).
RUNNER_NOTEBOOKS = ("a/01.ipynb", "a/02.ipynb", "b/03.ipynb", "b/04.ipynb")


def setup_runner(work: Path, new: bool) -> list[str]:
    """Unexecuted code notebooks in two folders of ``out``; the arguments of a run."""
    folder = work / "out"
    if not new:
        for name in RUNNER_NOTEBOOKS:
            code_notebook(folder / name, f"print('{name}')")
    return [str(folder / name) for name in RUNNER_NOTEBOOKS]


SETUPS = {"student_edition": setup_student_edition, "marking_guide": setup_student_edition,
          "handouts": setup_handouts, "student_pack": setup_pack,
          "notebook_runner": setup_runner}


def recovered_alone(folder: Path) -> list[str]:
    """Take ``folder`` as a tool does (which recovers it); the recovery lines."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with FolderLock(folder):
            pass
    return [str(w.message) for w in caught if issubclass(w.category, RecoveryWarning)]


def same_build(state: dict, reference: dict) -> bool:
    """Whether ``state`` is wholly the build ``reference``: byte-identical, or (handouts and
    zips are not byte-reproducible run to run) the same files, each holding what the
    manifest of the same files lists."""
    if state == reference:
        return True
    if set(state) != set(reference) or MANIFEST not in state:
        return False
    listed = json.loads(state[MANIFEST])["files"]
    return listed.keys() == json.loads(reference[MANIFEST])["files"].keys() and all(
        hashlib.sha256(state[name]).hexdigest() == digest for name, digest in listed.items())


def ours_left(folder: Path) -> bool:
    """Whether a journal or temporary folder of a swap is in ``folder`` or a sub-folder."""
    return folder.is_dir() and any(path.name != MANIFEST for path in folder.rglob(".lqe-*"))


def part(state: dict, name: str) -> dict:
    """The entries of a snapshot ``state`` under its sub-folder ``name`` (``""``: all)."""
    if not name:
        return state
    return {key[len(name) + 1:]: value for key, value in state.items()
            if key.startswith(name + "/")}


#: What a recovery line says for each way it went.
ROLLED_BACK = ("killed before it moved any file", "it is now undone")
FINISHED = "the move is now finished"


class Scenario:
    """A tool's folder before a build (``base``) and the build's arguments, copied into
    ``work`` before each run; ``old`` and ``new``: the folder before and after the build."""

    def __init__(self, tool: str, root: Path, run: Run, *, first: bool) -> None:
        self.tool, self.run, self.first = tool, run, first
        #: The folders swapped, each wholly old or new after a kill (the runner's: one per
        #: folder of notebooks; across them one may be old and another new).
        self.parts = sorted({name.split("/")[0] for name in RUNNER_NOTEBOOKS}) \
            if tool == "notebook_runner" else [""]
        setup = SETUPS[tool]
        self.base, self.work, self.alone = root / "base", root / "work", root / "alone"
        args = setup(self.base, new=False)
        if not first and tool != "notebook_runner":
            status, stderr = run(args, None)
            assert status == 0, stderr
            (self.base / "out" / "mine.txt").write_text("the instructor's own file")
        self.args = [arg.replace(str(self.base), str(self.work))
                     for arg in setup(self.base, new=True)]
        self.out = self.work / "out"
        self.old = snapshot(self.base / "out")
        self.restore()
        status, stderr = run(self.args, None)
        assert status == 0, stderr
        self.new = snapshot(self.out)
        assert self.new != self.old

    def restore(self) -> None:
        """``work`` as ``base``: the folder before the build."""
        shutil.rmtree(self.work, ignore_errors=True)
        shutil.copytree(self.base, self.work, symlinks=True)

    def whole(self, state: dict, name: str = "") -> str | None:
        """``"old"`` or ``"new"`` if ``state``'s part ``name`` is wholly the folder before or
        after the build."""
        now, old, new = part(state, name), part(self.old, name), part(self.new, name)
        if now == old or (self.first and now == {}):
            return "old"
        return "new" if same_build(now, new) else None

    def kill_and_rerun(self, step: int) -> list[str] | None:
        """Kill a build at swap step ``step``; check that each folder, recovered alone, is
        whole, and that the next run ends with the whole new folder and says in one line
        per folder it recovered which way the recovery went. Return the way of each folder
        (``"old"`` or ``"new"``), or ``None`` if the build completed before step ``step``."""
        self.restore()
        return self.recovered_after(*self.run(self.args, step), step)

    def recovered_after(self, status: int, stderr: str, step: object) -> list[str] | None:
        """:meth:`kill_and_rerun` after the killed run (exit ``status``, its ``stderr``) of
        the moment ``step`` (a step, or a time)."""
        if status == 0:
            assert self.whole(snapshot(self.out)) == "new", step
            return None
        assert status == KILLED, (step, status, stderr)
        shutil.rmtree(self.alone, ignore_errors=True)
        if self.out.exists():
            shutil.copytree(self.out, self.alone, symlinks=True)
        lines, ways = [], []
        for name in self.parts:
            left = ours_left(self.out / name)
            said = [line.replace(str(self.alone), str(self.out))
                    for line in (recovered_alone(self.alone / name)
                                 if (self.alone / name).exists() else [])]
            assert not ours_left(self.alone / name), step
            way = self.whole(snapshot(self.alone), name)
            assert way is not None, (step, name, sorted(part(snapshot(self.alone), name)))
            assert len(said) == (1 if left else 0), (step, said)
            for line in said:  # the line says which way it went
                assert line.startswith(f"recovered {self.out / name if name else self.out}:")
                assert (FINISHED in line) == (way == "new"), (step, way, line)
                assert (FINISHED in line) != any(text in line for text in ROLLED_BACK), line
            lines += said
            ways.append(way)
        status, stderr = self.run(self.args, None)  # the next run
        assert status == 0, (step, stderr)
        said = [line for line in stderr.splitlines() if line.startswith("warning: recovered")]
        assert sorted(said) == sorted(f"warning: {line}" for line in lines), (step, said)
        assert all(self.whole(snapshot(self.out), name) == "new" for name in self.parts), step
        assert not ours_left(self.out), step
        return ways
