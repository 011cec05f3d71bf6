"""Notebook files: read one and check it is a notebook, list a folder's, save one.

Every tool reads notebooks through :func:`read_notebook`, whose one-line errors name the
file; :func:`notebook_bytes` is exactly what :func:`nbformat.write` saves, and
:func:`write_notebook` saves it atomically (:mod:`lqe_helpers.authoring.files`).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from lqe_helpers.authoring.errors import NotebookFileError, first_line
from lqe_helpers.authoring.files import atomic_write_bytes

if TYPE_CHECKING:
    import nbformat


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
                                f"{first_line(error.message)}") from error
    except (ValueError, TypeError, KeyError, AttributeError) as error:
        raise NotebookFileError(f"{path} is not a valid notebook: "
                                f"{first_line(str(error)) or type(error).__name__}") from error
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
