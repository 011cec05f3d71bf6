"""Notebook files: read one and check it is a notebook, list a folder's, a notebook's bytes.

Every tool reads notebooks through :func:`read_notebook`, whose one-line errors name the
file; :func:`notebook_bytes` is exactly what :func:`nbformat.write` saves (the tools write
it through :mod:`lqe_helpers.authoring.output_folder` or
:func:`~lqe_helpers.authoring.folder_lock.atomic_write_many`).
"""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path
from typing import TYPE_CHECKING

from lqe_helpers.authoring.errors import NotebookFileError, first_line, shown, summarise

if TYPE_CHECKING:
    import nbformat

#: The largest notebook file the tools read (bytes); an executed notebook of the pack is
#: well under 10 MB.
MAX_NOTEBOOK_BYTES = 256 * 2**20
#: How deeply a notebook's JSON may nest lists and objects (a notebook of the pack: < 15).
MAX_DEPTH = 100


def read_notebook(path: Path | str) -> nbformat.NotebookNode:
    """Read and validate the notebook at ``path`` (nbformat 4).

    Raises
    ------
    NotebookFileError
        With a one-line message naming ``path`` if it is missing, a folder, not a
        regular file (a fifo, a device), larger than :data:`MAX_NOTEBOOK_BYTES`,
        unreadable, or not a notebook (:func:`parse_notebook`).
    """
    path = Path(path)
    return parse_notebook(path, read_notebook_bytes(path))


def read_notebook_bytes(path: Path) -> bytes:
    """The bytes of the notebook file ``path`` (see :func:`read_notebook` for the checks)."""
    try:
        status = os.stat(path)
        if stat.S_ISDIR(status.st_mode):
            raise NotebookFileError(f"{shown(path)} is a folder, not a notebook")
        if not stat.S_ISREG(status.st_mode):
            raise NotebookFileError(f"{shown(path)} is not a regular file (a fifo, device or "
                                    f"socket), so not a notebook")
        if status.st_size > MAX_NOTEBOOK_BYTES:
            raise NotebookFileError(
                f"{shown(path)} is {status.st_size / 2**20:.0f} MB, larger than the "
                f"{MAX_NOTEBOOK_BYTES // 2**20} MB the tools read as a notebook")
        return path.read_bytes()
    except FileNotFoundError:
        raise NotebookFileError(f"{shown(path)}: no such file") from None
    except OSError as error:
        raise NotebookFileError(f"{shown(path)}: cannot read it: {error.strerror}") from error


def parse_notebook(path: Path, raw: bytes) -> nbformat.NotebookNode:
    """The notebook in ``raw``, the content of the file ``path``, after checking it is one.

    A notebook here is UTF-8 JSON of nbformat 4 (minor version up to the installed
    nbformat's), valid against its schema, nested at most :data:`MAX_DEPTH` levels.

    Raises
    ------
    NotebookFileError
        With a one-line message naming ``path`` if ``raw`` is not such a notebook.
    """
    import nbformat  # here, so that the rest of this module needs only the standard library

    try:
        text = raw.decode("utf-8")
        content = json.loads(text)
    except UnicodeDecodeError as error:
        raise NotebookFileError(f"{shown(path)} is not a notebook (not UTF-8 text: "
                                f"{error.reason} at byte {error.start})") from error
    except json.JSONDecodeError as error:
        raise NotebookFileError(f"{shown(path)} is not a notebook (not valid JSON: {error.msg} "
                                f"at line {error.lineno}, column {error.colno})") from error
    except RecursionError:
        raise NotebookFileError(f"{shown(path)} is not a valid notebook: its JSON is nested "
                                f"too deeply") from None
    if not isinstance(content, dict) or not isinstance(content.get("nbformat"), int) \
            or isinstance(content.get("nbformat"), bool):
        raise NotebookFileError(f"{shown(path)} is not a valid notebook: JSON without an "
                                f"'nbformat' version number")
    major, minor = content["nbformat"], content.get("nbformat_minor")
    if major != nbformat.current_nbformat or (
            isinstance(minor, int) and not 0 <= minor <= nbformat.current_nbformat_minor):
        shown_minor = f".{minor}" if isinstance(minor, int) else ""
        raise NotebookFileError(
            f"{shown(path)} is not a valid notebook: nbformat {major}{shown_minor}, where the "
            f"tools read 4.0 to 4.{nbformat.current_nbformat_minor} (open and save it in "
            f"JupyterLab to convert it)")
    depth = _depth(content)
    if depth > MAX_DEPTH:
        raise NotebookFileError(f"{shown(path)} is not a valid notebook: its JSON is nested "
                                f"{depth} levels deep (at most {MAX_DEPTH})")
    try:
        notebook = nbformat.reads(text, as_version=4)
        nbformat.validate(notebook)
    except nbformat.ValidationError as error:
        raise NotebookFileError(f"{shown(path)} is not a valid notebook: "
                                f"{first_line(error.message)}") from error
    except (ValueError, TypeError, KeyError, AttributeError, RecursionError) as error:
        raise NotebookFileError(f"{shown(path)} is not a valid notebook: "
                                f"{first_line(str(error)) or type(error).__name__}") from error
    return notebook


def _depth(content: object) -> int:
    """How deeply ``content`` (parsed JSON) nests lists and objects (no recursion)."""
    deepest, stack = 0, [(content, 1)]
    while stack:
        value, level = stack.pop()
        children = value.values() if isinstance(value, dict) else value \
            if isinstance(value, list) else ()
        for child in children:
            if isinstance(child, dict | list):
                deepest = max(deepest, level + 1)
                stack.append((child, level + 1))
    return deepest


def source_notebooks(source_dir: Path | str) -> list[Path]:
    """The ``*.ipynb`` files directly in ``source_dir``, in name order.

    Raises
    ------
    ValueError
        If ``source_dir`` is not a folder or holds no notebook, or if a ``*.ipynb`` there
        is a symbolic link (the tools never follow a link to a source: it could be any
        file) or not a file at all (a folder, a fifo: never silently skipped).
    """
    source_dir = Path(source_dir)
    if not source_dir.is_dir():
        raise ValueError(f"source_dir must be an existing folder, got {shown(source_dir)}")
    notebooks = sorted(source_dir.glob("*.ipynb"))
    links = [path.name for path in notebooks if path.is_symlink()]
    if links:
        raise NotebookFileError(
            f"{summarise(links)} in {shown(source_dir)} "
            f"{'is a symbolic link' if len(links) == 1 else 'are symbolic links'}; the tools "
            f"read only real notebook files: put the notebook itself there")
    odd = [path.name for path in notebooks if not path.is_file()]
    if odd:
        raise NotebookFileError(
            f"{summarise(odd)} in {shown(source_dir)} "
            f"{'is' if len(odd) == 1 else 'are'} named like a notebook but not a file (a "
            f"folder, a fifo, a device); rename or remove {'it' if len(odd) == 1 else 'them'}")
    if not notebooks:
        raise ValueError(f"source_dir must hold at least one .ipynb file, got none in "
                         f"{shown(source_dir)}")
    return notebooks


def notebook_bytes(notebook: nbformat.NotebookNode) -> bytes:
    """The ``.ipynb`` file content of ``notebook``, exactly as :func:`nbformat.write` saves it."""
    import nbformat
    text = nbformat.writes(notebook)
    if not text.endswith("\n"):
        text += "\n"
    return text.encode("utf-8")
