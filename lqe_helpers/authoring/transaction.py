"""Write files into a folder all or nothing, one tool at a time, and survive a kill.

- :class:`FolderLock` holds a folder for one process (``flock``, released by the system
  even when the process is killed): a second tool on the same folder stops at once with
  one line. Taking a folder first finishes or undoes a build killed there
  (:func:`lqe_helpers.authoring.journal.recover`), said in one line
  (:class:`~lqe_helpers.authoring.journal.RecoveryWarning`).
- :class:`Transaction` (and :func:`commit`) moves a set of new files into one folder as
  the journal describes (:mod:`lqe_helpers.authoring.journal`): staged, recorded, then
  moved; a failure the process sees (full disk, I/O error, Ctrl-C, SIGTERM) is undone
  at once, and a file someone changed meanwhile is never overwritten.
- :func:`atomic_write_many` does it for files in several folders (the notebook runner).

Standard library only.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import signal
import threading
import warnings
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path, PurePosixPath
from types import TracebackType

from lqe_helpers.authoring.errors import OutputFolderError, OutputWriteError, error_line, shown
from lqe_helpers.authoring.files import (
    FileState,
    as_bytes,
    check_target,
    file_sha256,
    file_state,
    link_or_copy,
    mode_for,
    sha256,
    write_new_file,
)
from lqe_helpers.authoring.journal import (
    STAGING_PREFIX,
    Journal,
    RecoveryWarning,
    Step,
    finish,
    recover,
    roll_back,
    roll_forward,
    write_journal,
)
from lqe_helpers.authoring.manifest import entry_problem

try:  # POSIX; elsewhere a folder is not locked
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]


class FolderLock:
    """Hold ``folder`` for this process while a tool writes it (a context manager).

    Another process that tries to take the same folder stops at once with
    :class:`OutputFolderError`; this process may take it again (nested). The first
    time the folder is taken, an interrupted build found there is finished or undone
    (:func:`recover`, reported as a :class:`RecoveryWarning`).
    """

    _held: dict[tuple[int, int], int] = {}  # noqa: RUF012 (one registry for the process)

    def __init__(self, folder: Path | str) -> None:
        self.folder = Path(folder)
        self._fd: int | None = None
        self._key: tuple[int, int] | None = None

    def __enter__(self) -> FolderLock:
        fd = os.open(self.folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        status = os.fstat(fd)
        self._key = (status.st_dev, status.st_ino)
        if self._key in self._held:
            os.close(fd)
            self._held[self._key] += 1
            return self
        try:
            if fcntl is not None:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise OutputFolderError(
                f"another course tool is writing {shown(self.folder)} right now; wait until "
                f"it ends, then run this again (nothing was changed)") from None
        except OSError:
            pass  # a file system without locks: go on unlocked
        self._fd = fd
        self._held[self._key] = 1
        try:
            note = recover(self.folder)
        except BaseException:
            self._release()
            raise
        if note:
            warnings.warn(note, RecoveryWarning, stacklevel=2)
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        self._release()

    def _release(self) -> None:
        assert self._key is not None
        self._held[self._key] -= 1
        if self._held[self._key] == 0:
            del self._held[self._key]
            if self._fd is not None:
                os.close(self._fd)  # releases the lock
                self._fd = None


class Transaction:
    """A set of file moves in one folder, made all or nothing (see the module docstring).

    Call :meth:`stage`, then :meth:`apply`, then :meth:`finish`; :meth:`roll_back` after
    a failure in any of them. The caller holds the folder (:class:`FolderLock`).
    """

    def __init__(self, folder: Path, tool: str) -> None:
        self.folder = Path(folder)
        self.journal = Journal(tool, "staging", STAGING_PREFIX + secrets.token_hex(8))
        self._journal_written = False

    @property
    def staging(self) -> Path:
        """The temporary folder of this transaction."""
        return self.folder / self.journal.staging

    def stage(self, writes: Mapping[str, bytes], deletes: Iterable[str] = ()) -> None:
        """Write the new files and keep the old ones aside; the folder is not changed yet.

        Parameters
        ----------
        writes : mapping of str to bytes
            Relative POSIX path → new content, in the order they are to be moved.
        deletes : iterable of str
            Relative paths of files to delete (after the writes).
        """
        for name in [*writes, *deletes]:
            problem = entry_problem(self.folder, name, manifest_ok=True)
            if problem:
                raise ValueError(f"file names must be plain relative paths inside "
                                 f"{self.folder}, got {name!r} ({problem})")
        write_journal(self.folder, self.journal)
        self._journal_written = True
        self.staging.mkdir(mode=0o700)
        folders: list[str] = []
        for name, data in writes.items():
            target = self.folder / name
            for parent in reversed(PurePosixPath(name).parents[:-1]):
                if not (self.folder / parent).exists() and parent.as_posix() not in folders:
                    folders.append(parent.as_posix())
            staged = self.staging / "new" / name
            staged.parent.mkdir(parents=True, exist_ok=True)
            write_new_file(staged, data, mode=mode_for(target), named=target)
            self.journal.steps.append(Step(name, sha256(data), self._keep_old(name)))
        for name in deletes:
            self.journal.steps.append(Step(name, None, self._keep_old(name)))
        self.journal.folders = folders

    def _keep_old(self, name: str) -> str | None:
        """A hard link (or copy) of the file ``name`` in the temporary folder; its SHA-256."""
        target = self.folder / name
        digest = file_sha256(target)
        if digest is not None:
            backup = self.staging / "old" / name
            backup.parent.mkdir(parents=True, exist_ok=True)
            link_or_copy(target, backup)
        return digest

    def apply(self, expected: Mapping[str, FileState | str | None] | None = None, *,
              strict: bool = True) -> list[str]:
        """Move everything into place; return the names kept because they changed.

        Parameters
        ----------
        expected : mapping, optional
            Name → what the file must still be before it is replaced or deleted: a
            :class:`FileState` (size, time and SHA-256), a SHA-256, or ``None`` (it
            must not exist). A file that is not what is expected was changed by
            someone else since the tool looked at it.
        strict : bool
            A changed file stops everything (:class:`OutputFolderError`); else it is
            kept as it is, its move dropped, and its name returned.
        """
        changed = [step.name for step in self.journal.steps
                   if step.name in (expected or {})
                   and not _is_as_expected(self.folder / step.name, expected[step.name])]
        if changed and strict:
            raise OutputFolderError(
                f"{', '.join(map(shown, changed))} in {shown(self.folder)} changed while the "
                f"build ran; nothing was changed (run it again)")
        self.journal.steps = [step for step in self.journal.steps if step.name not in changed]
        self.journal.state = "committing"
        write_journal(self.folder, self.journal)
        _, kept = roll_forward(self.folder, self.journal, strict=strict)
        return changed + kept

    def finish(self) -> None:
        """Remove the temporary folder and the journal: the transaction is over."""
        finish(self.folder, self.journal)

    def roll_back(self) -> None:
        """Undo whatever was done, from the journal (safe to call at any stage)."""
        if not self._journal_written:
            return
        if self.journal.state == "committing":
            self.journal.state = "rolling-back"
            write_journal(self.folder, self.journal)
            roll_back(self.folder, self.journal)
        self.finish()


def _is_as_expected(path: Path, expected: FileState | str | None) -> bool:
    if expected is None:
        return not os.path.lexists(path)
    if isinstance(expected, FileState):
        return file_state(path) == expected
    return file_sha256(path) == expected


def commit(folder: Path, writes: Mapping[str, bytes], deletes: Iterable[str] = (), *,
           tool: str, expected: Mapping[str, FileState | str | None] | None = None,
           strict: bool = True) -> list[str]:
    """Make one :class:`Transaction` in ``folder`` (which the caller holds); undo it on failure.

    Returns
    -------
    list of str
        The names kept because someone changed them (only when ``strict`` is false).

    Raises
    ------
    OutputWriteError
        If the undo itself fails; the journal then lets the next run finish it.
    """
    transaction = Transaction(folder, tool)
    with signals_deferred():
        try:
            transaction.stage(writes, deletes)
            kept = transaction.apply(expected, strict=strict)
        except BaseException as error:
            try:
                transaction.roll_back()
            except OSError as undo_error:
                raise OutputWriteError(
                    f"writing into {shown(folder)} failed ({error_line(error)}) and so did "
                    f"putting the old files back ({error_line(undo_error)}); the next run of a "
                    f"course tool on {shown(folder)} finishes putting them back") from error
            raise
        transaction.finish()
    return kept


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) and SIGTERM until the block ends, then deliver them.

    Moving a build's files into place takes milliseconds; a Ctrl-C then would only
    cost an undo. Outside the main thread (where Python cannot set handlers) the
    signals are not held.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []
    previous = {number: signal.getsignal(number) for number in (signal.SIGINT, signal.SIGTERM)}
    for number in previous:
        signal.signal(number, lambda signum, frame: received.append(signum))
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler if handler is not None else signal.SIG_DFL)
        if received:
            signal.raise_signal(received[0])


def atomic_write_many(files: Mapping[Path | str, bytes | str], *,
                      expected: Mapping[Path, FileState | None] | None = None,
                      tool: str = "atomic_write_many") -> list[Path]:
    """Replace (or create) several files, all or none; return the files written.

    The files are grouped by folder; each folder is held (:class:`FolderLock`) and
    written as one :class:`Transaction`. Every new content is staged in every folder
    before the first file is moved (a full disk stops there, with nothing changed); a
    failure later puts every old file back. A kill leaves each folder's journal, from
    which the next tool on that folder finishes the moves: within a folder, wholly old
    or wholly new (across folders, a kill can leave one folder new and another old).

    Parameters
    ----------
    files : mapping of Path to bytes or str
        Target path → new content (``str`` is written as UTF-8).
    expected : mapping of Path to FileState or None, optional
        What each target must still be (see :meth:`Transaction.apply`). A target that
        changed since is kept as it is and left out of the result; without
        ``expected`` the files are replaced whatever they hold.
    tool : str
        The name recorded in the journals.

    Returns
    -------
    list of Path
        The targets written, in the mapping's order.

    Raises
    ------
    FileSafetyError
        If a target is a symbolic link or a folder (checked before anything is written).
    OSError
        If writing fails (every target is then as it was).
    """
    targets = {Path(path): as_bytes(data) for path, data in files.items()}
    for path in targets:
        check_target(path)
    groups: dict[Path, dict[str, bytes]] = {}
    for path, data in targets.items():
        groups.setdefault(Path(os.path.realpath(path.parent)), {})[path.name] = data
    wanted = {Path(os.path.realpath(path.parent)) / path.name: state
              for path, state in (expected or {}).items()}
    kept: list[Path] = []
    with contextlib.ExitStack() as held:
        for folder in sorted(groups):
            held.enter_context(FolderLock(folder))
        held.enter_context(signals_deferred())
        transactions: list[Transaction] = []
        try:
            for folder, writes in groups.items():
                transactions.append(Transaction(folder, tool))
                transactions[-1].stage(writes)
            for transaction in transactions:
                states = {name: wanted[transaction.folder / name] for name in groups[
                    transaction.folder] if transaction.folder / name in wanted}
                kept += [transaction.folder / name for name in
                         transaction.apply(states, strict=expected is None)]
        except BaseException as error:
            try:
                for transaction in reversed(transactions):
                    transaction.roll_back()
            except OSError as undo_error:
                raise OutputWriteError(
                    f"writing failed ({error_line(error)}) and so did putting the old files "
                    f"back ({error_line(undo_error)}); the next run of a course tool on "
                    f"those folders finishes putting them back") from error
            raise
        for transaction in transactions:
            transaction.finish()
    return [path for path in targets
            if Path(os.path.realpath(path.parent)) / path.name not in kept]
