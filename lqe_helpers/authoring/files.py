"""Single files, written atomically: a reader sees the old file or the new one, never half.

Every byte the course tools write goes out through this module:

- :func:`atomic_write_bytes` (and :func:`atomic_write_text`) writes a temporary file in
  the target's own folder, flushes it to disk and moves it over the target with
  :func:`os.replace`; on failure the target is untouched and the temporary file removed.
- :func:`atomic_write_many` replaces several files, all or none.
- :func:`write_new_file` creates a file that must not exist yet (a build's staged copy).
- A target that is a symbolic link is refused, never written through nor replaced
  (:func:`refuse_symlink`).

Standard library only.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import stat
import tempfile
from collections.abc import Mapping
from pathlib import Path

from lqe_helpers.authoring.errors import FileSafetyError, OutputWriteError, error_line


def refuse_symlink(path: Path | str) -> None:
    """Raise :class:`FileSafetyError` if ``path`` is a symbolic link (dangling or not)."""
    if os.path.islink(path):
        raise FileSafetyError(
            f"{path} is a symbolic link (to {os.readlink(path)}); the tools never write "
            f"through a link nor replace one: remove the link or write elsewhere")


def _write_fd(fd: int, data: bytes) -> None:
    """Write all of ``data`` to the open file descriptor ``fd`` (the one place bytes go out)."""
    view = memoryview(data)
    while view:
        written = os.write(fd, view)
        view = view[written:]


def umask() -> int:
    """The process's umask (read by setting and restoring it)."""
    current = os.umask(0)
    os.umask(current)
    return current


def new_file_mode() -> int:
    """Permission bits of a new file under the current umask (``0o666 & ~umask``)."""
    return 0o666 & ~umask()


def _temporary_copy(path: Path, data: bytes) -> Path:
    """Write ``data`` to a new temporary file beside ``path``; return its path.

    The file gets the permission bits of ``path`` if it exists (else the umask's), and
    is flushed to disk. On failure nothing is left behind.
    """
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".lqe-tmp")
    temporary = Path(name)
    try:
        try:
            mode = stat.S_IMODE(os.stat(path, follow_symlinks=False).st_mode)
        except FileNotFoundError:
            mode = new_file_mode()
        os.fchmod(fd, mode)
        _write_fd(fd, data)
        os.fsync(fd)
    except BaseException:
        os.close(fd)
        temporary.unlink(missing_ok=True)
        raise
    os.close(fd)
    return temporary


def _check_target(path: Path) -> None:
    """Refuse a write target that is a link or a folder."""
    refuse_symlink(path)
    if path.is_dir():
        raise FileSafetyError(f"{path} is a folder; expected a file to write")


def atomic_write_bytes(path: Path | str, data: bytes) -> Path:
    """Replace (or create) the file ``path`` with ``data``, atomically.

    ``data`` goes to a temporary file in the same folder, which is flushed to disk and
    then moved over ``path`` with :func:`os.replace`: at every moment ``path`` holds
    either its old content or all of the new. An existing file keeps its permission
    bits. On failure (disk full, no permission) ``path`` is untouched and the temporary
    file removed.

    Parameters
    ----------
    path : Path or str
        The file to write. Its folder must exist.
    data : bytes
        The new content.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    FileSafetyError
        If ``path`` is a symbolic link or a folder.
    OSError
        If writing fails (``path`` is then unchanged).
    """
    path = Path(path)
    _check_target(path)
    temporary = _temporary_copy(path, data)
    try:
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return path


def atomic_write_text(path: Path | str, text: str, encoding: str = "utf-8") -> Path:
    """:func:`atomic_write_bytes` of ``text`` encoded with ``encoding`` (no newline translation)."""
    return atomic_write_bytes(path, text.encode(encoding))


def atomic_write_many(files: Mapping[Path | str, bytes | str]) -> list[Path]:
    """Replace (or create) several files, all or none.

    Every new content is first written to a temporary file beside its target (a full
    disk stops here, with nothing changed); then each target gets a hard-link backup
    and is replaced with :func:`os.replace`. If any replacement fails, the ones already
    made are undone from their backups, so every file is left as it was.

    Parameters
    ----------
    files : mapping of Path to bytes or str
        Target path → new content (``str`` is written as UTF-8).

    Returns
    -------
    list of Path
        The targets, in the mapping's order.

    Raises
    ------
    FileSafetyError
        If a target is a symbolic link or a folder (checked before anything is written).
    OSError
        If writing fails (every target is then as it was).
    """
    targets = {Path(path): as_bytes(data) for path, data in files.items()}
    for path in targets:
        _check_target(path)
    staged: dict[Path, Path] = {}
    backups: dict[Path, Path | None] = {}
    replaced: list[Path] = []
    keep_backups = False
    try:
        for path, data in targets.items():
            staged[path] = _temporary_copy(path, data)
        for path in targets:
            backups[path] = _backup(path) if path.exists() else None
        for path, temporary in staged.items():
            os.replace(temporary, path)
            replaced.append(path)
    except BaseException as error:
        try:
            for path in reversed(replaced):
                backup = backups.get(path)
                if backup is not None:
                    os.replace(backup, path)
                else:
                    path.unlink(missing_ok=True)
        except OSError as undo_error:
            keep_backups = True
            kept = ", ".join(str(backup) for backup in backups.values() if backup)
            raise OutputWriteError(
                f"writing failed ({error_line(error)}) and so did putting the old files back "
                f"({error_line(undo_error)}); the old files are kept as {kept}") from error
        raise
    finally:
        for temporary in staged.values():
            temporary.unlink(missing_ok=True)
        if not keep_backups:
            for backup in backups.values():
                if backup is not None:
                    backup.unlink(missing_ok=True)
    return list(targets)


def _backup(path: Path) -> Path:
    """A hard link (else a copy) of ``path`` beside it, to put back if a replacement fails."""
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".lqe-old")
    os.close(fd)
    backup = Path(name)
    backup.unlink()
    try:
        os.link(path, backup, follow_symlinks=False)
    except OSError:
        shutil.copy2(path, backup, follow_symlinks=False)
    return backup


def as_bytes(data: bytes | str) -> bytes:
    """``data`` as bytes (``str`` encoded as UTF-8)."""
    return data.encode("utf-8") if isinstance(data, str) else bytes(data)


def write_new_file(path: Path, data: bytes) -> None:
    """Create the file ``path``, which must not exist yet, holding ``data`` (flushed to disk).

    Its permission bits are the umask's (:func:`new_file_mode`).

    Raises
    ------
    FileExistsError
        If ``path`` exists (a link included).
    OSError
        If writing fails.
    """
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, new_file_mode())
    try:
        _write_fd(fd, data)
        os.fsync(fd)
    finally:
        os.close(fd)


def sha256(data: bytes) -> str:
    """Hex SHA-256 of ``data``."""
    return hashlib.sha256(data).hexdigest()


def file_sha256(path: Path) -> str | None:
    """Hex SHA-256 of the file at ``path``, or ``None`` if it cannot be read."""
    try:
        return sha256(path.read_bytes())
    except OSError:
        return None
