"""All or nothing under a kill: a build killed at any step is recovered by the next run.

Issue 19: a SIGKILL during the final renames left the output folder half old and half
new with a ``.lqe-build-*`` folder inside, and every later build refused until a person
cleaned up by hand; the notebook runner left ``.lqe-tmp``/``.lqe-old`` files and a mixed
set of notebooks.

Here a build runs in a fresh interpreter whose file operations (``os.replace``,
``os.rename``, ``os.unlink``, ``os.rmdir``, ``os.mkdir``, ``os.link``) are counted, and it
kills itself with SIGKILL just before the N-th one, for every N a whole build makes. The
next tool to take the folder must recover by itself (one ``warning: recovered …`` line)
and leave it wholly old or wholly new; the next build must then succeed. A Ctrl-C at
each step is undone at once instead (the folder exactly as before, one line).
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
import textwrap
import warnings
from pathlib import Path

import pytest
from tools_helpers import (
    code_notebook,
    python_command,
    run_tool,
    snapshot,
    tools_environment,
    worked_notebook,
    write_notebook,
)

from lqe_helpers.authoring.folder_lock import FolderLock
from lqe_helpers.authoring.swap import RecoveryWarning

#: Runs ``code`` with every file operation under the folder ``watched`` counted; SIGKILL
#: (or KeyboardInterrupt) just before the ``N``-th.
HARNESS = textwrap.dedent("""
    import os, shutil, signal, sys
    N, how, watched, code = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
    count = [0]
    def inside(args, kwargs):
        return "dir_fd" in kwargs or any(
            isinstance(arg, (str, os.PathLike))
            and os.path.abspath(arg).startswith(watched + os.sep) for arg in args[:2])
    def counted(real):
        def operation(*args, **kwargs):
            if inside(args, kwargs):
                count[0] += 1
                if count[0] == N:
                    if how == "kill":
                        os.kill(os.getpid(), signal.SIGKILL)
                    raise KeyboardInterrupt
            return real(*args, **kwargs)
        return operation
    for name in ("replace", "rename", "unlink", "remove", "rmdir", "mkdir", "link"):
        setattr(os, name, counted(getattr(os, name)))
    try:
        exec(code)
    finally:
        print(f"operations: {count[0]}", file=sys.stderr)
""")

OLD = {"a.html": "a, old", "b.html": "b, old", "gone.html": "gone", "sub/c.html": "c, old"}
NEW = {"a.html": "a, new", "b.html": "b, old", "sub/c.html": "c, new", "new/d/e.html": "e"}
WRITE = ("from lqe_helpers.authoring.output_folder import write_output_folder\n"
         "write_output_folder({out!r}, {files!r}, tool='handouts')")


def harness(code: str, n: int, how: str = "kill", *,
            watched: Path | None = None) -> subprocess.CompletedProcess[str]:
    """Run ``code`` in a fresh interpreter, stopped before its ``n``-th file operation in
    ``watched`` (default: the system's temporary folder, where every test folder is)."""
    folder = str(watched or Path(tempfile.gettempdir()).resolve())
    return subprocess.run(python_command("-c", HARNESS, str(n), how, folder, code),
                          env=tools_environment(), capture_output=True, text=True, timeout=300,
                          check=False)


def operations(code: str, watched: Path | None = None) -> int:
    """How many counted file operations ``code`` makes when nothing stops it."""
    result = harness(code, 10**9, watched=watched)
    assert result.returncode == 0, result.stderr
    return int(result.stderr.rsplit("operations: ", 1)[1])


def recovered(folder: Path) -> list[str]:
    """Take ``folder`` as a tool does (which recovers it); the recovery lines."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with FolderLock(folder):
            pass
    return [str(warning.message) for warning in caught
            if issubclass(warning.category, RecoveryWarning)]


@pytest.fixture(scope="module")
def states(tmp_path_factory) -> tuple[dict, dict, int]:
    """The output folder wholly old and wholly new, and how many operations a build makes."""
    base = tmp_path_factory.mktemp("states")
    old, new = base / "old", base / "new"
    for folder, files in ((old, OLD), (new, OLD)):
        result = harness(WRITE.format(out=str(folder), files=files), 10**9)
        assert result.returncode == 0, result.stderr
    count = operations(WRITE.format(out=str(new), files=NEW))
    return snapshot(old), snapshot(new), count


@pytest.mark.slow
def test_a_build_killed_at_every_step_is_recovered(tmp_path, states):
    old, new, count = states
    assert count > 10
    outcomes = set()
    for n in range(1, count + 1):
        out = tmp_path / f"kill-{n}"
        result = harness(WRITE.format(out=str(out), files=OLD), 10**9)
        assert result.returncode == 0, result.stderr
        (out / "mine.txt").write_text("the instructor's own file")
        result = harness(WRITE.format(out=str(out), files=NEW), n)
        assert result.returncode == -9, (n, result.stderr)  # killed
        lines = recovered(out)
        after = snapshot(out)
        assert after.pop("mine.txt") == b"the instructor's own file"
        assert after in (old, new), (n, sorted(after))
        assert len(lines) <= 1 and all("\n" not in line for line in lines)
        outcomes.add("new" if after == new else "old")
        result = harness(WRITE.format(out=str(out), files=NEW), 10**9)  # the next build
        assert result.returncode == 0, (n, result.stderr)
        after = snapshot(out)
        after.pop("mine.txt")
        assert after == new
    assert outcomes == {"old", "new"}  # killed both before and after the point of no return


@pytest.mark.slow
def test_the_recovery_says_what_it_did(tmp_path, states):
    _, new, count = states
    out = tmp_path / "out"
    harness(WRITE.format(out=str(out), files=OLD), 10**9)
    result = harness(WRITE.format(out=str(out), files=NEW), count - 3)  # while moving files
    assert result.returncode == -9
    assert any(path.name.startswith(".lqe-") for path in out.iterdir())
    [line] = recovered(out)
    assert line.startswith(f"recovered {out}: a run of handouts was killed")
    assert snapshot(out) == new
    assert recovered(out) == []  # nothing left to do


@pytest.mark.slow
def test_a_ctrl_c_at_every_step_leaves_the_folder_as_it_was(tmp_path, states):
    """An interrupt the process sees is undone at once; once every file is in place
    (removing the temporary folder), the build is complete and the next run tidies up."""
    old, new, count = states
    outcomes = []
    for n in range(1, count + 1):
        out = tmp_path / f"interrupt-{n}"
        harness(WRITE.format(out=str(out), files=OLD), 10**9)
        result = harness(WRITE.format(out=str(out), files=NEW), n, "interrupt")
        assert result.returncode != 0
        if snapshot(out) == old:
            outcomes.append("old")
            continue
        recovered(out)
        assert snapshot(out) == new, n
        outcomes.append("new")
    # Undone up to the last move; after it only the tidying up is left (to the next run).
    first_new = outcomes.index("new")
    assert outcomes == ["old"] * first_new + ["new"] * (count - first_new)
    assert first_new > count / 2


@pytest.mark.slow
def test_a_new_folder_killed_at_every_step(tmp_path):
    code = WRITE.format(out=str(tmp_path / "probe"), files=NEW)
    count = operations(code)
    new = snapshot(tmp_path / "probe")
    for n in range(1, count + 1):
        out = tmp_path / f"new-{n}"
        result = harness(WRITE.format(out=str(out), files=NEW), n)
        assert result.returncode == -9
        if out.exists():
            recovered(out)
        assert snapshot(out) in ({}, new), n  # nothing (or an empty folder), or all of it


@pytest.mark.slow
def test_student_edition_killed_then_run_again_from_the_command_line(tmp_path):
    """The issue's case end to end: the next ``make student`` recovers and succeeds."""
    source = tmp_path / "notebooks"
    for name in ("01_a.ipynb", "02_b.ipynb", "03_c.ipynb"):
        write_notebook(source / name)
    out = tmp_path / "build" / "student"
    assert run_tool("student_edition", "--source", str(source), "--out", str(out)).returncode == 0
    (source / "03_c.ipynb").unlink()
    write_notebook(source / "01_a.ipynb", worked_notebook(solution="# Task: other.\nx = 2"))
    code = ("from lqe_helpers.authoring.student_edition import main\n"
            f"main(['--source', {str(source)!r}, '--out', {str(out)!r}])")
    probe = tmp_path.parent / f"{tmp_path.name}-probe"
    shutil.copytree(tmp_path, probe)
    count = operations(code.replace(str(tmp_path), str(probe)))
    result = harness(code, count - 2)
    assert result.returncode == -9
    result = run_tool("student_edition", "--source", str(source), "--out", str(out))
    assert result.returncode == 0, result.stderr
    [line] = result.stderr.splitlines()
    assert line.startswith(f"warning: recovered {out}: a run of student_edition was killed")
    assert sorted(path.name for path in out.iterdir()) == [".lqe-manifest.json", "01_a.ipynb",
                                                            "02_b.ipynb"]


@pytest.mark.slow
def test_atomic_write_many_killed_at_every_step(tmp_path):
    """The runner's save: each folder wholly old or wholly new after the next run."""
    first, second = tmp_path / "one", tmp_path / "two"
    for folder in (first, second):
        folder.mkdir()
        for name in ("01.ipynb", "02.ipynb"):
            (folder / name).write_text(f"{name} old")
    old = snapshot(tmp_path)
    files = {str(folder / name): f"{name} new" for folder in (first, second)
             for name in ("01.ipynb", "02.ipynb")}
    code = ("from lqe_helpers.authoring.folder_lock import atomic_write_many\n"
            f"atomic_write_many({files!r})")
    probe = tmp_path.parent / f"{tmp_path.name}-probe"
    shutil.copytree(tmp_path, probe)
    count = operations(code.replace(str(tmp_path), str(probe)))
    new = snapshot(probe)
    for n in range(1, count + 1):
        shutil.rmtree(first)
        shutil.rmtree(second)
        for folder in (first, second):
            folder.mkdir()
            for name in ("01.ipynb", "02.ipynb"):
                (folder / name).write_text(f"{name} old")
        result = harness(code, n)
        assert result.returncode == -9, n
        for folder in (first, second):
            recovered(folder)
            state = {name: data for name, data in snapshot(tmp_path).items()
                     if name.startswith(folder.name + "/") or name == folder.name}
            assert state in ({k: v for k, v in old.items() if k.startswith(folder.name)},
                             {k: v for k, v in new.items() if k.startswith(folder.name)}), n


@pytest.mark.kernel
def test_the_notebook_runner_killed_while_saving_recovers_on_its_next_run(tmp_path):
    first = code_notebook(tmp_path / "01.ipynb", "print('one')")
    second = code_notebook(tmp_path / "02.ipynb", "print('two')")
    code = ("from lqe_helpers.authoring.notebook_runner import main\n"
            f"main([{str(first)!r}, {str(second)!r}])")
    probe = tmp_path.parent / f"{tmp_path.name}-probe"
    shutil.copytree(tmp_path, probe)
    count = operations(code.replace(str(tmp_path), str(probe)), watched=probe)
    result = harness(code, count - 3, watched=tmp_path)  # while moving the notebooks
    assert result.returncode == -9, result.stderr
    result = run_tool("notebook_runner", str(first), str(second))
    assert result.returncode == 0, result.stderr
    assert result.stderr.startswith(f"warning: recovered {tmp_path}: a run of notebook_runner")
    assert sorted(path.name for path in tmp_path.iterdir()) == ["01.ipynb", "02.ipynb"]


@pytest.mark.slow
def test_the_recovery_never_overwrites_a_file_changed_after_the_kill(tmp_path, states):
    _, _, count = states
    out = tmp_path / "out"
    harness(WRITE.format(out=str(out), files=OLD), 10**9)
    journal_written = 4  # kill right after the journal of the moves, before the first move
    for n in range(journal_written, count):
        shutil.rmtree(out)
        harness(WRITE.format(out=str(out), files=OLD), 10**9)
        assert harness(WRITE.format(out=str(out), files=NEW), n).returncode == -9
        journal = out / ".lqe-journal.json"
        if journal.exists() and (out / "a.html").read_text() == "a, old":
            break
    else:
        pytest.fail("no kill point between the journal and the first move")
    (out / "a.html").write_text("edited by hand after the crash")
    [line] = recovered(out)
    assert "kept as they are, changed since: a.html" in line
    assert (out / "a.html").read_text() == "edited by hand after the crash"
    assert (out / "sub" / "c.html").read_text() == "c, new"


def test_ctrl_c_while_the_files_are_moved_is_held_until_the_move_ends(tmp_path):
    """A real SIGINT in the middle of the moves: the build completes, then the interrupt."""
    out = tmp_path / "out"
    code = textwrap.dedent(f"""
        import os, signal
        from lqe_helpers.authoring.output_folder import write_output_folder
        write_output_folder({str(out)!r}, {OLD!r}, tool="handouts")
        real, calls = os.link, []
        def link(*args, **kwargs):  # a new file linked into place
            calls.append(args)
            if len(calls) == 2:
                signal.raise_signal(signal.SIGINT)  # Ctrl-C, between two moves
            return real(*args, **kwargs)
        os.link = link
        try:
            write_output_folder({str(out)!r}, {NEW!r}, tool="handouts")
        except KeyboardInterrupt:
            print("interrupted after", len(calls), "moves")
    """)
    result = subprocess.run(python_command("-c", code), env=tools_environment(),
                            capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("interrupted after")
    assert int(result.stdout.split()[2]) > 2  # every move was made first
    assert {name: data.decode() for name, data in snapshot(out).items()
            if isinstance(data, bytes) and name.endswith(".html")} == NEW


@pytest.mark.slow
def test_student_edition_killed_mid_move_is_recovered_before_the_folder_is_checked(tmp_path):
    """Issue 27: each tool checked the folder before taking it (which recovers), so a kill
    while the files moved made the next run refuse ("… was changed since student_edition
    wrote it"). Killed at a spread of file operations (the harness counts the operating
    system's, whatever the mechanism), the next command line run must succeed."""
    source, out = tmp_path / "notebooks", tmp_path / "build" / "student"
    for name in ("01_a.ipynb", "02_b.ipynb", "03_c.ipynb"):
        write_notebook(source / name)
    assert run_tool("student_edition", "--source", str(source), "--out", str(out)).returncode == 0
    base = tmp_path.parent / f"{tmp_path.name}-base"
    for name in ("01_a.ipynb", "02_b.ipynb"):
        write_notebook(source / name, worked_notebook(solution=f"# Task: other.\nx = '{name}'"))
    shutil.copytree(tmp_path, base)
    code = ("from lqe_helpers.authoring.student_edition import main\n"
            f"main(['--source', {str(source)!r}, '--out', {str(out)!r}])")
    count = operations(code)
    new = snapshot(out)
    for n in range(count // 3, count, max(1, count // 8)):
        shutil.rmtree(tmp_path)
        shutil.copytree(base, tmp_path)
        assert harness(code, n).returncode == -9
        result = run_tool("student_edition", "--source", str(source), "--out", str(out))
        assert result.returncode == 0, (n, result.stderr)
        assert snapshot(out) == new, n
