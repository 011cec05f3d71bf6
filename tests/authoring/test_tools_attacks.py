"""More attacks on the instructor tools, as a hostile user would try them.

Beyond the cases issue 19 lists: a forged or odd journal, files that are huge or not
files, names with newlines, folders held by another tool or reached through a link, a
time limit near the largest float, ``--out`` at the home folder.
"""

from __future__ import annotations

import hashlib
import json
import os
import resource
import stat
import subprocess
import warnings
from pathlib import Path

import pytest
from tools_helpers import (
    MANIFEST,
    error_lines,
    python_command,
    run_tool,
    snapshot,
    tools_environment,
    write_notebook,
)

from lqe_helpers.authoring.errors import OutputFolderError
from lqe_helpers.authoring.folder_lock import FolderLock
from lqe_helpers.authoring.output_folder import write_output_folder
from lqe_helpers.authoring.swap import JOURNAL_NAME, RecoveryWarning


def journal(staging: str, writes: list | None = None, deletes: list | None = None, *,
            undo: bool = False) -> str:
    return json.dumps({"format": 2, "tool": "handouts", "staging": staging, "undo": undo,
                       "writes": {name: [new, old] for name, new, old in writes or []},
                       "deletes": dict(deletes or []), "folders": []})


STAGING = ".lqe-build-00000000000000ff"


def sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


# --- a forged journal ---------------------------------------------------------------------------

@pytest.mark.parametrize(("content", "said"), [
    (journal(STAGING, [["../outside.txt", "0" * 64, None]]), "lists '../outside.txt'"),
    (journal("../.."), "is not a journal"),
    (journal(".lqe-build-x/../.."), "is not a journal"),
    (journal(".lqe-build-mine"), "is not a journal"),  # a user's folder named like ours
    (json.dumps({"format": 1, "tool": "handouts", "state": "committing",
                 "staging": STAGING, "folders": [], "steps": []}), "is not a journal"),
    ("{not json", "is not a journal"),
])
def test_a_forged_journal_touches_nothing(tmp_path, content, said):
    out = tmp_path / "out"
    write_output_folder(out, {"a.html": "a"}, tool="handouts")
    (tmp_path / "outside.txt").write_text("someone's file")
    (out / ".lqe-build-mine").mkdir()
    (out / ".lqe-build-mine" / "draft.txt").write_text("the instructor's draft")
    (out / JOURNAL_NAME).write_text(content)
    before = snapshot(tmp_path)
    with pytest.raises(OutputFolderError, match=said):
        write_output_folder(out, {"a.html": "b"}, tool="handouts")
    assert snapshot(tmp_path) == before


def test_a_forged_delete_of_a_file_not_in_the_manifest_deletes_nothing(tmp_path):
    """Issue 26: a forged delete step made student_edition delete a user's file."""
    out = tmp_path / "out"
    write_output_folder(out, {"a.html": "a"}, tool="handouts")
    (out / "mine.txt").write_text("the instructor's notes")
    manifest = (out / MANIFEST).read_bytes()
    (out / JOURNAL_NAME).write_text(journal(
        STAGING, [[MANIFEST, "1" * 64, sha(manifest)]],
        [["mine.txt", sha(b"the instructor's notes")]]))
    before = snapshot(out)
    write_notebook(tmp_path / "notebooks" / "01_a.ipynb")
    result = run_tool("student_edition", "--source", str(tmp_path / "notebooks"), "--out",
                      str(out))
    assert result.returncode == 1
    assert error_lines(result.stderr) == [
        f"error: {out / JOURNAL_NAME} names 'mine.txt', which {MANIFEST} does not list as the "
        f"tool's; nothing was changed: move the folder {out} away"]
    assert snapshot(out) == before
    (out / JOURNAL_NAME).write_text(journal(STAGING, [], [["mine.txt", sha(b"x")]]))
    with pytest.raises(OutputFolderError, match="it deletes files, but writes no manifest"):
        write_output_folder(out, {"a.html": "b"}, tool="handouts")
    assert (out / "mine.txt").read_text() == "the instructor's notes"


def test_a_forged_undo_removes_only_files_the_swap_put_there(tmp_path):
    """An undo removes a created file only if it is the very file the swap staged (its
    ``keep/`` link), so a forged journal cannot make it remove a user's file."""
    out = tmp_path / "out"
    write_output_folder(out, {"a.html": "a"}, tool="handouts")
    (out / "mine.txt").write_text("mine")
    staging = out / STAGING
    (staging / "keep").mkdir(parents=True)
    (staging / "made-by").write_text("handouts\n")
    (staging / "keep" / "mine.txt").write_text("mine")  # same content, another file
    (out / JOURNAL_NAME).write_text(journal(STAGING, [["mine.txt", sha(b"mine"), None]],
                                            undo=True))
    with pytest.warns(RecoveryWarning, match=r"it is now undone \(0 file\(s\) put back\)"), \
            FolderLock(out):
        pass
    assert (out / "mine.txt").read_text() == "mine"
    assert sorted(path.name for path in out.iterdir()) == [MANIFEST, "a.html", "mine.txt"]


def test_user_files_named_like_the_tools_temporary_files_are_kept(tmp_path):
    """Issue 26: the recovery's glob deleted a user file named like a journal temp file."""
    out = tmp_path / "out"
    write_output_folder(out, {"a.html": "a"}, tool="handouts")
    for name in (f".{JOURNAL_NAME}.abc.lqe-tmp", ".lqe-build-0123456789abcdef"):
        (out / name).mkdir() if "build" in name else (out / name).write_text("mine")
    (out / ".lqe-build-0123456789abcdef" / "x.txt").write_text("mine")  # no stamp
    before = snapshot(out)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with FolderLock(out):
            pass
    write_output_folder(out, {"a.html": "b"}, tool="handouts")
    assert {k: v for k, v in snapshot(out).items() if k.startswith(".lqe-build") or
            k.endswith("lqe-tmp")} == {k: v for k, v in before.items()
                                        if k.startswith(".lqe-build") or k.endswith("lqe-tmp")}


def test_a_staging_folder_reached_through_a_link_is_never_followed(tmp_path):
    """A journal naming a 'staged' file behind a link would move someone's file in."""
    out = tmp_path / "out"
    write_output_folder(out, {"a.html": "a"}, tool="handouts")
    elsewhere = tmp_path / "home"
    elsewhere.mkdir()
    (elsewhere / "thesis.tex").write_text("three years of work")
    staging = out / STAGING
    staging.mkdir()
    (staging / "made-by").write_text("handouts\n")
    (staging / "new").symlink_to(elsewhere)
    (out / JOURNAL_NAME).write_text(journal(STAGING, [["thesis.tex", "1" * 64, None]]))
    with pytest.warns(RecoveryWarning, match=r"0 of 1 file\(s\) \(its manifest included\) hold"), \
            FolderLock(out):
        pass  # taking the folder recovers it
    assert (elsewhere / "thesis.tex").read_text() == "three years of work"
    assert not (out / "thesis.tex").exists()
    assert not (out / JOURNAL_NAME).exists()
    assert not os.path.lexists(staging)


@pytest.mark.parametrize(("tool", "name"), [
    ("clean", MANIFEST), ("clean", JOURNAL_NAME), ("student_edition", MANIFEST),
    ("student_edition", JOURNAL_NAME),
    pytest.param("notebook_runner", JOURNAL_NAME, marks=pytest.mark.slow)])
def test_a_fifo_named_like_the_tools_files_never_blocks(tmp_path, tool, name):
    """Issue 27: a fifo named .lqe-manifest.json or .lqe-journal.json blocked these tools."""
    source = tmp_path / "notebooks"
    path = write_notebook(source / "01_a.ipynb")
    out = source if tool == "notebook_runner" else tmp_path / "out"
    if tool != "notebook_runner":
        write_output_folder(out, {"01_a.ipynb": "x"}, tool="student_edition")
        (out / name).unlink(missing_ok=True)
    else:
        out.mkdir(exist_ok=True)
    os.mkfifo(out / name)
    args = {"clean": [str(out)], "notebook_runner": [str(path)],
            "student_edition": ["--source", str(source), "--out", str(out)]}[tool]
    result = run_tool(tool, *args, timeout=60)
    assert result.returncode == 1
    [line] = error_lines(result.stderr)
    assert "not a regular file" in line or "is not a journal" in line, line
    assert stat.S_ISFIFO(os.lstat(out / name).st_mode)


@pytest.mark.parametrize("kind", ["folder", "link", "huge"])
def test_an_odd_journal_file_is_one_line(tmp_path, kind):
    out = tmp_path / "out"
    write_output_folder(out, {"a.html": "a"}, tool="handouts")
    path = out / JOURNAL_NAME
    if kind == "folder":
        path.mkdir()
    elif kind == "link":
        (tmp_path / "journal.json").write_text(journal(STAGING))
        path.symlink_to(tmp_path / "journal.json")
    else:
        with open(path, "wb") as file:
            file.truncate(100 * 2**20)  # sparse: 100 MB long, nothing written
    result = run_tool("clean", str(out))
    assert result.returncode == 1
    assert result.stderr == (f"error: {path} is not a journal the course tools can read; "
                             f"nothing was changed: move the folder {out} away or write "
                             f"elsewhere\n")
    assert (out / "a.html").exists()


# --- huge files, files that are not files --------------------------------------------------

@pytest.mark.slow
def test_a_huge_file_in_the_way_is_hashed_in_pieces(tmp_path):
    """A 4 GB file listed in the manifest, under a 1 GB memory limit: no MemoryError."""
    out = tmp_path / "out"
    write_output_folder(out, {"a.html": "a", "big.bin": "small"}, tool="handouts")
    with open(out / "big.bin", "wb") as file:
        file.truncate(4 * 2**30)  # sparse
    limit = 2**30

    def limited() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    result = subprocess.run(python_command("-m", "lqe_helpers.authoring.clean", str(out)),
                            env=tools_environment(), capture_output=True, text=True,
                            timeout=300, preexec_fn=limited, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout == f"kept in {out}: big.bin (not written by the tools, or changed " \
                            f"since)\n"


def test_a_huge_manifest_is_one_line(tmp_path):
    out = tmp_path / "out"
    write_output_folder(out, {"a.html": "a"}, tool="handouts")
    with open(out / MANIFEST, "wb") as file:
        file.truncate(200 * 2**20)
    with pytest.raises(OutputFolderError, match="more than a manifest's"):
        write_output_folder(out, {"a.html": "b"}, tool="handouts")


@pytest.mark.parametrize("kind", ["fifo", "folder"])
@pytest.mark.slow
def test_a_source_named_like_a_notebook_that_is_not_a_file_is_refused(tmp_path, kind):
    source = tmp_path / "notebooks"
    write_notebook(source / "01_real.ipynb")
    odd = source / "02_odd.ipynb"
    os.mkfifo(odd) if kind == "fifo" else odd.mkdir()
    result = run_tool("student_edition", "--source", str(source), "--out",
                      str(tmp_path / "out"), timeout=60)
    assert result.returncode == 1
    assert result.stderr == (f"error: 02_odd.ipynb in {source} is named like a notebook but "
                             f"not a file (a folder, a fifo, a device); rename or remove it\n")
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_a_notebook_named_with_a_newline_keeps_every_line_one_line(tmp_path):
    source = tmp_path / "notebooks"
    write_notebook(source / "01_two\nlines.ipynb")
    out = tmp_path / "out"
    result = run_tool("student_edition", "--source", str(source), "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert result.stdout == f"{str(out / '01_two') + chr(10) + 'lines.ipynb'!r}\n"
    (out / "01_two\nlines.ipynb").write_text("changed by hand")
    result = run_tool("student_edition", "--source", str(source), "--out", str(out))
    assert result.returncode == 1
    assert result.stderr.count("\n") == 1 and "'01_two\\nlines.ipynb' was changed" \
        in result.stderr, result.stderr


# --- folders held, linked, or the home folder ----------------------------------------------------

def test_clean_leaves_a_folder_another_tool_is_writing(tmp_path):
    held, other = tmp_path / "held", tmp_path / "other"
    write_output_folder(held, {"a.html": "a"}, tool="handouts")
    write_output_folder(other, {"b.html": "b"}, tool="handouts")
    with FolderLock(held):
        result = run_tool("clean", str(held), str(other))
    assert result.returncode == 1
    assert result.stderr == (f"error: another course tool is writing {held} right now; wait "
                             f"until it ends, then run this again (nothing was changed)\n")
    assert (held / "a.html").exists()
    assert not other.exists()


def test_clean_through_a_linked_output_folder_keeps_the_link(tmp_path):
    real = tmp_path / "big-disk" / "handouts"
    write_output_folder(real, {"a.html": "a"}, tool="handouts")
    link = tmp_path / "handouts"
    link.symlink_to(real)
    result = run_tool("clean", str(link))
    assert result.returncode == 0, result.stderr
    assert link.is_symlink() and list(real.iterdir()) == []


@pytest.mark.slow
def test_out_at_a_home_folder_adds_only_its_own_files(tmp_path):
    """Allowed on purpose: the tool adds its files and a manifest, and clean takes back
    exactly those."""
    home = tmp_path / "home"
    (home / "thesis").mkdir(parents=True)
    (home / "thesis" / "main.tex").write_text("mine")
    (home / ".bashrc").write_text("mine")
    before = snapshot(home)
    source = tmp_path / "notebooks"
    write_notebook(source / "01_a.ipynb")
    result = run_tool("student_edition", "--source", str(source), "--out", "~/x",
                      env={"HOME": str(home)}, cwd=tmp_path)
    assert result.returncode == 1  # no shell expanded it: it would make a folder named '~'
    assert result.stderr.startswith("error: the output folder ~/x starts with '~', which no "
                                    "shell expanded")
    assert not (tmp_path / "~").exists()
    result = run_tool("student_edition", "--source", str(source), "--out", str(home))
    assert result.returncode == 0, result.stderr
    assert sorted(set(snapshot(home)) - set(before)) == [MANIFEST, "01_a.ipynb"]
    assert run_tool("clean", str(home)).returncode == 0
    assert snapshot(home) == before


@pytest.mark.parametrize("value", ["1e308", "1e9", "604801"])
@pytest.mark.slow
def test_a_time_limit_near_the_largest_float_is_one_line(tmp_path, value):
    path = write_notebook(tmp_path / "01.ipynb")
    result = run_tool("notebook_runner", str(path), "--timeout", value)
    assert result.returncode == 1
    assert result.stderr == (f"error: argument --timeout: must be a number of seconds > 0, got "
                             f"{value!r} (at most 604800, a week); see python -m "
                             f"lqe_helpers.authoring.notebook_runner --help\n")


# --- read-only folders: refused before anything runs ----------------------------------------------

def test_a_read_only_output_folder_is_refused_before_any_notebook_runs(tmp_path, monkeypatch):
    from lqe_helpers.authoring import handouts

    source = tmp_path / "notebooks"
    write_notebook(source / "01_a.ipynb")
    out = tmp_path / "out"
    out.mkdir()
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda path, mode, **kwargs: (
        False if Path(path) == out else real_access(path, mode, **kwargs)))

    def must_not_run(*args, **kwargs):
        raise AssertionError("a notebook ran although nothing could be written")

    monkeypatch.setattr(handouts, "execute_notebook", must_not_run)
    with pytest.raises(OutputFolderError, match=f"cannot write into {out}: {out} is read-only "
                                                f"for you; nothing was done"):
        handouts.build_handouts(source, out, mathjax_url="")


def test_the_runner_refuses_a_read_only_folder_before_running(tmp_path, monkeypatch):
    from lqe_helpers.authoring import notebook_runner
    from lqe_helpers.authoring.errors import NotebookFileError

    path = write_notebook(tmp_path / "01.ipynb")
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda folder, mode, **kwargs: (
        False if Path(folder) == tmp_path else real_access(folder, mode, **kwargs)))
    monkeypatch.setattr(notebook_runner, "execute_notebook", lambda *args: pytest.fail("ran"))
    with pytest.raises(NotebookFileError, match=f"cannot save into {tmp_path}: it is read-only"):
        notebook_runner.run_notebooks([path])


@pytest.fixture
def read_only_mount(tmp_path):
    """A folder on a real read-only bind mount (root with mount rights only; else skipped)."""
    folder = tmp_path / "read-only"
    folder.mkdir()
    (folder / "kept.txt").write_text("kept")
    mounted = subprocess.run(["mount", "--bind", str(folder), str(folder)], capture_output=True,
                             check=False).returncode == 0
    if not mounted:
        pytest.skip("cannot bind-mount here (needs root and mount rights)")
    try:
        if subprocess.run(["mount", "-o", "remount,ro,bind", str(folder)], capture_output=True,
                          check=False).returncode != 0:
            pytest.skip("cannot remount read-only here")
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=False)


@pytest.mark.slow
def test_a_real_read_only_file_system(tmp_path, read_only_mount):
    source = tmp_path / "notebooks"
    write_notebook(source / "01_a.ipynb")
    for out in (read_only_mount, read_only_mount / "new"):
        result = run_tool("student_edition", "--source", str(source), "--out", str(out))
        assert result.returncode == 1
        assert result.stderr == (f"error: cannot write into {out}: {read_only_mount} is "
                                 f"read-only for you; nothing was done\n")
    assert sorted(path.name for path in read_only_mount.iterdir()) == ["kept.txt"]
