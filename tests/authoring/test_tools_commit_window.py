"""The notebook runner's commit window: an author's save is never overwritten.

Issue 26: ``notebook_runner`` overwrote an edit an author saved by atomic rename about
1 ms after its journal appeared (3 of 21 trials) and reported ``saved``: it compared the
file, then replaced it, and a save landing in between was lost. Here the author's save
is made deterministically at the worst moment, right before the runner's first rename
that touches the notebook, and right after it.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from tools_helpers import code_notebook

from lqe_helpers.authoring import notebook_runner
from lqe_helpers.authoring.notebook_io import notebook_bytes, read_notebook

REAL_RENAME = os.rename


def author_saves(path: Path, text: bytes) -> None:
    """JupyterLab's save: a temporary file renamed over the notebook."""
    temporary = path.with_name(".~" + path.name)
    temporary.write_bytes(text)
    REAL_RENAME(temporary, path)


@pytest.mark.parametrize("when", ["before the new file goes in", "after the first rename"])
def test_an_edit_saved_at_the_moment_of_the_save_is_kept(tmp_path, monkeypatch, when):
    """The save lands right before the runner puts the new notebook in place (after every
    check it makes), or right after its first rename of the notebook."""
    path = code_notebook(tmp_path / "01.ipynb", "print('one')")
    edit = path.read_bytes().replace(b"print('one')", b"print('edited')")
    monkeypatch.setattr(notebook_runner, "execute_notebook",
                        lambda notebook, *args: read_notebook(notebook))
    monkeypatch.setattr(notebook_runner, "notebook_bytes",
                        lambda notebook: notebook_bytes(notebook) + b"\n")  # new outputs
    saved: list[None] = []

    def at_the_moment(real):
        def operation(source, target, *args, **kwargs):
            new_in = Path(target) == path and ".lqe-build-" in str(source)
            if new_in and not saved and when.startswith("before"):
                saved.append(author_saves(path, edit))
            result = real(source, target, *args, **kwargs)
            if path in (Path(source), Path(target)) and not saved and when.startswith("after"):
                saved.append(author_saves(path, edit))
            return result
        return operation

    for name in ("replace", "rename", "link"):
        monkeypatch.setattr(os, name, at_the_moment(getattr(os, name)))
    written, kept = notebook_runner.run_notebooks([path], log=False)
    monkeypatch.undo()
    assert saved, "the runner never renamed the notebook"
    assert path.read_bytes() == edit
    assert (written, kept) == ([], [path])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["01.ipynb"]
