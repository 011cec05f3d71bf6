"""Single files, written atomically: a reader sees the old file or the new one, never half.

Every byte the course tools write goes out through this module:

- :func:`atomic_write_bytes` (and :func:`atomic_write_text`) writes a temporary file in
  the target's own folder, flushes it to disk and moves it over the target with
  :func:`os.replace`; on failure the target is untouched and the temporary file removed.
- :func:`write_new_file` creates a file that must not exist yet (a build's staged copy);
  :func:`regular_file_bytes` reads a small regular file, refusing anything else unopened.
- :func:`file_state` says what a file is now (size, modification time, SHA-256), so a
  tool can tell whether someone changed it since it was read.
- A target that is a symbolic link is refused, never written through nor replaced
  (:func:`refuse_symlink`).

Standard library only.
"""

from __future__ import annotations

import hashlib
import os
import secrets
import stat
from dataclasses import dataclass
from pathlib import Path

from lqe_helpers.authoring.errors import FileSafetyError


def refuse_symlink(path: Path | str) -> None:
    """Raise :class:`FileSafetyError` if ``path`` is a symbolic link (dangling or not)."""
    if os.path.islink(path):
        raise FileSafetyError(
            f"{path} is a symbolic link (to {os.readlink(path)}); the tools never read or write "
            f"through a link (it could lead to any file) nor replace one: put the file itself "
            f"there, remove the link or write elsewhere")


def _write_fd(fd: int, data: bytes) -> None:
    """Write all of ``data`` to the open file descriptor ``fd`` (the one place bytes go out)."""
    view = memoryview(data)
    while view:
        written = os.write(fd, view)
        view = view[written:]


def new_file_mode() -> int:
    """Permission bits of a new file under the current umask (``0o666 & ~umask``)."""
    current = os.umask(0)
    os.umask(current)
    return 0o666 & ~current


def mode_for(path: Path) -> int:
    """Permission bits for a new version of ``path``: its own if it exists, else the umask's."""
    try:
        return stat.S_IMODE(os.stat(path, follow_symlinks=False).st_mode)
    except FileNotFoundError:
        return new_file_mode()


def check_target(path: Path) -> None:
    """Refuse a write target that is a link or a folder (:class:`FileSafetyError`)."""
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
    check_target(path)
    temporary = path.with_name(f".{path.name}.{secrets.token_hex(4)}.lqe-tmp")
    try:
        write_new_file(temporary, data, mode=mode_for(path), named=path)
        os.replace(temporary, path)
    except BaseException as error:
        temporary.unlink(missing_ok=True)
        if isinstance(error, OSError) and error.filename == str(temporary):
            raise OSError(error.errno, error.strerror, str(path)) from error  # not a temp name
        raise
    return path


def atomic_write_text(path: Path | str, text: str, encoding: str = "utf-8") -> Path:
    """:func:`atomic_write_bytes` of ``text`` encoded with ``encoding`` (no newline translation)."""
    return atomic_write_bytes(path, text.encode(encoding))


def as_bytes(data: bytes | str) -> bytes:
    """``data`` as bytes (``str`` encoded as UTF-8)."""
    return data.encode("utf-8") if isinstance(data, str) else bytes(data)


def write_new_file(path: Path, data: bytes, *, mode: int | None = None,
                   named: Path | None = None) -> None:
    """Create the file ``path``, which must not exist yet, holding ``data`` (flushed to disk).

    Parameters
    ----------
    path : Path
        The new file (its folder must exist).
    data : bytes
        Its content.
    mode : int, optional
        Its permission bits (default: the umask's, :func:`new_file_mode`).
    named : Path, optional
        The file a failure should name (default ``path``): the target of a staged copy.

    Raises
    ------
    FileExistsError
        If ``path`` exists (a link included).
    OSError
        If writing fails (naming ``named``).
    """
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, new_file_mode())
    try:
        os.fchmod(fd, new_file_mode() if mode is None else mode)
        _write_fd(fd, data)
        os.fsync(fd)
    except OSError as error:  # os.write names no file (ENOSPC, EFBIG: ``ulimit -f``)
        if error.filename is None and error.errno is not None:
            raise OSError(error.errno, error.strerror,
                          str(path if named is None else named)) from error
        raise
    finally:
        os.close(fd)


def regular_file_bytes(path: Path, limit: int, what: str = "file") -> bytes:
    """The content of the regular file ``path`` of at most ``limit`` bytes.

    Checked before it is opened (a fifo or a device never blocks, a huge file is never
    read) and opened without following a link.

    Raises
    ------
    ValueError
        Saying why: not a regular file, or larger than ``limit`` (a ``what``'s).
    OSError
        If it cannot be read.
    """
    status = os.lstat(path)
    if not stat.S_ISREG(status.st_mode):
        raise ValueError("not a regular file (a link, a folder, a fifo or a device)")
    if status.st_size > limit:
        raise ValueError(f"{status.st_size} bytes, more than a {what}'s {limit}")
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | os.O_NONBLOCK)
    with open(fd, "rb") as file:
        return file.read(limit + 1)[:limit + 1]


def sha256(data: bytes) -> str:
    """Hex SHA-256 of ``data``."""
    return hashlib.sha256(data).hexdigest()


def file_sha256(path: Path) -> str | None:
    """Hex SHA-256 of the regular file at ``path``; ``None`` if it is missing, a link,
    not a regular file, or cannot be read."""
    try:
        if not stat.S_ISREG(os.lstat(path).st_mode):
            return None
        digest = hashlib.sha256()
        with open(path, "rb") as file:  # in pieces: a file in the way may be huge
            while piece := file.read(2**20):
                digest.update(piece)
        return digest.hexdigest()
    except OSError:
        return None


@dataclass(frozen=True)
class FileState:
    """What a file was when a tool read it: size (bytes), modification time (ns), SHA-256."""

    size: int
    mtime_ns: int
    sha256: str


def file_state(path: Path, data: bytes | None = None) -> FileState | None:
    """The :class:`FileState` of the regular file ``path`` now (``None`` if there is none).

    ``data``, if given, is the content just read from ``path`` (hashed instead of
    reading the file again).
    """
    try:
        status = os.lstat(path)
        if not stat.S_ISREG(status.st_mode):
            return None
        content = path.read_bytes() if data is None else data
    except OSError:
        return None
    return FileState(status.st_size, status.st_mtime_ns, sha256(content))
