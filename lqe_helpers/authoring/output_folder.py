"""Output folders a tool owns: written all or nothing, touching only the tool's own files.

- :func:`check_out_dir` refuses an output folder that is, contains or lies inside a
  source folder (compared by real path and :func:`os.path.samefile`, so a
  case-insensitive file system or a link cannot hide it).
- :func:`write_output_folder` keeps a manifest (:mod:`lqe_helpers.authoring.manifest`)
  in the output folder listing every file the tool wrote there with its SHA-256. A
  rebuild replaces or deletes only files that are in that manifest *and* still hold
  exactly what the tool wrote; any other file in the folder is left alone, and a file
  the build would have to replace that is not the tool's stops the build before
  anything is changed. A manifest entry that is not a plain relative path inside the
  folder stops it too.
- All or nothing, even under a kill: the build is swapped in with renames
  (:mod:`lqe_helpers.authoring.swap`); a failure is undone at once, a killed swap is
  finished or undone by the next tool that takes the folder, before it checks it.
- One tool at a time: the folder is held (:class:`~lqe_helpers.authoring.swap.
  FolderLock`) for the whole build (:func:`build_output_folder`).
- :func:`remove_output_folder` deletes what a tool wrote (``make clean``).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from lqe_helpers.authoring.errors import OutputFolderError, OutputWriteError, shown, summarise
from lqe_helpers.authoring.files import as_bytes, file_sha256, sha256
from lqe_helpers.authoring.folder_lock import FolderLock
from lqe_helpers.authoring.manifest import (
    MANIFEST_NAME,
    Manifest,
    blocked_parent,
    name_problem,
    read_manifest,
)
from lqe_helpers.authoring.swap import swap_folders


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
        raise OutputFolderError(f"the output folder {shown(out_dir)} is a file; give a folder")
    source_real = Path(os.path.realpath(source_dir))
    out_real = Path(os.path.realpath(out_dir))
    for folder in _ancestors(out_real):
        if folder.exists() and _same(folder, source_real):
            where = "is" if folder == out_real else "lies inside"
            raise OutputFolderError(
                f"the output folder {shown(out_dir)} {where} the source folder "
                f"{shown(source_dir)}; "
                f"write the build somewhere else")
    if out_real.exists():
        for folder in _ancestors(source_real):
            if folder.exists() and _same(folder, out_real):
                raise OutputFolderError(
                    f"the output folder {shown(out_dir)} contains the source folder "
                    f"{shown(source_dir)}, "
                    f"so a build could replace or delete source files; write it somewhere else")


def check_output_location(out_dir: Path | str, sources: Sequence[Path | str] = ()) -> None:
    """Refuse an output path that is a file or a broken link, or overlaps a source folder.

    Raises
    ------
    OutputFolderError
        If ``out_dir`` is a file, a broken symbolic link, starts with an unexpanded ``~``,
        is, contains or lies inside one of ``sources`` (:func:`check_out_dir`), or is (or
        would be made in) a folder this process may not write (a read-only file system).
    """
    out_dir = Path(out_dir)
    if out_dir.parts and out_dir.parts[0].startswith("~"):
        raise OutputFolderError(
            f"the output folder {shown(out_dir)} starts with '~', which no shell expanded "
            f"(was it quoted?); a folder named like that is too easily taken for a home "
            f"folder: give the path itself (e.g. $HOME/...)")
    if out_dir.exists() and not out_dir.is_dir():
        raise OutputFolderError(f"the output folder {shown(out_dir)} is a file; give a folder")
    if os.path.islink(out_dir) and not out_dir.exists():
        raise OutputFolderError(f"the output folder {shown(out_dir)} is a broken symbolic link")
    for source in sources:
        check_out_dir(source, out_dir)
    existing = next(folder for folder in [out_dir.absolute(), *out_dir.absolute().parents]
                    if folder.exists())
    if not os.access(existing, os.W_OK | os.X_OK):
        raise OutputFolderError(f"cannot write into {shown(out_dir)}: {shown(existing)} is "
                                f"read-only for you; nothing was done")


def check_output_names(names: Iterable[str]) -> list[str]:
    """The names a build writes, each once, after checking each is a plain relative path.

    Raises
    ------
    ValueError
        If a name is absolute, has an empty, ``.`` or ``..`` part, or starts with the
        tools' reserved ``.lqe-``.
    """
    names = list(dict.fromkeys(names))
    for name in names:
        problem = name_problem(name)
        if problem:
            raise ValueError(f"output file names must be plain relative paths inside the "
                             f"output folder, got {name!r} ({problem})")
    return names


@dataclass(frozen=True)
class OutputPlan:
    """What :func:`write_output_folder` will do: checked before anything changes."""

    replace: tuple[str, ...]
    create: tuple[str, ...]
    delete: tuple[str, ...]
    ours: Mapping[str, str]


def _problem_text(names: list[str], one: str, many: str) -> str:
    """``"a was X"`` or ``"a, b, c and 5 more were X"`` (each fault said once)."""
    return f"{summarise(names)} {one if len(names) == 1 else many}"


def plan_output_folder(out_dir: Path | str, names: Iterable[str], *, tool: str,
                       sources: Sequence[Path | str] = ()) -> OutputPlan:
    """Check that ``tool`` may write ``names`` into ``out_dir``; say what it would change.

    Call it before a long build to fail early; :func:`write_output_folder` calls it again
    just before writing. Nothing is changed.

    Parameters
    ----------
    out_dir : Path or str
        The output folder (need not exist).
    names : iterable of str
        Relative POSIX paths of the files the build writes (``"prose/index.html"``).
    tool : str
        The tool's name, recorded in the manifest.
    sources : sequence of Path or str
        The source folders, which ``out_dir`` must not overlap (:func:`check_out_dir`).

    Returns
    -------
    OutputPlan
        ``replace``: files of ours to be overwritten; ``create``: new files; ``delete``:
        files of ours from an earlier build no longer written; ``ours``: the manifest's
        entries. A file of the manifest changed or replaced since is left alone (and
        dropped from the manifest).

    Raises
    ------
    OutputFolderError
        If ``out_dir`` is a file, overlaps a source, holds another tool's manifest or a
        manifest with an entry outside the folder, or holds a file in the way that is
        not the tool's own unchanged output (or is a link, or a folder). Each fault is
        said once, with how many files it concerns and the first few.
    """
    out_dir = Path(out_dir)
    names = check_output_names(names)
    check_output_location(out_dir, sources)
    if not out_dir.exists():
        return OutputPlan((), tuple(names), (), {})
    manifest = read_manifest(out_dir)
    if manifest is not None and manifest.tool != tool:
        raise OutputFolderError(
            f"{shown(out_dir)} holds the output of {shown(manifest.tool)} (see its "
            f"{MANIFEST_NAME}), not of {tool}; give {tool} a folder of its own")
    ours = manifest.files if manifest is not None else {}
    unchanged = {name for name, digest in ours.items()
                 if file_sha256(out_dir / name) == digest}
    blocked: dict[str, None] = {}
    faults: dict[str, list[str]] = {"link": [], "folder": [], "changed": [], "foreign": []}
    replace, create = [], []
    for name in names:
        target = out_dir / name
        why = blocked_parent(out_dir, PurePosixPath(name))
        if why:
            blocked[why] = None
        elif os.path.islink(target):
            faults["link"].append(name)
        elif target.is_dir():
            faults["folder"].append(name)
        elif not target.exists():
            create.append(name)
        elif name in unchanged:
            replace.append(name)
        else:
            faults["changed" if name in ours else "foreign"].append(name)
    problems = [*blocked]
    for kind, one, many in (
            ("link", "is a symbolic link", "are symbolic links"),
            ("folder", "is a folder", "are folders"),
            ("changed", f"was changed since {tool} wrote it",
             f"were changed since {tool} wrote them"),
            ("foreign", f"was not written by {tool}", f"were not written by {tool}")):
        if faults[kind]:
            problems.append(_problem_text(faults[kind], one, many))
    if problems:
        raise OutputFolderError(
            f"{tool} will not write into {shown(out_dir)}: {'; '.join(problems)}. Nothing was "
            f"changed; move those files away, or give another output folder")
    wanted = set(names)
    delete = sorted(name for name in unchanged if name not in wanted)
    return OutputPlan(tuple(replace), tuple(create), tuple(delete), dict(ours))


@contextlib.contextmanager
def _held_folder(out_dir: Path) -> Iterator[None]:
    """Create ``out_dir`` if needed and hold it (:class:`FolderLock`, which first recovers a
    killed swap); a folder created here and empty when the block fails is removed again."""
    created = not out_dir.exists()
    out_dir.mkdir(parents=True, exist_ok=True)
    try:
        with FolderLock(out_dir):
            yield
    except BaseException:
        if created:
            with contextlib.suppress(OSError):
                out_dir.rmdir()  # only if empty
        raise


def write_output_folder(out_dir: Path | str, files: Mapping[str, bytes | str], *, tool: str,
                        sources: Sequence[Path | str] = ()) -> list[Path]:
    """Write a whole build into ``out_dir``, all or nothing, touching only the tool's files.

    Holds the folder (created if needed; a swap killed there is recovered first), then
    checks it (:func:`plan_output_folder`): a file in the way that the tool did not
    write, or changed since, stops the build before anything is written. Then the files
    and the manifest are swapped in and the files of an earlier build no longer written
    deleted (:func:`~lqe_helpers.authoring.swap.swap_folders`, all or nothing).

    Parameters
    ----------
    out_dir : Path or str
        The output folder (its parent folders are created if needed).
    files : mapping of str to bytes or str
        Relative POSIX path → content (``str`` is written as UTF-8).
    tool : str
        The tool's name (recorded in the manifest :data:`MANIFEST_NAME`).
    sources : sequence of Path or str
        The folders the build reads, which ``out_dir`` must not overlap.

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
    return build_output_folder(out_dir, list(files), lambda: files, tool=tool, sources=sources)


def build_output_folder(out_dir: Path | str, names: Sequence[str],
                        build: Callable[[], Mapping[str, bytes | str]], *, tool: str,
                        sources: Sequence[Path | str] = ()) -> list[Path]:
    """Hold and check ``out_dir``, run ``build()``, write what it returns: every tool's shape.

    An existing folder is held (and a killed swap there recovered) *before* it is checked
    for ``names``, and for the whole (perhaps long) build, so a second tool on it stops
    at once; then the files ``build`` returns are written as :func:`write_output_folder`
    says.

    Returns
    -------
    list of Path
        The written files, in the order ``build`` returned them.
    """
    out_dir = Path(out_dir)
    check_output_names(names)
    check_output_location(out_dir, sources)
    with FolderLock(out_dir) if out_dir.is_dir() else contextlib.nullcontext():
        plan_output_folder(out_dir, names, tool=tool, sources=sources)
        contents = {name: as_bytes(data) for name, data in build().items()}
        try:
            with _held_folder(out_dir):
                plan = plan_output_folder(out_dir, contents, tool=tool, sources=sources)
                manifest = Manifest(tool, {name: sha256(data) for name, data in contents.items()})
                expected = {**{name: None for name in plan.create},
                            **{name: plan.ours[name] for name in plan.replace}}
                writes = {**contents, MANIFEST_NAME: manifest.to_bytes()}
                deletes = {name: plan.ours[name] for name in plan.delete}
                swap_folders({out_dir: (writes, deletes, expected, {})}, tool, shown(out_dir),
                             strict=True)
        except OSError as error:
            where = f" ({shown(error.filename)})" if error.filename else ""
            raise OutputWriteError(
                f"cannot write into {shown(out_dir)}: {error.strerror or error}{where}; "
                f"it was left as it was") from error
    return [out_dir / name for name in contents]


def remove_output_folder(out_dir: Path | str) -> tuple[list[Path], list[Path]] | None:
    """Delete what a tool wrote in ``out_dir`` (per its manifest); the folder too if then empty.

    The folder is held and a swap killed there recovered first. Then only files listed
    in the manifest that still hold exactly what the tool wrote are deleted, then the
    manifest and the sub-folders of listed files (and ``out_dir``) left empty.

    Returns
    -------
    tuple of (list of Path, list of Path) or None
        The deleted files and the files left in ``out_dir``; ``None`` (nothing touched)
        if ``out_dir`` holds no manifest.

    Raises
    ------
    OutputFolderError
        If the manifest or journal cannot be trusted, or another tool holds the folder;
        nothing is deleted then.
    """
    out_dir = Path(out_dir)
    removed: list[Path] = []
    with FolderLock(out_dir):
        manifest = read_manifest(out_dir)
        if manifest is None:
            return None
        folders: set[Path] = set()
        for name, digest in sorted(manifest.files.items()):
            path = out_dir / name
            folders.update(out_dir / parent for parent in PurePosixPath(name).parents[:-1])
            if file_sha256(path) == digest:
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
