"""The manifest a tool keeps in its output folder: what it wrote there, with checksums.

:data:`MANIFEST_NAME` (JSON) lists every file a tool wrote in its output folder with its
SHA-256; a rebuild and ``clean`` replace or delete only those files, and only while they
still hold what the tool wrote.

The manifest is a file anyone can edit, so nothing in it is trusted: every entry must be
a plain relative path inside the folder (:func:`entry_problem`, the one check of a name
used by every tool, by ``clean`` and by the journal of a build), and a manifest with any
other entry stops the tool before it touches a file. Standard library only.
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from lqe_helpers.authoring.errors import OutputFolderError, shown
from lqe_helpers.authoring.files import regular_file_bytes

#: Name of the manifest a tool keeps in its output folder (a JSON file).
MANIFEST_NAME = ".lqe-manifest.json"
#: Version of the manifest's format.
MANIFEST_FORMAT = 1
#: What a name in an output folder may not start with: the tools' own files and folders.
RESERVED_PREFIX = ".lqe-"
#: The largest manifest the tools read (bytes): one of thousands of files is < 1 MB.
MAX_MANIFEST_BYTES = 4 * 2**20
_SHA256 = re.compile(r"[0-9a-f]{64}")


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


def name_problem(name: object, *, manifest_ok: bool = False) -> str:
    """Why ``name`` is not a plain relative POSIX path of a file ('' if it is).

    A plain path has no empty, ``.`` or ``..`` part, no backslash, no NUL, is not
    absolute, and does not start with :data:`RESERVED_PREFIX` (the tools' own names;
    :data:`MANIFEST_NAME` itself is allowed if ``manifest_ok``).
    """
    if not isinstance(name, str) or not name:
        return "not a file name"
    if "\x00" in name or "\\" in name:
        return "a name with a NUL or a backslash"
    relative = PurePosixPath(name)
    if relative.is_absolute():
        return "an absolute path"
    if relative.as_posix() != name or any(part in {".", ".."} for part in name.split("/")):
        return "not a plain relative path"
    if relative.parts[0].startswith(RESERVED_PREFIX) and not (manifest_ok
                                                             and name == MANIFEST_NAME):
        return f"a name the tools keep for themselves ({RESERVED_PREFIX}…)"
    return ""


def blocked_parent(out_dir: Path, relative: PurePosixPath) -> str:
    """Why a sub-folder on the way to ``relative`` cannot hold it ('' if it can)."""
    folder = out_dir
    for part in relative.parts[:-1]:
        folder = folder / part
        if os.path.islink(folder):
            return f"{shown(folder.relative_to(out_dir).as_posix())}/ is a symbolic link"
        if folder.exists() and not folder.is_dir():
            return f"{shown(folder.relative_to(out_dir).as_posix())} is a file, not a folder"
    return ""


def entry_problem(folder: Path, name: object, *, manifest_ok: bool = False) -> str:
    """Why ``name`` cannot name a file of ``folder`` that a tool may write or delete.

    The one check of a name in an output folder (manifest entries, journal entries,
    and the names a build writes): a plain relative path (:func:`name_problem`) whose
    sub-folders are real folders, not links (:func:`blocked_parent`), and which
    resolves inside ``folder``. Returns '' if ``name`` is fine. ``manifest_ok`` allows
    :data:`MANIFEST_NAME` (a build writes it; a manifest never lists it).
    """
    problem = name_problem(name, manifest_ok=manifest_ok)
    if problem:
        return problem
    assert isinstance(name, str)
    relative = PurePosixPath(name)
    problem = blocked_parent(folder, relative)
    if problem:
        return f"a path where {problem}"
    inside = os.path.realpath(folder)
    parent = os.path.realpath(folder / relative.parent)
    if os.path.commonpath([inside, parent]) != inside:
        return "a path that leads outside the folder"
    return ""


def read_manifest(out_dir: Path | str) -> Manifest | None:
    """The manifest in ``out_dir``, or ``None`` if there is none.

    Every entry is checked (:func:`entry_problem`) before the manifest is returned,
    so no caller acts on a name outside the folder.

    Raises
    ------
    OutputFolderError
        If the manifest exists but is a link, cannot be read as one, or lists an entry
        that is not a plain relative path inside ``out_dir`` (named in the message).
    """
    out_dir = Path(out_dir)
    path = out_dir / MANIFEST_NAME
    if not os.path.lexists(path):
        return None
    unreadable = (f"{path} is not a manifest the course tools can read (%s); nothing was "
                  f"changed: move the folder {out_dir} away or write elsewhere")
    try:
        content = json.loads(regular_file_bytes(path, MAX_MANIFEST_BYTES, "manifest")
                             .decode("utf-8"))
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as error:
        reason = error.strerror if isinstance(error, OSError) else (
            "nested too deeply" if isinstance(error, RecursionError) else str(error))
        raise OutputFolderError(unreadable % reason) from error
    problem = _shape_problem(content)
    if problem:
        raise OutputFolderError(unreadable % problem)
    for name in content["files"]:
        problem = entry_problem(out_dir, name)
        if problem:
            raise OutputFolderError(
                f"{path} lists {name!r}, which is {problem}, not a plain relative "
                f"path inside {out_dir}; nothing was changed: the tools never delete or "
                f"replace a file through such an entry (remove it from the manifest, or "
                f"move the folder away)")
    return Manifest(content["tool"], dict(content["files"]))


def _shape_problem(content: object) -> str:
    """What is wrong with the JSON of a manifest ('' if it has the right shape)."""
    if not isinstance(content, dict):
        return "not a JSON object"
    if content.get("format") != MANIFEST_FORMAT:
        return f"format {content.get('format')!r}, not {MANIFEST_FORMAT}"
    if not isinstance(content.get("tool"), str):
        return "no tool name"
    files = content.get("files")
    if not isinstance(files, dict):
        return "no 'files' object"
    bad = [name for name, digest in files.items()
           if not isinstance(digest, str) or not _SHA256.fullmatch(digest)]
    if bad:
        return f"entries without a SHA-256: {', '.join(map(repr, bad[:3]))}"
    return ""
