"""The journal of a build: what it is about to do to a folder, so a kill can be recovered.

A build that writes a folder (:class:`~lqe_helpers.authoring.transaction.Transaction`):

1. records in the folder's journal (:data:`JOURNAL_NAME`, written atomically) the name
   of the temporary folder it is about to create (state ``staging``);
2. writes every new file into that temporary folder (``.lqe-build-…/new/``) and keeps a
   hard link to every file it will replace or delete (``.lqe-build-…/old/``);
3. records every move it will make, with the SHA-256 of the old and the new content
   (state ``committing``), and only then moves the files into place (manifest last);
4. removes the temporary folder, then the journal.

A failure the process sees is undone at once: the journal turns to ``rolling-back`` and
every old file is put back. If the process dies instead (SIGKILL, a power cut), the next
tool that takes the folder reads the journal and finishes the job (:func:`recover`): a
``committing`` build is completed (:func:`roll_forward`), a ``rolling-back`` one undone
(:func:`roll_back`), a ``staging`` one had changed nothing and only its temporary folder
goes. A file someone changed meanwhile is never overwritten, and the tools remove only
temporary folders a journal recorded. Every name in a journal is checked like a manifest
entry before anything is touched. Standard library only.
"""

from __future__ import annotations

import json
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from lqe_helpers.authoring.errors import OutputFolderError, shown, summarise
from lqe_helpers.authoring.files import atomic_write_bytes, file_sha256
from lqe_helpers.authoring.manifest import entry_problem

#: The journal of a build in progress, in the folder it writes.
JOURNAL_NAME = ".lqe-journal.json"
#: Version of the journal's format.
JOURNAL_FORMAT = 1
#: Prefix of the temporary folder of a build in progress (inside the folder it writes).
STAGING_PREFIX = ".lqe-build-"
_STATES = ("staging", "committing", "rolling-back")
#: The largest journal the tools read (bytes): a build of thousands of files is < 1 MB.
MAX_JOURNAL_BYTES = 64 * 2**20


class RecoveryWarning(UserWarning):
    """A tool found a build that was killed part-way, and finished or undid it."""


@dataclass(frozen=True)
class Step:
    """One move of a build: ``name`` gets the content ``new`` (``None``: it is deleted);
    ``old`` is the content it replaces (``None``: the file is new). SHA-256 hex digests."""

    name: str
    new: str | None
    old: str | None


@dataclass
class Journal:
    """What a build in a folder is doing, as its journal file records it."""

    tool: str
    state: str
    staging: str
    steps: list[Step] = field(default_factory=list)
    folders: list[str] = field(default_factory=list)

    def to_bytes(self) -> bytes:
        """The journal file's content (JSON)."""
        content = {"format": JOURNAL_FORMAT, "tool": self.tool, "state": self.state,
                   "staging": self.staging, "folders": self.folders,
                   "steps": [[step.name, step.new, step.old] for step in self.steps]}
        return (json.dumps(content, indent=1, ensure_ascii=False) + "\n").encode("utf-8")


def read_journal(folder: Path) -> Journal | None:
    """The journal of ``folder`` (``None`` if there is none), every name in it checked.

    Raises
    ------
    OutputFolderError
        If the journal cannot be read, or names a file or folder that is not a plain
        relative path inside ``folder`` (nothing is touched then).
    """
    path = folder / JOURNAL_NAME
    if not os.path.lexists(path):
        return None
    try:
        if os.path.islink(path) or os.path.getsize(path) > MAX_JOURNAL_BYTES:
            raise ValueError("a link, or too large")
        content = json.loads(path.read_bytes().decode("utf-8"))
        journal = Journal(content["tool"], content["state"], content["staging"],
                          [Step(*step) for step in content["steps"]], list(content["folders"]))
        valid = (content["format"] == JOURNAL_FORMAT and journal.state in _STATES
                 and isinstance(journal.tool, str) and isinstance(journal.staging, str)
                 and journal.staging.startswith(STAGING_PREFIX)
                 and PurePosixPath(journal.staging).name == journal.staging
                 and all(isinstance(value, str | None) for step in journal.steps
                         for value in (step.new, step.old)))
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError, RecursionError):
        valid = False
    if not valid:
        raise OutputFolderError(f"{path} is not a journal the course tools can read; nothing "
                                f"was changed: move the folder {folder} away or write elsewhere")
    for name in [*(step.name for step in journal.steps), *journal.folders]:
        problem = entry_problem(folder, name, manifest_ok=True)
        if problem:
            raise OutputFolderError(f"{path} lists {name!r}, which is {problem}; nothing was "
                                    f"changed: move the folder {folder} away")
    return journal


def write_journal(folder: Path, journal: Journal) -> None:
    """Write ``journal`` as ``folder``'s journal, atomically."""
    atomic_write_bytes(folder / JOURNAL_NAME, journal.to_bytes())


def finish(folder: Path, journal: Journal) -> None:
    """Remove the temporary folder the journal recorded, then the journal."""
    staging = folder / journal.staging
    if staging.is_dir() and not staging.is_symlink():
        shutil.rmtree(staging)
    (folder / JOURNAL_NAME).unlink(missing_ok=True)


def _kept_copy(folder: Path, journal: Journal, part: str, name: str) -> Path | None:
    """The staged (``part="new"``) or backed-up (``"old"``) copy of ``name``, if it is a
    plain file reached through real folders of the temporary folder (``None`` if not:
    moved already, or something there is a link, which is never followed)."""
    root = folder / journal.staging / part
    for level in (folder / journal.staging, root):
        if os.path.islink(level) or not level.is_dir():
            return None
    path = root / name
    if entry_problem(root, name, manifest_ok=True) or os.path.islink(path) \
            or not path.is_file():
        return None
    return path


def _content(target: Path) -> str | None:
    """The SHA-256 of ``target`` if it is a plain file; ``None`` if there is nothing; a
    mark that matches no content if it is anything else (a link, a folder)."""
    if not os.path.lexists(target):
        return None
    return file_sha256(target) or "not a plain file"


def roll_forward(folder: Path, journal: Journal, *, strict: bool) -> tuple[int, list[str]]:
    """Make every move the journal records that is not made yet.

    A target that holds neither its old nor its new content was changed by someone
    else: it is kept (its name returned) or, if ``strict``, the build stops.

    Returns
    -------
    moved : int
        How many files were moved into place or deleted now.
    kept : list of str
        The names kept because they changed.
    """
    for name in journal.folders:
        (folder / name).mkdir(exist_ok=True)
    kept, moved = [], 0
    for step in journal.steps:
        target = folder / step.name
        now = _content(target)
        if step.new is None:
            if now is not None and now == step.old:
                target.unlink()
                moved += 1
            continue
        staged = _kept_copy(folder, journal, "new", step.name)
        if staged is None:
            continue  # moved already
        if now != step.old and now != step.new:
            if strict:
                raise OutputFolderError(f"{folder / step.name} was changed while the build ran; "
                                        f"nothing was changed")
            kept.append(step.name)
            continue
        os.replace(staged, target)
        moved += 1
    return moved, kept


def roll_back(folder: Path, journal: Journal) -> int:
    """Put back every old file the journal records; return how many were put back."""
    restored = 0
    for step in reversed(journal.steps):
        target = folder / step.name
        now = _content(target)
        backup = _kept_copy(folder, journal, "old", step.name) if step.old else None
        if step.old is None:
            if now is not None and now == step.new:
                target.unlink()
                restored += 1
        elif backup is not None and now != step.old and (now is None or now == step.new):
            os.replace(backup, target)
            restored += 1
    for name in reversed(journal.folders):
        try:
            (folder / name).rmdir()
        except OSError:
            pass  # not empty (someone's file) or gone: left as it is
    return restored


def recover(folder: Path) -> str | None:
    """Finish or undo a build of ``folder`` that was killed part-way, from its journal.

    Returns
    -------
    str or None
        One line saying what was done; ``None`` if there was nothing to do.

    Raises
    ------
    OutputFolderError
        If the journal cannot be trusted (:func:`read_journal`).
    """
    for stray in folder.glob(f".{JOURNAL_NAME}.*.lqe-tmp"):  # a journal being written
        if stray.is_file() and not stray.is_symlink():
            stray.unlink()
    journal = read_journal(folder)
    if journal is None:
        return None
    what = f"recovered {shown(folder)}: a run of {shown(journal.tool)} was killed"
    if journal.state == "staging":
        finish(folder, journal)
        return (f"{what} before it changed anything; its temporary folder {journal.staging} "
                f"is removed")
    if journal.state == "rolling-back":
        restored = roll_back(folder, journal)
        finish(folder, journal)
        return (f"{what} while undoing a failed build; it is now undone ({restored} file(s) "
                f"put back)")
    moved, kept = roll_forward(folder, journal, strict=False)
    finish(folder, journal)
    note = f"; kept as they are, changed since: {summarise(kept)}" if kept else ""
    return (f"{what} while moving its files into place; the move is now finished ({moved} "
            f"more file(s) moved), so the folder holds that run's files{note}")
