"""File safety for the course tools: they never lose a file they did not write.

Every command-line tool of :mod:`lqe_helpers.authoring` reads and writes through this
module, which promises:

- **Atomic writes.** A file is written to a temporary file in its own folder, flushed
  to disk, and moved over the old one with :func:`os.replace`, so a reader sees the
  old file or the new one, never half of one (:func:`atomic_write_bytes`,
  :func:`atomic_write_text`, :func:`write_notebook`, :func:`atomic_write_many`).
- **No writing through links.** A target that is a symbolic link is refused, never
  written through nor replaced.
- **Output folders the tool owns.** :func:`check_out_dir` refuses an output folder
  that is, contains or lies inside the source folder (compared by real path and
  :func:`os.path.samefile`, so a case-insensitive file system or a link cannot hide it).
  :func:`write_output_folder` keeps a manifest (:data:`MANIFEST_NAME`) in the output
  folder listing every file the tool wrote there with its SHA-256. A rebuild replaces or
  deletes only files that are in that manifest *and* still hold exactly what the tool
  wrote; any other file in the folder is left alone, and a file the build would have to
  replace that is not the tool's (an instructor's own notes, a hand-edited copy) stops
  the build before anything is changed.
- **All or nothing.** :func:`write_output_folder` builds into a temporary folder (beside
  a new output folder, or hidden inside an existing one), then moves the files into
  place, keeping a hard link to each file it replaces; if anything fails, every moved
  file is put back, so the folder is left as it was.
- **One line per failure.** :func:`run_command` runs a tool's command line and turns any
  failure into one ``error: ...`` line on stderr and exit status 1 (``--verbose`` adds
  the traceback); warnings become one ``warning: ...`` line.
"""

from __future__ import annotations

import argparse
import errno
import hashlib
import json
import os
import re
import shutil
import stat
import sys
import tempfile
import traceback
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import TYPE_CHECKING, Any, NoReturn

if TYPE_CHECKING:
    import nbformat

#: Name of the manifest a tool keeps in its output folder (a JSON file).
MANIFEST_NAME = ".lqe-manifest.json"
#: Version of the manifest's format.
MANIFEST_FORMAT = 1
#: Prefix of the temporary folders of a build in progress (removed when it ends).
STAGING_PREFIX = ".lqe-build-"

# Terminal colour codes, as IPython puts them in tracebacks.
_ANSI_COLOUR = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


class ToolError(Exception):
    """A failure a course tool explains fully in its message's first line (printed as it is)."""


class FileSafetyError(ToolError, ValueError):
    """A tool refused to read or write a file, to keep someone's work safe."""


class OutputFolderError(FileSafetyError):
    """An output folder cannot be used (it overlaps the source, or holds others' files)."""


class NotebookFileError(FileSafetyError):
    """A file that should be a notebook is missing, unreadable or not a valid notebook."""


class OutputWriteError(FileSafetyError):
    """Writing failed part-way (disk full, read-only folder); what was there is restored."""


# --- single files ------------------------------------------------------------------------------

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


def _umask() -> int:
    """The process's umask (read by setting and restoring it)."""
    umask = os.umask(0)
    os.umask(umask)
    return umask


def _new_file_mode() -> int:
    """Permission bits of a new file under the current umask (``0o666 & ~umask``)."""
    return 0o666 & ~_umask()


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
            mode = _new_file_mode()
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
    targets = {Path(path): _as_bytes(data) for path, data in files.items()}
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


def _as_bytes(data: bytes | str) -> bytes:
    return data.encode("utf-8") if isinstance(data, str) else bytes(data)


# --- notebooks ---------------------------------------------------------------------------------

def read_notebook(path: Path | str) -> nbformat.NotebookNode:
    """Read and validate the notebook at ``path`` (converted to nbformat 4).

    Raises
    ------
    NotebookFileError
        With a one-line message naming ``path`` if it is missing, a folder, unreadable,
        not UTF-8, not JSON, or JSON that is not a valid notebook.
    """
    import nbformat  # here, so that the rest of this module needs only the standard library

    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise NotebookFileError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise NotebookFileError(f"{path} is a folder, not a notebook") from None
    except OSError as error:
        raise NotebookFileError(f"{path}: cannot read it: {error.strerror}") from error
    try:
        text = raw.decode("utf-8")
        content = json.loads(text)
    except UnicodeDecodeError as error:
        raise NotebookFileError(f"{path} is not a notebook (not UTF-8 text: {error.reason} "
                                f"at byte {error.start})") from error
    except json.JSONDecodeError as error:
        raise NotebookFileError(f"{path} is not a notebook (not valid JSON: {error.msg} at "
                                f"line {error.lineno}, column {error.colno})") from error
    if not isinstance(content, dict) or not isinstance(content.get("nbformat"), int):
        raise NotebookFileError(f"{path} is not a valid notebook: JSON without an 'nbformat' "
                                f"version number")
    try:
        notebook = nbformat.reads(text, as_version=4)
        nbformat.validate(notebook)
    except nbformat.ValidationError as error:
        raise NotebookFileError(f"{path} is not a valid notebook: "
                                f"{_first_line(error.message)}") from error
    except (ValueError, TypeError, KeyError, AttributeError) as error:
        raise NotebookFileError(f"{path} is not a valid notebook: "
                                f"{_first_line(str(error)) or type(error).__name__}") from error
    return notebook


def source_notebooks(source_dir: Path | str) -> list[Path]:
    """The ``*.ipynb`` files directly in ``source_dir``, in name order.

    Raises
    ------
    ValueError
        If ``source_dir`` is not a folder or holds no notebook.
    """
    source_dir = Path(source_dir)
    if not source_dir.is_dir():
        raise ValueError(f"source_dir must be an existing folder, got {source_dir}")
    notebooks = sorted(path for path in source_dir.glob("*.ipynb") if path.is_file())
    if not notebooks:
        raise ValueError(f"source_dir must hold at least one .ipynb file, got none in "
                         f"{source_dir}")
    return notebooks


def notebook_bytes(notebook: nbformat.NotebookNode) -> bytes:
    """The ``.ipynb`` file content of ``notebook``, exactly as :func:`nbformat.write` saves it."""
    import nbformat
    text = nbformat.writes(notebook)
    if not text.endswith("\n"):
        text += "\n"
    return text.encode("utf-8")


def write_notebook(path: Path | str, notebook: nbformat.NotebookNode) -> Path:
    """Save ``notebook`` at ``path`` atomically (see :func:`atomic_write_bytes`)."""
    return atomic_write_bytes(path, notebook_bytes(notebook))


# --- output folders ----------------------------------------------------------------------------

def _ancestors(path: Path) -> list[Path]:
    return [path, *path.parents]


def _same(first: Path, second: Path) -> bool:
    """Whether two paths name the same existing folder (by inode, so case-blind where the FS is)."""
    try:
        return os.path.samefile(first, second)
    except OSError:
        return os.path.normcase(first) == os.path.normcase(second)


def check_out_dir(source_dir: Path | str, out_dir: Path | str) -> None:
    """Refuse an output folder that is, contains or lies inside the source folder.

    Compared by real path (links resolved) and :func:`os.path.samefile`, so two
    spellings of one folder (``C/drafts`` and ``C/Drafts`` on a case-insensitive file
    system, or a link) are recognised.

    Raises
    ------
    OutputFolderError
        If ``out_dir`` is an existing file, or overlaps ``source_dir``.
    """
    source_dir, out_dir = Path(source_dir), Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise OutputFolderError(f"the output folder {out_dir} is a file; give a folder")
    source_real = Path(os.path.realpath(source_dir))
    out_real = Path(os.path.realpath(out_dir))
    for folder in _ancestors(out_real):
        if folder.exists() and _same(folder, source_real):
            where = "is" if folder == out_real else "lies inside"
            raise OutputFolderError(
                f"the output folder {out_dir} {where} the source folder {source_dir}; "
                f"write the build somewhere else")
    if out_real.exists():
        for folder in _ancestors(source_real):
            if folder.exists() and _same(folder, out_real):
                raise OutputFolderError(
                    f"the output folder {out_dir} contains the source folder {source_dir}, "
                    f"so a build could replace or delete source files; write it somewhere else")


@dataclass(frozen=True)
class Manifest:
    """What a tool wrote in an output folder: its name and ``{relative path: sha256}``."""

    tool: str
    files: dict[str, str] = field(default_factory=dict)

    def to_bytes(self) -> bytes:
        """The manifest file's content (sorted, indented JSON)."""
        content = {
            "format": MANIFEST_FORMAT,
            "tool": self.tool,
            "about": (f"Files that {self.tool} wrote in this folder, with their SHA-256. A rebuild "
                      f"replaces or deletes only these, and only while unchanged; every other "
                      f"file here is left alone."),
            "files": dict(sorted(self.files.items())),
        }
        return (json.dumps(content, indent=1, ensure_ascii=False) + "\n").encode("utf-8")


def read_manifest(out_dir: Path | str) -> Manifest | None:
    """The manifest in ``out_dir``, or ``None`` if there is none.

    Raises
    ------
    OutputFolderError
        If the manifest exists but is a link or cannot be read as one.
    """
    path = Path(out_dir) / MANIFEST_NAME
    if not os.path.lexists(path):
        return None
    refuse_symlink(path)
    try:
        content = json.loads(path.read_text(encoding="utf-8"))
        manifest = Manifest(str(content["tool"]), {str(name): str(digest)
                                                   for name, digest in content["files"].items()})
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError,
            AttributeError) as error:
        raise OutputFolderError(
            f"{path} is not a manifest the course tools can read ({error}); "
            f"move the folder {out_dir} away or write elsewhere") from error
    return manifest


def sha256(data: bytes) -> str:
    """Hex SHA-256 of ``data``."""
    return hashlib.sha256(data).hexdigest()


def _file_sha256(path: Path) -> str | None:
    try:
        return sha256(path.read_bytes())
    except OSError:
        return None


def _check_name(name: str) -> PurePosixPath:
    relative = PurePosixPath(name)
    if (relative.is_absolute() or not relative.parts or ".." in relative.parts
            or relative.parts[0].startswith(".lqe-") or name != relative.as_posix()):
        raise ValueError(f"output file names must be plain relative paths inside the output "
                         f"folder, got {name!r}")
    return relative


@dataclass(frozen=True)
class OutputPlan:
    """What :func:`write_output_folder` will do: checked before anything changes."""

    out_dir: Path
    tool: str
    exists: bool
    replace: tuple[str, ...]
    create: tuple[str, ...]
    delete: tuple[str, ...]
    keep: tuple[str, ...]


def plan_output_folder(out_dir: Path | str, names: Iterable[str], *, tool: str,
                       source_dir: Path | str | None = None) -> OutputPlan:
    """Check that ``tool`` may write ``names`` into ``out_dir``; say what it would change.

    Call it before a long build to fail early; :func:`write_output_folder` calls it again
    just before writing.

    Parameters
    ----------
    out_dir : Path or str
        The output folder (need not exist).
    names : iterable of str
        Relative POSIX paths of the files the build writes (``"prose/index.html"``).
    tool : str
        The tool's name, recorded in the manifest.
    source_dir : Path or str, optional
        The source folder, which ``out_dir`` must not overlap (:func:`check_out_dir`).

    Returns
    -------
    OutputPlan
        ``replace``: files of ours to be overwritten; ``create``: new files; ``delete``:
        files of ours from an earlier build no longer written; ``keep``: files in the
        manifest that were changed or replaced since, and so are left alone (and dropped
        from the manifest).

    Raises
    ------
    OutputFolderError
        If ``out_dir`` is a file, overlaps ``source_dir``, holds another tool's manifest,
        or holds a file in the way that is not the tool's own unchanged output (or is a
        link, or a folder).
    """
    out_dir = Path(out_dir)
    names = list(dict.fromkeys(names))
    for name in names:
        _check_name(name)
    if source_dir is not None:
        check_out_dir(source_dir, out_dir)
    elif out_dir.exists() and not out_dir.is_dir():
        raise OutputFolderError(f"the output folder {out_dir} is a file; give a folder")
    if os.path.islink(out_dir) and not out_dir.exists():
        raise OutputFolderError(f"the output folder {out_dir} is a broken symbolic link")
    if not out_dir.exists():
        return OutputPlan(out_dir, tool, False, (), tuple(names), (), ())
    manifest = read_manifest(out_dir)
    if manifest is not None and manifest.tool != tool:
        raise OutputFolderError(
            f"{out_dir} holds the output of {manifest.tool} (see its {MANIFEST_NAME}), "
            f"not of {tool}; give {tool} a folder of its own")
    ours = manifest.files if manifest is not None else {}
    unchanged = {name for name, digest in ours.items()
                 if not os.path.islink(out_dir / name) and (out_dir / name).is_file()
                 and _file_sha256(out_dir / name) == digest}
    problems, replace, create = [], [], []
    for name in names:
        target = out_dir / name
        blocked = _blocked_parent(out_dir, PurePosixPath(name))
        if blocked:
            problems.append(blocked)
        elif os.path.islink(target):
            problems.append(f"{name} is a symbolic link")
        elif target.is_dir():
            problems.append(f"{name} is a folder")
        elif not target.exists():
            create.append(name)
        elif name in unchanged:
            replace.append(name)
        elif name in ours:
            problems.append(f"{name} was changed since {tool} wrote it")
        else:
            problems.append(f"{name} was not written by {tool}")
    if problems:
        raise OutputFolderError(
            f"{tool} will not write into {out_dir}: {'; '.join(problems)}. Nothing was "
            f"changed; move those files away, or give another output folder")
    wanted = set(names)
    delete = sorted(name for name in unchanged if name not in wanted)
    keep = sorted(name for name in ours if name not in wanted and name not in unchanged)
    return OutputPlan(out_dir, tool, True, tuple(replace), tuple(create), tuple(delete),
                      tuple(keep))


def _blocked_parent(out_dir: Path, relative: PurePosixPath) -> str:
    """Why a sub-folder on the way to ``relative`` cannot hold it ('' if it can)."""
    folder = out_dir
    for part in relative.parts[:-1]:
        folder = folder / part
        if os.path.islink(folder):
            return f"{folder.relative_to(out_dir).as_posix()}/ is a symbolic link"
        if folder.exists() and not folder.is_dir():
            return f"{folder.relative_to(out_dir).as_posix()} is a file, not a folder"
    return ""


def write_output_folder(out_dir: Path | str, files: Mapping[str, bytes | str], *, tool: str,
                        source_dir: Path | str | None = None) -> list[Path]:
    """Write a whole build into ``out_dir``, all or nothing, touching only the tool's files.

    Checks first (:func:`plan_output_folder`): a file in the way that the tool did not
    write, or changed since, stops the build before anything is written. Then:

    - ``out_dir`` missing: everything (with the manifest) is written into a temporary
      folder beside it, which is then renamed to ``out_dir``;
    - ``out_dir`` present: everything is written into a hidden temporary folder inside
      it, then each file is moved into place (the file it replaces kept as a hard link),
      files of an earlier build that this one no longer writes are deleted, and the
      manifest is rewritten. If any step fails, every change is undone.

    Parameters
    ----------
    out_dir : Path or str
        The output folder (its parent folders are created if needed).
    files : mapping of str to bytes or str
        Relative POSIX path → content (``str`` is written as UTF-8).
    tool : str
        The tool's name (recorded in the manifest :data:`MANIFEST_NAME`).
    source_dir : Path or str, optional
        The folder the build reads, which ``out_dir`` must not overlap.

    Returns
    -------
    list of Path
        The written files, in the order of ``files``.

    Raises
    ------
    OutputFolderError
        If the folder cannot be used (nothing is changed).
    OutputWriteError
        If writing fails part-way (disk full, no permission); ``out_dir`` is then as
        it was.
    """
    out_dir = Path(out_dir)
    contents = {name: _as_bytes(data) for name, data in files.items()}
    plan = plan_output_folder(out_dir, contents, tool=tool, source_dir=source_dir)
    manifest = Manifest(tool, {name: sha256(data) for name, data in contents.items()})
    try:
        if plan.exists:
            _commit_into(out_dir, contents, manifest.to_bytes(), plan.delete)
        else:
            _create_folder(out_dir, contents, manifest.to_bytes())
    except OSError as error:
        where = f" ({error.filename})" if error.filename else ""
        raise OutputWriteError(
            f"cannot write into {out_dir}: {error.strerror or error}{where}; "
            f"it was left as it was") from error
    return [out_dir / name for name in contents]


def _stage(folder: Path, contents: Mapping[str, bytes], manifest: bytes | None) -> None:
    """Write ``contents`` (and the manifest) as files under the new folder ``folder``."""
    for name, data in contents.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, _new_file_mode())
        try:
            _write_fd(fd, data)
            os.fsync(fd)
        finally:
            os.close(fd)
    if manifest is not None:
        _stage(folder, {MANIFEST_NAME: manifest}, None)


def _create_folder(out_dir: Path, contents: Mapping[str, bytes], manifest: bytes) -> None:
    """Build a new ``out_dir`` beside it, then rename it into place."""
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name}{STAGING_PREFIX}"))
    try:
        os.chmod(staging, 0o777 & ~_umask())
        _stage(staging, contents, manifest)
        if out_dir.exists() or os.path.islink(out_dir):
            raise OSError(errno.EEXIST, "appeared while the build ran", str(out_dir))
        os.rename(staging, out_dir)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise


def _commit_into(out_dir: Path, contents: Mapping[str, bytes], manifest: bytes,
                 delete: Sequence[str]) -> None:
    """Stage inside ``out_dir``, move each file into place; undo everything on failure."""
    staging = Path(tempfile.mkdtemp(dir=out_dir, prefix=STAGING_PREFIX))
    new, old = staging / "new", staging / "old"
    undo: list[tuple[Path, Path | None]] = []  # (target, its backup or None if it was new)
    created: list[Path] = []
    restored = True
    try:
        _stage(new, contents, manifest)
        for name in [*contents, MANIFEST_NAME]:
            target = out_dir / name
            for folder in reversed(target.relative_to(out_dir).parents[:-1]):
                if not (out_dir / folder).exists():
                    (out_dir / folder).mkdir()
                    created.append(out_dir / folder)
            backup = None
            if os.path.lexists(target):
                backup = old / name
                backup.parent.mkdir(parents=True, exist_ok=True)
                try:
                    os.link(target, backup, follow_symlinks=False)
                except OSError:
                    shutil.copy2(target, backup, follow_symlinks=False)
            os.replace(new / name, target)
            undo.append((target, backup))
        for name in delete:
            backup = old / name
            backup.parent.mkdir(parents=True, exist_ok=True)
            os.replace(out_dir / name, backup)
            undo.append((out_dir / name, backup))
    except BaseException as error:
        try:
            for target, backup in reversed(undo):
                if backup is None:
                    target.unlink(missing_ok=True)
                else:
                    os.replace(backup, target)
            for folder in reversed(created):
                folder.rmdir()
        except OSError as undo_error:
            restored = False
            raise OutputWriteError(
                f"writing into {out_dir} failed ({error_line(error)}) and so did putting the "
                f"old files back ({error_line(undo_error)}); the old files are kept in "
                f"{old}") from error
        raise
    finally:
        if restored:
            shutil.rmtree(staging, ignore_errors=True)


def remove_output_folder(out_dir: Path | str) -> tuple[list[Path], list[Path]]:
    """Delete what a tool wrote in ``out_dir`` (per its manifest); the folder too if then empty.

    Only files listed in the manifest that still hold exactly what the tool wrote are
    deleted, then the manifest, the temporary folders of an interrupted build, and the
    sub-folders of listed files (and ``out_dir``) that are left empty. Everything else
    stays. A folder without a manifest is left alone entirely.

    Parameters
    ----------
    out_dir : Path or str
        A tool's output folder (nothing happens if it does not exist).

    Returns
    -------
    removed : list of Path
        The deleted files.
    kept : list of Path
        The files left in ``out_dir`` (not the tool's, or changed since it wrote them).
    """
    out_dir = Path(out_dir)
    if not out_dir.is_dir():
        return [], []
    for staging in [*out_dir.glob(f"{STAGING_PREFIX}*"),
                    *out_dir.parent.glob(f".{out_dir.name}{STAGING_PREFIX}*")]:
        if staging.is_dir() and not staging.is_symlink():
            shutil.rmtree(staging)
    manifest = read_manifest(out_dir)
    removed: list[Path] = []
    folders: set[Path] = set()
    if manifest is not None:
        for name, digest in sorted(manifest.files.items()):
            _check_name(name)
            path = out_dir / name
            folders.update(out_dir / parent for parent in PurePosixPath(name).parents[:-1])
            if (not os.path.islink(path) and path.is_file() and not _blocked_parent(
                    out_dir, PurePosixPath(name)) and _file_sha256(path) == digest):
                path.unlink()
                removed.append(path)
        (out_dir / MANIFEST_NAME).unlink()
        for folder in sorted(folders, key=lambda path: len(path.parts), reverse=True):
            if folder.is_dir() and not folder.is_symlink() and not any(folder.iterdir()):
                folder.rmdir()
        if not out_dir.is_symlink() and not any(out_dir.iterdir()):
            out_dir.rmdir()
    kept = sorted(path for path in out_dir.rglob("*") if not path.is_dir()) \
        if out_dir.exists() else []
    return removed, kept


# --- command lines -----------------------------------------------------------------------------

class CommandLineParser(argparse.ArgumentParser):
    """An :class:`argparse.ArgumentParser` with ``--verbose`` whose usage errors are one line.

    A bad option prints ``error: <what>; see --help`` on stderr and exits with status 1,
    like every other failure of the tools.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.add_argument("--verbose", action="store_true",
                          help="on failure, also print the traceback")

    def error(self, message: str) -> NoReturn:
        """Print one ``error:`` line and exit with status 1."""
        print(f"error: {message}; see {self.prog} --help", file=sys.stderr)
        raise SystemExit(1)


def strip_colour(text: str) -> str:
    """``text`` without terminal colour codes (as IPython puts them in tracebacks)."""
    return _ANSI_COLOUR.sub("", text)


def _first_line(text: str) -> str:
    lines = [line.strip() for line in _ANSI_COLOUR.sub("", text).splitlines() if line.strip()]
    return lines[0] if lines else ""


def error_line(error: BaseException) -> str:
    """One line saying what went wrong, for ``error: ...`` (no traceback, no colour codes).

    An :class:`OSError` reads ``<file>: <reason>``; an error the tools raise on purpose
    (:class:`ToolError`, :class:`ValueError` and their kin) gives its message's first
    line; anything else also names its type. A message cut to its first line says so.
    """
    if isinstance(error, OSError) and error.strerror:
        names = " -> ".join(str(name) for name in (error.filename, error.filename2) if name)
        return f"{names}: {error.strerror}" if names else error.strerror
    message = str(error)
    line = _first_line(message)
    if not isinstance(error, (ToolError, ValueError)):
        line = f"{type(error).__name__}: {line}" if line else type(error).__name__
    if len([part for part in message.splitlines() if part.strip()]) > 1:
        line += " (--verbose shows the rest)"
    return line


def fail(message: object) -> int:
    """Print ``error: <message>`` (its first line) on stderr; return 1 (a failed command)."""
    print(f"error: {_first_line(str(message)) or message}", file=sys.stderr)
    return 1


def _one_line_warning(message: Warning | str, category: type[Warning], filename: str,
                      lineno: int, file: Any = None, line: str | None = None) -> None:
    print(f"warning: {_first_line(str(message))}", file=sys.stderr if file is None else file)


def run_command(parser: argparse.ArgumentParser,
                command: Callable[[argparse.Namespace], int | None],
                argv: Sequence[str] | None = None) -> int:
    """Parse ``argv`` and run ``command(args)``; turn any failure into one ``error:`` line.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The tool's parser (a :class:`CommandLineParser`, which has ``--verbose``).
    command : callable
        Does the work; returns an exit status (``None`` means 0).
    argv : sequence of str, optional
        The arguments (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        ``command``'s status; 1 after an exception (printed as ``error: ...`` on
        stderr, preceded by the traceback with ``--verbose``); 130 after Ctrl-C.
        Warnings are printed as one ``warning: ...`` line each (in full with ``--verbose``).
    """
    args = parser.parse_args(argv)
    verbose = bool(getattr(args, "verbose", False))
    with warnings.catch_warnings():
        if not verbose:
            warnings.showwarning = _one_line_warning
        try:
            status = command(args)
        except KeyboardInterrupt:
            print("error: interrupted", file=sys.stderr)
            return 130
        except Exception as error:  # the one place every failure is reported
            if verbose:
                print(strip_colour(traceback.format_exc()).rstrip(), file=sys.stderr)
            print(f"error: {error_line(error)}", file=sys.stderr)
            return 1
    return 0 if status is None else int(status)
