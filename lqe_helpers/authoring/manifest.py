"""The manifest a tool keeps in its output folder: what it wrote there, with checksums.

:data:`MANIFEST_NAME` (JSON) lists every file a tool wrote in its output folder with its
SHA-256; a rebuild and ``clean`` replace or delete only those files, and only while they
still hold what the tool wrote. Standard library only.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from lqe_helpers.authoring.errors import OutputFolderError
from lqe_helpers.authoring.files import refuse_symlink

#: Name of the manifest a tool keeps in its output folder (a JSON file).
MANIFEST_NAME = ".lqe-manifest.json"
#: Version of the manifest's format.
MANIFEST_FORMAT = 1


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


def check_name(name: str) -> PurePosixPath:
    """``name`` as a path, if it is a plain relative path inside a folder (else ValueError)."""
    relative = PurePosixPath(name)
    if (relative.is_absolute() or not relative.parts or ".." in relative.parts
            or relative.parts[0].startswith(".lqe-") or name != relative.as_posix()):
        raise ValueError(f"output file names must be plain relative paths inside the output "
                         f"folder, got {name!r}")
    return relative


def blocked_parent(out_dir: Path, relative: PurePosixPath) -> str:
    """Why a sub-folder on the way to ``relative`` cannot hold it ('' if it can)."""
    folder = out_dir
    for part in relative.parts[:-1]:
        folder = folder / part
        if os.path.islink(folder):
            return f"{folder.relative_to(out_dir).as_posix()}/ is a symbolic link"
        if folder.exists() and not folder.is_dir():
            return f"{folder.relative_to(out_dir).as_posix()} is a file, not a folder"
    return ""
