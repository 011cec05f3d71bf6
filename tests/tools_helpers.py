"""Shared pieces of the instructor tools' attack tests (tests/test_tools_*.py).

Small course folders and notebooks built from scratch, a snapshot of a folder, and a
way to run a tool's command line in a fresh interpreter (as ``make`` does).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

from lqe_helpers.authoring import student_pack

ROOT = Path(__file__).resolve().parents[1]
#: The code the command-line tests run: this folder's, or (to see a test fail before a fix)
#: another checkout named by LQE_TOOLS_UNDER_TEST.
TOOLS_ROOT = Path(os.environ.get("LQE_TOOLS_UNDER_TEST", ROOT))
KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
MANIFEST = ".lqe-manifest.json"

SOLUTION = ("# Task: compute the mean squared error of the estimate (cm²).\n"
            "mse = ((estimate - truth) ** 2).mean()\n"
            "print(f'MSE = {mse:.1f} cm²')")


def snapshot(folder: Path) -> dict[str, bytes | str]:
    """Every file (its bytes), link (its target) and folder under ``folder``."""
    found: dict[str, bytes | str] = {}
    if not folder.exists():
        return found
    for path in sorted(folder.rglob("*")):
        name = path.relative_to(folder).as_posix()
        if path.is_symlink():
            found[name] = f"link -> {os.readlink(path)}"
        elif path.is_dir():
            found[name] = "folder"
        else:
            found[name] = path.read_bytes()
    return found


def sha256_of(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def worked_notebook(*, solution: str = SOLUTION, tags: tuple[str, ...] = ("solution",),
                    extra: list | None = None) -> nbformat.NotebookNode:
    """A small executed worked notebook: title, setup, one task with its check, an answer."""
    task = new_code_cell(solution, metadata={"tags": list(tags)}, execution_count=2,
                         outputs=[new_output("stream", name="stdout", text="MSE = 1.0 cm²\n")])
    check = new_code_cell("checks.check_steady_state(mse, mse)", execution_count=3,
                          outputs=[new_output("stream", name="stdout", text="✓ right\n")])
    cells = [
        new_markdown_cell("# A worked notebook\n\nWhat will you learn?"),
        new_code_cell("import numpy as np\nestimate, truth = np.ones(3), np.zeros(3)",
                      execution_count=1),
        task, check,
        new_markdown_cell("### Your conclusion\n\nThe error is small.",
                          metadata={"tags": ["answer"]}),
        *(extra or []),
    ]
    return new_notebook(cells=cells, metadata={"kernelspec": KERNELSPEC,
                                               "language_info": {"name": "python"}})


def write_notebook(path: Path, notebook: nbformat.NotebookNode | None = None) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(worked_notebook() if notebook is None else notebook, path)
    return path


def code_notebook(path: Path, *sources: str) -> Path:
    """A notebook of code cells ``sources`` (for the runner)."""
    return write_notebook(path, new_notebook(cells=[new_code_cell(source) for source in sources],
                                             metadata={"kernelspec": KERNELSPEC}))


def make_course(root: Path) -> Path:
    """A minimal course folder the student pack can be built from."""
    root.mkdir(parents=True, exist_ok=True)
    for name in ("Makefile", "pyproject.toml", "constraints.txt"):
        shutil.copy2(ROOT / name, root / name)
    (root / "README.md").write_text("# The course\n\nRead me.\n", encoding="utf-8")
    (root / "lqe_helpers").mkdir()
    (root / "lqe_helpers" / "__init__.py").write_text('"""Helpers."""\n')
    (root / "lqe_helpers" / "science.py").write_text("VALUE = 1\n")
    (root / "tests").mkdir()
    (root / "tests" / "test_science.py").write_text("def test_value():\n    assert True\n")
    for name in student_pack.PACK_TESTS:  # the tests the pack ships, here trivial ones
        (root / "tests" / name).parent.mkdir(parents=True, exist_ok=True)
        (root / "tests" / name).write_text("def test_shipped():\n    assert True\n")
    write_notebook(root / "notebooks" / "01_first.ipynb")
    return root


def poison_manifest(out: Path, entry: str, victim: Path) -> None:
    """Add ``entry`` to ``out``'s manifest with the checksum of ``victim`` (the attack)."""
    path = out / MANIFEST
    content = json.loads(path.read_text(encoding="utf-8"))
    content["files"][entry] = sha256_of(victim)
    path.write_text(json.dumps(content), encoding="utf-8")


def run_tool(tool: str, *args: str, cwd: Path | None = None, env: dict[str, str] | None = None,
             timeout: float = 120) -> subprocess.CompletedProcess[str]:
    """``python -m lqe_helpers.authoring.<tool> args`` in a fresh interpreter."""
    environment = {**tools_environment(), **(env or {})}
    return subprocess.run(python_command("-m", f"lqe_helpers.authoring.{tool}", *args),
                          cwd=cwd, env=environment, capture_output=True, text=True,
                          timeout=timeout, check=False)


def python_command(*args: str) -> list[str]:
    """A fresh interpreter that imports the package from :data:`TOOLS_ROOT` only (``-P``:
    not from the current folder, which may hold a course folder's own ``lqe_helpers``)."""
    return [sys.executable, "-P", *args]


def tools_environment() -> dict[str, str]:
    """The environment of a tool run: this one, importing from :data:`TOOLS_ROOT`."""
    return {**os.environ, "PYTHONPATH": str(TOOLS_ROOT)}


def error_lines(stderr: str) -> list[str]:
    """The ``error:`` lines of a command's stderr."""
    return [line for line in stderr.splitlines() if line.startswith("error: ")]
