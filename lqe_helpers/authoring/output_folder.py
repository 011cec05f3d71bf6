"""Output folders a tool owns: written all or nothing, touching only the tool's own files.

- :func:`check_out_dir` refuses an output folder that is, contains or lies inside a
  source folder (compared by real path and :func:`os.path.samefile`, so a
  case-insensitive file system or a link cannot hide it).
- :func:`write_output_folder` keeps a manifest (:mod:`lqe_helpers.authoring.manifest`)
  in the output folder listing every file the tool wrote there with its SHA-256. A
  rebuild replaces or deletes only files that are in that manifest *and* still hold
  exactly what the tool wrote; any other file in the folder is left alone, and a file
  the build would have to replace that is not the tool's stops the build before
  anything is changed.
- All or nothing: the build is written into a temporary folder first, then moved into
  place; if anything fails, every moved file is put back.
- :func:`remove_output_folder` deletes what a tool wrote (``make clean``).
"""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from lqe_helpers.authoring.errors import OutputFolderError, OutputWriteError, error_line
from lqe_helpers.authoring.files import (
    as_bytes,
    file_sha256,
    sha256,
    umask,
    write_new_file,
)
from lqe_helpers.authoring.manifest import (
    MANIFEST_NAME,
    Manifest,
    blocked_parent,
    check_name,
    read_manifest,
)

#: Prefix of the temporary folders of a build in progress (removed when it ends).
STAGING_PREFIX = ".lqe-build-"


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
        check_name(name)
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
                 and file_sha256(out_dir / name) == digest}
    problems, replace, create = [], [], []
    for name in names:
        target = out_dir / name
        blocked = blocked_parent(out_dir, PurePosixPath(name))
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
    contents = {name: as_bytes(data) for name, data in files.items()}
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
        write_new_file(path, data)
    if manifest is not None:
        _stage(folder, {MANIFEST_NAME: manifest}, None)


def _create_folder(out_dir: Path, contents: Mapping[str, bytes], manifest: bytes) -> None:
    """Build a new ``out_dir`` beside it, then rename it into place."""
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name}{STAGING_PREFIX}"))
    try:
        os.chmod(staging, 0o777 & ~umask())
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
            check_name(name)
            path = out_dir / name
            folders.update(out_dir / parent for parent in PurePosixPath(name).parents[:-1])
            if (not os.path.islink(path) and path.is_file() and not blocked_parent(
                    out_dir, PurePosixPath(name)) and file_sha256(path) == digest):
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
