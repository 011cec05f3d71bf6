"""The suite's own plumbing: shared artefacts built once, the ``kernel`` marker enforced.

tests/once_per_run.py builds each costly artefact of tests/artefacts.py once per test
run, also when pytest-xdist runs two sessions at once, and notices a test that changed
one; tests/conftest.py fails a test that starts a Jupyter kernel without the ``kernel``
marker (which ``make test-fast`` relies on) and marks nbval's notebook cells.
Instructor's side of the suite: it checks the machinery behind tests/artefacts.py, which
builds with lqe_helpers.authoring, so the student pack leaves this file out.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import nbformat
import pytest
from make_env import make_environment
from once_per_run import SharedArtefacts, writable_copy

TESTS = Path(__file__).resolve().parent

# Two of these run at once, as two pytest-xdist workers would: each asks for the same
# artefact, whose build takes a second and counts itself.
SESSION = """
import json, sys, time
from pathlib import Path
sys.path.insert(0, {tests!r})
from once_per_run import SharedArtefacts

root, worker = Path(sys.argv[1]), sys.argv[2]

def build(folder):
    with open(root / "builds.txt", "a") as count:
        count.write(worker + "\\n")
    time.sleep(1.0)
    folder.mkdir()
    (folder / "page.html").write_text("built by " + worker)
    return {{"by": worker}}

builds = []
folder, data = SharedArtefacts(root, worker, builds).get("pages", build)
print(json.dumps({{"data": data, "page": (folder / "page.html").read_text(),
                  "built": len(builds)}}))
"""


@pytest.mark.slow
def test_two_sessions_at_once_build_an_artefact_once(tmp_path):
    script = tmp_path / "session.py"
    script.write_text(SESSION.format(tests=str(TESTS)))
    root = tmp_path / "run"
    root.mkdir()
    sessions = [subprocess.Popen([sys.executable, str(script), str(root), worker],
                                 stdout=subprocess.PIPE, text=True)
                for worker in ("gw0", "gw1")]
    outputs = [json.loads(session.communicate(timeout=120)[0]) for session in sessions]
    assert all(session.returncode == 0 for session in sessions)
    [builder] = (root / "builds.txt").read_text().split()
    assert sorted(output["built"] for output in outputs) == [0, 1]
    for output in outputs:
        assert output["data"] == {"by": builder}
        assert output["page"] == f"built by {builder}"


def test_a_failed_build_fails_every_session_that_needs_it_and_is_not_retried(tmp_path):
    calls = []

    def broken(folder: Path) -> None:
        calls.append(folder)
        raise ValueError("notebook 03 raised")

    with pytest.raises(ValueError, match="notebook 03 raised"):
        SharedArtefacts(tmp_path, "gw0", []).get("handouts", broken)
    with pytest.raises(pytest.fail.Exception,
                       match=r"shared build of 'handouts' failed \(in session gw0\).*"
                             r"ValueError: notebook 03 raised"):
        SharedArtefacts(tmp_path, "gw1", []).get("handouts", broken)
    assert len(calls) == 1


def test_an_artefact_is_read_only_and_a_change_to_it_is_found(tmp_path):
    def build(folder: Path) -> list[str]:
        (folder / "prose").mkdir(parents=True)
        (folder / "index.html").write_text("index")
        (folder / "prose" / "index.html").write_text("prose")
        return ["index.html"]

    builds: list = []
    artefacts = SharedArtefacts(tmp_path, "main", builds)
    folder, data = artefacts.get("handouts", build)
    assert data == ["index.html"] and [build.artefact for build in builds] == ["handouts"]
    for path in [folder, *folder.rglob("*")]:
        assert path.stat().st_mode & 0o222 == 0, path
    assert artefacts.get("handouts", build) == (folder, data)  # no second build
    assert len(builds) == 1
    assert artefacts.changed() == []

    copy = writable_copy(folder, tmp_path / "copy")
    (copy / "prose" / "index.html").write_text("changed in the copy")
    (copy / "new.html").write_text("new")
    assert artefacts.changed() == []

    for path in (folder, folder / "prose"):
        path.chmod(0o755)
    (folder / "prose" / "index.html").chmod(0o644)
    (folder / "prose" / "index.html").write_text("changed by a test")
    (folder / "index.html").unlink()
    (folder / "extra.html").write_text("added by a test")
    assert sorted(artefacts.changed()) == ["handouts/extra.html: added",
                                           "handouts/index.html: deleted",
                                           "handouts/prose/index.html: changed"]


UNMARKED = """
import pytest
from jupyter_client.manager import start_new_kernel


def start_and_stop_a_kernel():
    manager, client = start_new_kernel(kernel_name="python3")
    client.stop_channels()
    manager.shutdown_kernel(now=True)


def test_unmarked():
    start_and_stop_a_kernel()


@pytest.mark.kernel
def test_marked():
    start_and_stop_a_kernel()


def test_no_kernel():
    pass
"""


def pytest_in(folder: Path, *arguments: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", *arguments],
                          cwd=folder, capture_output=True, text=True, timeout=300,
                          env=make_environment())


@pytest.mark.kernel
def test_a_test_that_starts_a_kernel_without_the_marker_fails(tmp_path):
    shutil.copy(TESTS / "conftest.py", tmp_path / "conftest.py")
    (tmp_path / "pytest.ini").write_text("[pytest]\nmarkers =\n    kernel: starts a kernel\n")
    (tmp_path / "test_kernels.py").write_text(textwrap.dedent(UNMARKED))
    result = pytest_in(tmp_path, "-rA", "-q", "-p", "no:nbval")  # no notebook: start faster
    assert result.returncode == 1, result.stdout[-3000:]
    assert result.stdout.splitlines()[-1].startswith("1 failed, 2 passed"), result.stdout[-3000:]
    assert ("test_kernels.py::test_unmarked started 1 Jupyter kernel(s) but is not marked "
            "@pytest.mark.kernel") in result.stdout
    assert "PASSED test_kernels.py::test_marked" in result.stdout


# A plugin that prints whether each test left out by -m is marked kernel.
SHOW_MARKS = """
def pytest_deselected(items):
    for item in items:
        print("MARKS", item.nodeid, item.get_closest_marker("kernel") is not None, sep="|")
"""


def conftest_in(folder: Path) -> None:
    """This suite's conftest.py in ``folder``, with the ``kernel`` marker registered."""
    shutil.copy(TESTS / "conftest.py", folder / "conftest.py")
    (folder / "pytest.ini").write_text("[pytest]\nmarkers =\n    kernel: starts a kernel\n")


@pytest.mark.slow
def test_notebook_cells_carry_the_kernel_marker(tmp_path):
    conftest_in(tmp_path)
    (tmp_path / "show_marks.py").write_text(SHOW_MARKS)
    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("1 + 1"),
                                               nbformat.v4.new_code_cell("2 + 2")])
    nbformat.write(notebook, tmp_path / "one.ipynb")
    shown = pytest_in(tmp_path, "-p", "show_marks", "--nbval", "one.ipynb", "-m", "not kernel",
                      "--collect-only", "-q")
    marks = [line.split("|")[1:] for line in shown.stdout.splitlines()
             if line.startswith("MARKS|")]
    assert marks == [[f"one.ipynb::Cell {index}", "True"] for index in range(2)], shown.stdout


# Each test writes down which pytest-xdist worker ran it.
WHERE = """
import os
from pathlib import Path


def test_{name}():
    Path(os.environ["WORKERS_SEEN"], "{name}").write_text(os.environ["PYTEST_XDIST_WORKER"])
"""


@pytest.mark.slow
def test_the_files_of_a_worker_group_run_in_one_worker(tmp_path):
    """The two JupyterLab files come first; as two units they would go to two workers."""
    conftest_in(tmp_path)
    files = {"lab": "tests/browser/test_notebooks_in_jupyterlab.py",
             "harness": "tests/browser/test_harness.py", "other": "tests/test_other.py",
             "more": "tests/test_more.py"}
    for name, path in files.items():
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(WHERE.format(name=name))
    seen = tmp_path / "seen"
    seen.mkdir()
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-p", "no:nbval", "-q",
         "-n", "2", "--dist", "loadfile", "--no-loadscope-reorder", "tests"],
        cwd=tmp_path, capture_output=True, text=True, timeout=300,
        env=make_environment(WORKERS_SEEN=str(seen)))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    workers = {path.name: path.read_text() for path in seen.iterdir()}
    assert sorted(workers) == sorted(files)
    assert workers["lab"] == workers["harness"]
    assert len(set(workers.values())) == 2, workers  # the other files went to the other one
