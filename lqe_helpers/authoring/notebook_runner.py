"""Execute notebooks top to bottom in a fresh kernel and save them, ready to commit.

``python -m lqe_helpers.authoring.notebook_runner notebooks/*.ipynb`` (or ``make notebooks``).
The saved notebooks carry outputs but no widget state and no execution timings,
so a re-run with unchanged code gives a byte-identical file.

Every notebook is read and checked first, then every one is executed, and only when
all have run to the end are they saved, all together and atomically
(:func:`~lqe_helpers.authoring.folder_lock.atomic_write_many`: staged beside them, then
swapped in with renames; if one move fails the others are undone; if the process is killed
while moving them, the next run finishes the move first). So a failure anywhere (a bad
file, a cell that raises, a cell past its time limit, a kernel that dies, a full disk,
Ctrl-C, SIGTERM) leaves every notebook byte-identical. A notebook an author saved while
the run went on is never overwritten: it is kept, and the runner says so and exits 1.
"""

from __future__ import annotations

from lqe_helpers.authoring.command_line import interrupt_exits_quietly

with interrupt_exits_quietly(__name__):  # Ctrl-C while importing: one line
    import argparse
    import contextlib
    import os
    import sys
    from collections.abc import Sequence
    from pathlib import Path

    from lqe_helpers.authoring.command_line import CommandLineParser, run_command
    from lqe_helpers.authoring.errors import NotebookFileError, shown, summarise
    from lqe_helpers.authoring.execution import (
        CELL_TIMEOUT,
        execute_notebook,
        positive_seconds,
    )
    from lqe_helpers.authoring.files import FileState, file_state, refuse_symlink
    from lqe_helpers.authoring.folder_lock import FolderLock, atomic_write_many
    from lqe_helpers.authoring.notebook_io import (
        notebook_bytes,
        parse_notebook,
        read_notebook_bytes,
    )

#: The name the runner records in the journal of a save.
TOOL_NAME = "notebook_runner"


def _check_paths(paths: Sequence[Path]) -> dict[Path, FileState]:
    """The notebooks to run (duplicates of one file dropped), each with what its file was.

    Raises
    ------
    NotebookFileError
        Naming the paths that are not existing ``.ipynb`` files, or the first one
        that is a symbolic link or not a valid notebook (nbformat 4).
    """
    bad = [str(path) for path in paths if path.suffix != ".ipynb" or not path.is_file()]
    if bad:
        raise NotebookFileError(f"notebooks must be existing .ipynb files, got {summarise(bad)}")
    unique: dict[Path, FileState] = {}
    seen: set[str] = set()
    for path in paths:
        refuse_symlink(path)
        key = os.path.normcase(os.path.realpath(path))
        raw = read_notebook_bytes(path)
        parse_notebook(path, raw)  # every notebook is checked before any runs
        state = file_state(path, raw)
        if key not in seen and state is not None:
            seen.add(key)
            unique[path] = state
    return unique


def run_notebooks(paths: Sequence[Path | str], *, timeout: float = CELL_TIMEOUT,
                  log: bool = True) -> tuple[list[Path], list[Path]]:
    """Execute each notebook and save it in place, all or none.

    The notebooks' folders are held for the whole run (a second runner on them stops at
    once; a save killed part-way before is finished first). Every path is checked, then
    every notebook executed; only if all run to the end are they saved, together and
    atomically (:func:`~lqe_helpers.authoring.folder_lock.atomic_write_many`). A notebook
    whose file would not change is not rewritten. A notebook whose file changed while
    the run went on (size, time or content: an edit saved from JupyterLab) is kept as it
    is on disk: nothing is written for it.

    Parameters
    ----------
    paths : sequence of Path or str
        The notebooks (``.ipynb`` files; not symbolic links).
    timeout : float
        Seconds one cell may run.
    log : bool
        Print ``executing <path>`` before each run.

    Returns
    -------
    saved : list of Path
        The notebooks saved with their new outputs.
    kept : list of Path
        The notebooks kept as they are on disk because they changed during the run.

    Raises
    ------
    NotebookFileError, NotebookRunError, OSError
        As :func:`execute_notebook` and :func:`atomic_write_many`; no file is changed.
    """
    paths = [Path(path) for path in paths]
    with contextlib.ExitStack() as held:
        for folder in sorted({Path(os.path.realpath(path.parent)) for path in paths
                              if path.parent.is_dir()}):
            held.enter_context(FolderLock(folder))
        checked = _check_paths(paths)
        for folder in {path.parent for path in checked}:
            if not os.access(folder, os.W_OK | os.X_OK):
                raise NotebookFileError(f"cannot save into {shown(folder)}: it is read-only "
                                        f"for you; nothing was run")
        results: dict[Path, bytes] = {}
        for path, state in checked.items():
            if log:
                print(f"executing {shown(path)}", flush=True)
            content = notebook_bytes(execute_notebook(path, timeout))
            if file_state(path) != state:
                results[path] = content  # changed meanwhile: the save below keeps it
            elif path.read_bytes() != content:
                results[path] = content
            elif log:
                print(f"unchanged {shown(path)} (not rewritten)", flush=True)
        written = atomic_write_many(results, expected={path: checked[path] for path in results},
                                    tool=TOOL_NAME)
    return written, [path for path in results if path not in written]


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: execute the notebooks named, then save them all (or none)."""
    parser = CommandLineParser(
        prog="python -m lqe_helpers.authoring.notebook_runner",
        description="Execute notebooks top to bottom in a fresh kernel each; once every one "
                    "has run to the end, save them all in place (atomically). Any failure "
                    "changes no file.")
    parser.add_argument("notebooks", nargs="+", type=Path, metavar="NOTEBOOK",
                        help=".ipynb file to execute and save")
    parser.add_argument("--timeout", type=positive_seconds, default=CELL_TIMEOUT,
                        metavar="SECONDS",
                        help=f"seconds one cell may run before the run stops "
                             f"(default: {CELL_TIMEOUT})")

    def command(args: argparse.Namespace) -> int:
        saved, kept = run_notebooks(args.notebooks, timeout=args.timeout)
        for path in saved:
            print(f"saved {shown(path)}")
        for path in kept:
            print(f"error: kept {shown(path)} as it is on disk: it changed while the run went "
                  f"on (an edit saved meanwhile?), so its new outputs were not written; run "
                  f"it again", file=sys.stderr)
        return 1 if kept else 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
