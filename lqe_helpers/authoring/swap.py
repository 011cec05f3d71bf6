"""Swap a finished build into a folder with renames; one tool at a time; survive a kill.

A swap (:func:`swap_folders`: a build's output folder, or
:func:`~lqe_helpers.authoring.folder_lock.atomic_write_many`) in a folder:

1. writes every new file into a temporary folder beside them, ``.lqe-build-<16 hex>/``
   (``new/<name>``, linked into place later, so it proves which files the swap placed),
   stamped with the tool's name;
2. writes the journal :data:`JOURNAL_NAME`: the temporary folder, every file to replace
   or create with the SHA-256 of its old and new content, every file to delete;
3. moves each old file aside (``old/<name>``), checks that what it moved is what the
   tool expects, and links the new one in (which never overwrites a file saved
   meanwhile); then deletes; the manifest last. A file someone changed is kept;
4. removes the temporary folder, then the journal.

A failure the process sees is undone at once (the journal says ``undo`` first). After
a kill, the next tool to take the folder (``folder_lock.FolderLock``) finishes the swap, or
the undo, from the journal (:func:`recover`) and says which in one line
(:class:`RecoveryWarning`). Nothing in a journal is trusted: a name must be a plain
path inside the folder, a file replaced or deleted must be listed with that content
in the folder's manifest (when the swap writes one), a file removed by an undo must be
the very file the swap put there, and only a stamped temporary folder is removed.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import secrets
import shutil
import signal
import threading
from collections.abc import Iterator, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path, PurePosixPath

from lqe_helpers.authoring.errors import OutputFolderError, OutputWriteError, error_line, shown
from lqe_helpers.authoring.errors import summarise as _summarise
from lqe_helpers.authoring.files import (
    FileState,
    file_sha256,
    file_state,
    mode_for,
    regular_file_bytes,
    sha256,
    write_new_file,
)
from lqe_helpers.authoring.manifest import MANIFEST_NAME, entry_problem, read_manifest

#: The journal of a swap in progress, in the folder it writes.
JOURNAL_NAME = ".lqe-journal.json"
#: The largest journal the tools read (bytes): a build of thousands of files is < 1 MB.
MAX_JOURNAL_BYTES = 4 * 2**20
#: The temporary folder of a swap: exactly this pattern, and stamped (:data:`_STAMP`).
STAGING = re.compile(r"\.lqe-build-[0-9a-f]{16}")
_STAMP = "made-by"
#: Test hook: a tool run with this variable set to k kills itself (SIGKILL) at step k. The
#: steps (:func:`_step`), in order: before the temporary folder is made, before it is stamped,
#: before each staged file, before the journal, before each move aside and each link,
#: before each part of the temporary folder is removed (its ``new``, its ``old``), before it
#: is removed, before the journal is; an undo or a recovery counts its moves too.
KILL_AT_STEP = "LQE_KILL_AT_STEP"
_steps = [0]


class RecoveryWarning(UserWarning):
    """A tool found a swap that was killed part-way, and finished or undid it."""


def _step() -> None:
    """Count one step of a swap; SIGKILL this process at step ``$LQE_KILL_AT_STEP``."""
    _steps[0] += 1
    if os.environ.get(KILL_AT_STEP) == str(_steps[0]):
        os.kill(os.getpid(), signal.SIGKILL)


@dataclass
class Journal:
    """A swap in ``staging``: ``writes`` name → (new, old SHA-256 or ``None`` if absent),
    the manifest last; ``deletes`` name → old SHA-256; ``undo``: being undone; ``folders``:
    the sub-folders it creates (an undo removes them if empty)."""

    tool: str
    staging: str
    writes: dict[str, tuple[str, str | None]] = field(default_factory=dict)
    deletes: dict[str, str] = field(default_factory=dict)
    undo: bool = False
    folders: list[str] = field(default_factory=list)  # sub-folders the swap creates

    def to_bytes(self) -> bytes:
        """The journal file's content (JSON)."""
        return json.dumps({"format": 2, **asdict(self)}, ensure_ascii=False).encode("utf-8")


def _bad(folder: Path, why: str = "") -> OutputFolderError:
    return OutputFolderError(f"{folder / JOURNAL_NAME} is not a journal the course tools can "
                             f"read{why}; nothing was changed: move the folder {folder} away or "
                             f"write elsewhere")


def read_journal(folder: Path) -> Journal | None:
    """The journal of ``folder`` (``None`` if there is none), every name in it checked.

    Raises
    ------
    OutputFolderError
        If it is not a regular file of at most :data:`MAX_JOURNAL_BYTES` (checked before
        it is opened: a fifo never blocks), not a journal, or names a file outside
        ``folder`` or a temporary folder not of the pattern :data:`STAGING`.
    """
    if not os.path.lexists(folder / JOURNAL_NAME):
        return None
    try:
        content = json.loads(regular_file_bytes(folder / JOURNAL_NAME, MAX_JOURNAL_BYTES))
        journal = Journal(**{key: content[key] for key in Journal.__dataclass_fields__})
        values = [journal.tool, journal.staging, *journal.folders, *journal.deletes.values(),
                  *(new for new, _ in journal.writes.values())]
        valid = (content["format"] == 2 and STAGING.fullmatch(journal.staging)
                 and all(isinstance(value, str) for value in values)
                 and all(isinstance(old, str | None) for _, old in journal.writes.values()))
    except (OSError, ValueError, KeyError, TypeError, AttributeError, RecursionError):
        valid = False
    if not valid:
        raise _bad(folder)
    for name in [*journal.writes, *journal.deletes, *journal.folders]:
        problem = entry_problem(folder, name, manifest_ok=True)
        if problem:
            raise OutputFolderError(f"{folder / JOURNAL_NAME} lists {name!r}, which is {problem}; "
                                    f"nothing was "
                                    f"changed: move the folder {folder} away")
    return journal


def _check_against_manifest(folder: Path, journal: Journal) -> None:
    """Refuse a journal that would replace or delete a file the manifest does not list."""
    if MANIFEST_NAME not in journal.writes:
        if journal.deletes:
            raise _bad(folder, " (it deletes files, but writes no manifest)")
        return
    new, old = journal.writes[MANIFEST_NAME]
    now, staging = _content(folder / MANIFEST_NAME), folder / journal.staging
    if now == new or journal.undo:
        return  # every replace and delete was made (an undo checks each file it touches)
    aside = now is None and _aside(staging, MANIFEST_NAME, old)
    if now != old and not aside:
        raise _bad(folder, f" (it does not match the folder's {MANIFEST_NAME})")
    listed = read_manifest(staging / "old" if aside else folder).files if old else {}
    touched = {**{n: o for n, (_, o) in journal.writes.items() if o}, **journal.deletes}
    for name, digest in touched.items():
        if name != MANIFEST_NAME and listed.get(name) != digest:
            raise OutputFolderError(
                f"{folder / JOURNAL_NAME} names {name!r}, which {MANIFEST_NAME} does not list "
                f"as the tool's; nothing was changed: move the folder {folder} away")


def _is_dir(path: Path) -> bool:
    return not os.path.islink(path) and path.is_dir()


def _ours(staging: Path) -> bool:
    """Whether ``staging`` is a temporary folder the tools made: of the pattern
    :data:`STAGING`, and stamped (or empty: its stamp goes last)."""
    stamp = staging / _STAMP
    return (STAGING.fullmatch(staging.name) is not None and _is_dir(staging)
            and ((not os.path.islink(stamp) and stamp.is_file()) or not any(staging.iterdir())))


def _content(target: Path) -> str | None:
    """SHA-256 of ``target``; ``None`` if absent; a mark matching no content if it is not
    a regular file (a link, a folder, a fifo)."""
    return file_sha256(target) or "not a plain file" if os.path.lexists(target) else None


def _kept(staging: Path, part: str, name: str) -> Path | None:
    """``staging/part/name`` if it is a regular file reached through real folders."""
    path = staging / part / name
    parents = [staging, *list(reversed(path.parents))[len(staging.parts):]]
    if not all(_is_dir(parent) for parent in parents) or not _ours(staging) \
            or os.path.islink(path) or not path.is_file():
        return None
    return path


def _aside(staging: Path, name: str, old: str | None) -> bool:
    """Whether the old file ``name`` (SHA-256 ``old``) was moved aside into ``staging``."""
    return old is not None and _kept(staging, "old", name) is not None \
        and file_sha256(staging / "old" / name) == old


def _same(first: Path, second: Path | None) -> bool:
    try:
        return second is not None and os.path.samefile(first, second)
    except OSError:
        return False


def _order(journal: Journal) -> list[tuple[str, str | None, str | None]]:
    """The moves of a swap in order: (name, new or ``None`` to delete, old); manifest last."""
    moves = [(n, new, old) for n, (new, old) in journal.writes.items() if n != MANIFEST_NAME]
    moves += [(n, None, old) for n, old in journal.deletes.items()]
    if MANIFEST_NAME in journal.writes:
        moves.append((MANIFEST_NAME, *journal.writes[MANIFEST_NAME]))
    return moves


def forward(folder: Path, journal: Journal,
            expected: Mapping[str, FileState] | None = None) -> tuple[int, list[str], list[str]]:
    """Make every move of the journal not made yet; return (moved, changed, missing).

    Each target is first renamed aside (``old/<name>``) and what was moved is compared
    with the journal's old content (and ``expected``'s size, time and checksum): a file
    someone changed, even a moment before, is put back and kept (``changed``). The new
    file is then linked in, which fails rather than overwrite a file saved meanwhile.
    A move whose new file is gone from the temporary folder cannot be made (``missing``).
    """
    staging = folder / journal.staging
    moved, changed, missing = 0, [], []
    for name, new, old in _order(journal):
        target, backup = folder / name, staging / "old" / name
        now = _content(target)
        aside = now is None and _aside(staging, name, old)  # moved aside by a killed run
        if now == new and not aside:
            continue  # made already
        staged = _kept(staging, "new", name) if new else None
        if (now != old and not aside) or (new and staged is None):
            (changed if staged or not new else missing).append(name)
            continue
        if now is not None:
            backup.parent.mkdir(parents=True, exist_ok=True)
            _step()
            os.replace(target, backup)
            if file_sha256(backup) != old or (expected and name in expected
                                              and file_state(backup) != expected[name]):
                with contextlib.suppress(FileExistsError):
                    os.link(backup, target)  # someone's edit: back in place, never over a newer
                os.unlink(backup)
                changed.append(name)
                continue
        if staged is not None:
            target.parent.mkdir(parents=True, exist_ok=True)
            _step()
            try:
                os.link(staged, target)
            except FileExistsError:
                changed.append(name)  # saved by someone while the old file was aside
                continue
        moved += 1
    return moved, changed, missing


def undo(folder: Path, journal: Journal) -> int:
    """Put back every old file of the journal; remove only files the swap itself put in
    place (the same file as its staged copy). Return how many files were put back."""
    staging = folder / journal.staging
    restored = 0
    for name, new, old in reversed(_order(journal)):
        target, backup = folder / name, _kept(staging, "old", name)
        placed = new is not None and _same(target, _kept(staging, "new", name))
        if placed and old is None:
            _step()
            os.unlink(target)
            restored += 1
        elif (placed or not os.path.lexists(target)) and backup and file_sha256(backup) == old:
            _step()
            os.replace(backup, target)
            restored += 1
    for name in reversed(journal.folders):
        with contextlib.suppress(OSError):
            (folder / name).rmdir()  # only if empty
    return restored


def _write_journal(folder: Path, journal: Journal) -> None:
    """Write the journal through the temporary folder, atomically (no stray file beside)."""
    temporary = folder / journal.staging / "journal"
    temporary.unlink(missing_ok=True)
    write_new_file(temporary, journal.to_bytes())
    _step()
    os.replace(temporary, folder / JOURNAL_NAME)


def _finish(folder: Path, journal: Journal | None, staging: Path) -> None:
    """Remove the temporary folder (if stamped as ours), then the journal."""
    if _ours(staging):
        for entry in os.scandir(staging):  # the stamp last: a kill leaves it recognisable
            if entry.name != _STAMP:
                _step()
                shutil.rmtree(entry.path) if entry.is_dir(follow_symlinks=False) \
                    else os.unlink(entry.path)
        (staging / _STAMP).unlink(missing_ok=True)
        _step()
        staging.rmdir()
    if journal is not None:
        _step()
        (folder / JOURNAL_NAME).unlink(missing_ok=True)


def recover(folder: Path) -> str | None:
    """Finish (or finish undoing) a swap of ``folder`` killed part-way; one line or ``None``.

    Raises
    ------
    OutputFolderError
        If the journal cannot be trusted (nothing is touched then).
    """
    journal = read_journal(folder)
    if journal is None:
        stray = sorted(entry.name for entry in os.scandir(folder)
                       if STAGING.fullmatch(entry.name) and _ours(folder / entry.name))
        for name in stray:
            _finish(folder, None, folder / name)
        return (f"recovered {shown(folder)}: removed the temporary folder {stray[0]} of a run "
                f"killed before it moved any file") if stray else None
    _check_against_manifest(folder, journal)
    what = f"recovered {shown(folder)}: a run of {shown(journal.tool)} was killed"
    staging = folder / journal.staging
    if journal.undo:
        restored = undo(folder, journal)
        _finish(folder, journal, staging)
        return (f"{what} while undoing a failed build; it is now undone ({restored} file(s) "
                f"put back), so the folder holds the earlier files")
    moved, changed, missing = forward(folder, journal)
    if missing:
        return _cannot_finish(folder, journal, what, missing)
    _finish(folder, journal, staging)
    note = f"; kept as they are, changed since: {_summarise(changed)}" if changed else ""
    return (f"{what} while moving its files into place; the move is now finished ({moved} "
            f"more file(s) moved), so the folder holds that run's files{note}")


def _cannot_finish(folder: Path, journal: Journal, what: str, missing: list[str]) -> str:
    """The temporary folder went mid-swap: remove the journal and say what is true."""
    written = [n for n, (new, _) in journal.writes.items() if _content(folder / n) == new]
    _finish(folder, journal, folder / journal.staging)
    return (f"{what} while moving its files into place, and its temporary folder "
            f"{journal.staging} is gone, so that run can be neither finished nor undone: "
            f"{len(written)} of {len(journal.writes)} file(s) (its manifest included) hold its "
            f"new content, the others are as before ({len(missing)} move(s) lost); files no "
            f"longer as the manifest lists them are kept and named by the next build")


def _stage(folder: Path, tool: str, writes: Mapping[str, bytes],
           swaps: list[tuple[Path, Journal]]) -> Journal:
    """Step 1: a stamped temporary folder in ``folder`` holding every new file (its journal
    appended to ``swaps`` first, so a failure removes the folder again)."""
    journal = Journal(tool, f".lqe-build-{secrets.token_hex(8)}")
    swaps.append((folder, journal))
    staging = folder / journal.staging
    _step()
    staging.mkdir(mode=0o700)
    _step()  # made, not yet stamped (an empty one is recognised as ours)
    write_new_file(staging / _STAMP, f"{tool}\n".encode())
    for name, data in writes.items():
        target = folder / name
        (staging / "new" / name).parent.mkdir(parents=True, exist_ok=True)
        _step()
        write_new_file(staging / "new" / name, data, mode=mode_for(target), named=target)
        journal.writes[name] = (sha256(data), file_sha256(target))
        journal.folders += [p.as_posix() for p in reversed(PurePosixPath(name).parents[:-1])
                            if p.as_posix() not in journal.folders and not (folder / p).exists()]
    return journal


@contextlib.contextmanager
def _undone_on_failure(swaps: list[tuple[Path, Journal]], where: str) -> Iterator[None]:
    """Undo every swap (journal first marked ``undo``) if the block fails."""
    try:
        yield
    except BaseException as error:
        try:
            for folder, journal in reversed(swaps):
                if os.path.lexists(folder / JOURNAL_NAME):
                    journal.undo = True
                    _write_journal(folder, journal)
                    undo(folder, journal)
                _finish(folder, journal, folder / journal.staging)
        except OSError as undo_error:
            raise OutputWriteError(
                f"writing into {where} failed ({error_line(error)}) and so did putting the old "
                f"files back ({error_line(undo_error)}); the next run of a course tool there "
                f"finishes putting them back") from error
        raise


def swap_folders(plans: Mapping[Path, tuple[Mapping[str, bytes], Mapping[str, str],
                                     Mapping[str, str | None], Mapping[str, FileState]]],
          tool: str, where: str, *, strict: bool) -> set[tuple[Path, str]]:
    """Swap each folder's (writes, deletes, expected SHA-256s, expected states); every
    folder is staged before the first rename. Return the (folder, name)s kept as changed
    (``strict``: a changed file undoes everything instead).

    Each folder is held by the caller. ``writes``: name → content (the manifest last);
    ``deletes``: name → the SHA-256 it must hold; expected SHA-256s: name → the SHA-256
    the file must hold right before its rename (``None``: absent), as the caller checked
    it; expected states: name → its :class:`FileState` when the caller read it.

    Raises
    ------
    OutputFolderError
        If ``strict`` and a file changed since the caller looked (everything is then
        undone).
    """
    swaps: list[tuple[Path, Journal]] = []
    kept: set[tuple[Path, str]] = set()
    with signals_deferred():
        with _undone_on_failure(swaps, where):
            for folder, (writes, deletes, expected, _) in plans.items():
                journal = _stage(folder, tool, writes, swaps)
                journal.writes.update({n: (journal.writes[n][0], o) for n, o in expected.items()})
                journal.deletes = dict(deletes)
            for folder, journal in swaps:
                _write_journal(folder, journal)
                kept.update((folder, n) for n in forward(folder, journal, plans[folder][3])[1])
            if kept and strict:
                raise OutputFolderError(f"{_summarise([n for _, n in kept])} in {where} changed "
                                        f"while the build ran; nothing was changed (run it again)")
        for folder, journal in swaps:  # done: an interrupt now leaves tidying to the next run
            _finish(folder, journal, folder / journal.staging)
    return kept


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) and SIGTERM until the block ends, then deliver them (main
    thread only: elsewhere Python cannot set handlers)."""
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
