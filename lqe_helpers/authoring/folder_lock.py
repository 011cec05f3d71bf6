"""One course tool at a time in a folder, and several files replaced all or none.

:class:`FolderLock` holds a folder while a tool writes it, and first finishes or undoes a
swap a killed run left there (:func:`~lqe_helpers.authoring.swap.recover`);
:func:`atomic_write_many` swaps new contents into several folders at once
(:func:`~lqe_helpers.authoring.swap.swap_folders`), keeping a file an author saved
meanwhile.
"""

from __future__ import annotations

import contextlib
import os
import warnings
from collections.abc import Mapping
from pathlib import Path

try:
    from filelock import lock_descriptor
except ImportError:  # make clean with a broken .venv runs on the system's Python
    lock_descriptor = None
from lqe_helpers.authoring.errors import OutputFolderError, shown
from lqe_helpers.authoring.files import FileState, as_bytes, check_target
from lqe_helpers.authoring.swap import RecoveryWarning, recover, swap_folders


class FolderLock:
    """Hold ``folder`` for this process while a tool writes it (a context manager).

    A :func:`filelock.lock_descriptor` lock on the folder itself (released by the system
    even when the process is killed): another process stops at once with
    :class:`OutputFolderError`; this process may take it again (nested). The first
    time, a swap killed there is finished or undone (:func:`recover`), said as a
    :class:`RecoveryWarning`.
    """

    _held: dict[tuple[int, int], int] = {}  # noqa: RUF012 (one registry for the process)

    def __init__(self, folder: Path | str) -> None:
        self.folder = Path(folder)
        self._fd: int | None = None
        self._key = (0, 0)

    def __enter__(self) -> FolderLock:
        fd = os.open(self.folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        status = os.fstat(fd)
        self._key = (status.st_dev, status.st_ino)
        if self._key in self._held:
            os.close(fd)
            self._held[self._key] += 1
            return self
        try:
            locked = _lock(fd)
        except OSError:
            locked = True  # a file system without locks: go on unlocked
        if not locked:
            os.close(fd)
            raise OutputFolderError(
                f"another course tool is writing {shown(self.folder)} right now; wait until "
                f"it ends, then run this again (nothing was changed)")
        self._fd, self._held[self._key] = fd, 1
        try:
            note = recover(self.folder)
        except BaseException:
            self.__exit__()
            raise
        if note:
            warnings.warn(note, RecoveryWarning, stacklevel=2)
        return self

    def __exit__(self, *exc: object) -> None:
        self._held[self._key] -= 1
        if self._held[self._key] == 0:
            del self._held[self._key]
            if self._fd is not None:
                os.close(self._fd)  # releases the lock
                self._fd = None


def _lock(fd: int) -> bool:
    """Lock the open folder ``fd`` (``filelock``'s flock); ``False`` if another holds it."""
    if lock_descriptor is not None:
        return lock_descriptor(fd, blocking=False)
    import fcntl

    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


def atomic_write_many(files: Mapping[Path | str, bytes | str], *,
                      expected: Mapping[Path, FileState | None] | None = None,
                      tool: str = "atomic_write_many") -> list[Path]:
    """Replace (or create) several files, all or none; return the files written.

    Grouped by folder: each folder is held (:class:`FolderLock`) and swapped; every new
    content is staged in every folder before the first rename. A target that is not
    its ``expected`` :class:`FileState` right before its rename (an author's edit) is
    kept as it is and left out of the result. Within a folder a kill leaves wholly old
    or wholly new after the next run; across folders one may be new and another old.

    Raises
    ------
    FileSafetyError
        If a target is a symbolic link or a folder (before anything is written).
    OSError
        If writing fails (every target is then as it was).
    """
    targets = {Path(path): as_bytes(data) for path, data in files.items()}
    for path in targets:
        check_target(path)
    real = {path: Path(os.path.realpath(path.parent)) for path in targets}
    groups: dict[Path, dict[str, bytes]] = {}
    for path, data in targets.items():
        groups.setdefault(real[path], {})[path.name] = data
    states: dict[Path, dict[str, FileState]] = {}
    for path, state in (expected or {}).items():
        if state is not None:
            states.setdefault(real[path], {})[path.name] = state
    with contextlib.ExitStack() as held:
        for folder in sorted(groups):
            held.enter_context(FolderLock(folder))
        kept = swap_folders({folder: (writes, {}, {}, states.get(folder, {}))
                      for folder, writes in groups.items()}, tool, "those folders", strict=False)
    return [path for path in targets if (real[path], path.name) not in kept]
