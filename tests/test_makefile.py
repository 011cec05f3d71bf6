"""The Makefile: ``make clean`` removes only what it made; ``make lab`` starts for everyone.

``make clean`` and the broken-``.venv`` message are tried for real on a copy of the
pack's Makefile and tools in ``tmp_path`` (with a stand-in ``.venv``), never on this
checkout. ``make lab`` is started for real in this checkout, as the current user (root
on CI), on a free port of 127.0.0.1 with a token, and stopped once it answers.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from make_env import make_environment, makefile_variables

from lqe_helpers.authoring.output_folder import write_output_folder

ROOT = Path(__file__).resolve().parents[1]
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
MAKE = shutil.which("make")
pytestmark = pytest.mark.skipif(MAKE is None, reason="make is not installed")

BROKEN_HINT = "run make clean, then make lab"


def snapshot(folder: Path) -> dict[str, bytes | str]:
    """Every file (its bytes), link (its target) and folder under ``folder``."""
    return {path.relative_to(folder).as_posix():
            (f"link -> {os.readlink(path)}" if path.is_symlink()
             else "folder" if path.is_dir() else path.read_bytes())
            for path in sorted(folder.rglob("*"))}


def make(folder: Path, *targets: str, env: dict[str, str] | None = None,
         timeout: float = 60) -> subprocess.CompletedProcess[str]:
    return subprocess.run([MAKE, "--no-print-directory", *targets], cwd=folder,
                          env=make_environment(**(env or {})), capture_output=True, text=True,
                          timeout=timeout, check=False)


def test_a_make_started_by_a_test_inherits_nothing_of_the_callers_make(monkeypatch):
    """``make test PYTEST_ARGS=--durations=60`` exports it, and MAKEFLAGS passes it on."""
    assert {"PYTEST_ARGS", "PYTHON", "CONSTRAINTS", "LAB_ARGS", "VENV"} <= makefile_variables()
    for name, value in {"MAKEFLAGS": " -- PYTEST_ARGS=--durations=60", "MFLAGS": "-s",
                        "MAKELEVEL": "1", "PYTEST_ARGS": "--durations=60", "LAB_ARGS": "x",
                        "PYTEST_ADDOPTS": "-x", "PYTEST_XDIST_WORKER": "gw1"}.items():
        monkeypatch.setenv(name, value)
    environment = make_environment(remove=["HOME"], VENV="kept")
    for name in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "PYTEST_ARGS", "LAB_ARGS", "PYTEST_ADDOPTS",
                 "PYTEST_XDIST_WORKER", "HOME"):
        assert name not in environment, name
    assert environment["VENV"] == "kept"
    assert environment["PATH"] == os.environ["PATH"]


@pytest.fixture
def pack(tmp_path: Path) -> Path:
    """A copy of the Makefile and the package, with a working stand-in ``.venv``."""
    copy = tmp_path / "pack"
    copy.mkdir()
    for name in ("Makefile", "pyproject.toml", "constraints.txt"):
        shutil.copy2(ROOT / name, copy / name)
    shutil.copytree(ROOT / "lqe_helpers", copy / "lqe_helpers",
                    ignore=shutil.ignore_patterns("__pycache__"))
    (copy / ".venv" / "bin").mkdir(parents=True)
    (copy / ".venv" / "bin" / "python").symlink_to(os.path.realpath(sys.executable))
    (copy / ".venv" / ".installed").write_text("")
    past = time.time() - 3600  # the stamp is newer than what it depends on: no install
    for name in ("pyproject.toml", "constraints.txt"):
        os.utime(copy / name, (past, past))
    return copy


# --- make clean --------------------------------------------------------------------------------

@pytest.mark.parametrize("how", ["environment", "command line"])
def test_clean_never_deletes_another_environment_named_by_venv(pack, tmp_path, how):
    """The issue's case: VENV=~/.virtualenvs/research make clean deleted that environment."""
    research = tmp_path / "virtualenvs" / "research"
    (research / "bin").mkdir(parents=True)
    (research / "bin" / "python").write_text("the researcher's environment")
    before = snapshot(research)
    if how == "environment":
        result = make(pack, "clean", env={"VENV": str(research)})
    else:
        result = make(pack, "clean", f"VENV={research}")
    assert result.returncode == 0, result.stderr
    assert snapshot(research) == before
    assert not (pack / ".venv").exists()  # the pack's own .venv is what goes


def test_clean_removes_only_what_the_makefile_made(pack):
    build = pack / "build"
    write_output_folder(build / "student", {"01.ipynb": "one", "02.ipynb": "two"},
                        tool="student_edition")
    write_output_folder(build / "handouts", {"index.html": "i", "prose/index.html": "p"},
                        tool="handouts")
    write_output_folder(build / "marking-guide", {"marking-guide.md": "m"},
                        tool="marking_guide")
    (build / "student" / "02.ipynb").write_text("hand-edited after the build")
    (build / "student" / "my_grading_notes.ipynb").write_text("grading notes")
    (build / "handouts" / "course_home.html").write_text("the instructor's page")
    (build / "screenshots").mkdir()
    (build / "screenshots" / "lab.png").write_bytes(b"png")
    (build / "my_own").mkdir()
    (build / "my_own" / "keep.txt").write_text("not the Makefile's")
    for cache in (".pytest_cache", ".ruff_cache", ".hypothesis", "lqe_course_pack.egg-info",
                  "lqe_helpers/__pycache__"):
        (pack / cache).mkdir(exist_ok=True)
        (pack / cache / "x").write_text("cache")
    (pack / "notes.md").write_text("the instructor's notes")

    result = make(pack, "clean")
    assert result.returncode == 0, result.stderr
    assert snapshot(build) == {
        "handouts": "folder", "handouts/course_home.html": b"the instructor's page",
        "my_own": "folder", "my_own/keep.txt": b"not the Makefile's",
        "student": "folder", "student/02.ipynb": b"hand-edited after the build",
        "student/my_grading_notes.ipynb": b"grading notes",
    }
    assert "kept in build/student: 02.ipynb, my_grading_notes.ipynb" in result.stdout
    assert "kept in build/handouts: course_home.html" in result.stdout
    for gone in (".venv", ".pytest_cache", ".ruff_cache", ".hypothesis",
                 "lqe_course_pack.egg-info", "lqe_helpers/__pycache__"):
        assert not (pack / gone).exists(), gone
    assert (pack / "notes.md").read_text() == "the instructor's notes"
    assert (pack / "lqe_helpers" / "authoring" / "files.py").is_file()


def test_clean_leaves_a_folder_without_manifest_and_only_unlinks_a_venv_link(pack, tmp_path):
    (pack / "build" / "student").mkdir(parents=True)
    (pack / "build" / "student" / "01.ipynb").write_text("from an older version of the pack")
    elsewhere = tmp_path / "elsewhere-venv"
    shutil.move(pack / ".venv", elsewhere)
    (pack / ".venv").symlink_to(elsewhere)
    before = snapshot(elsewhere)
    result = make(pack, "clean")
    assert result.returncode == 0, result.stderr
    assert "kept build/student: it has no .lqe-manifest.json" in result.stdout
    assert (pack / "build" / "student" / "01.ipynb").is_file()
    assert not os.path.lexists(pack / ".venv")
    assert snapshot(elsewhere) == before


# --- a broken .venv ----------------------------------------------------------------------------

@pytest.mark.parametrize("target", ["lab", "test", "student"])
def test_a_venv_whose_python_was_removed_says_to_run_make_clean(pack, target):
    python = pack / ".venv" / "bin" / "python"
    python.unlink()
    python.symlink_to("/nonexistent/python3.11")
    result = make(pack, target)
    assert result.returncode != 0
    assert result.stderr.splitlines()[0] == (
        "error: .venv is broken (its Python, /nonexistent/python3.11, no longer exists); "
        f"{BROKEN_HINT}")
    assert "No such file or directory" not in result.stderr
    assert result.stdout == ""
    # And make clean, which the message asks for, works without it.
    cleaned = make(pack, "clean")
    assert cleaned.returncode == 0, cleaned.stderr
    assert not (pack / ".venv").exists()


def test_a_venv_python_that_does_not_run_says_to_run_make_clean(pack):
    python = pack / ".venv" / "bin" / "python"
    python.unlink()
    python.write_text("#!/nonexistent/interpreter\n")
    python.chmod(0o755)
    result = make(pack, "lab")
    assert result.returncode != 0
    assert result.stderr.splitlines()[0] == (
        f"error: .venv is broken (.venv/bin/python does not run); {BROKEN_HINT}")


# --- make lab ----------------------------------------------------------------------------------

def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def answers(url: str) -> bool:
    try:
        with urllib.request.urlopen(url, timeout=2) as response:
            return response.status == 200
    except (urllib.error.URLError, OSError):
        return False


@pytest.mark.slow
@pytest.mark.timeout(240)
def test_make_lab_starts_jupyterlab_and_prints_its_url(tmp_path):
    """``make lab`` as the current user (root on CI), with no browser to open."""
    if not (ROOT / ".venv" / "bin" / "python").exists():
        pytest.fail("this checkout has no .venv: run make test, which creates it")
    port = free_port()
    env = make_environment(remove=["DISPLAY", "WAYLAND_DISPLAY", "BROWSER"])
    for name in ("JUPYTER_CONFIG_DIR", "JUPYTER_RUNTIME_DIR", "JUPYTER_DATA_DIR", "IPYTHONDIR",
                 "JUPYTERLAB_WORKSPACES_DIR", "JUPYTERLAB_SETTINGS_DIR"):
        env[name] = str(tmp_path / name.lower())
    options = f"--ServerApp.ip=127.0.0.1 --ServerApp.port={port} --ServerApp.port_retries=0"
    log = tmp_path / "lab.log"
    printed = re.compile(rf"^\s*(http://127\.0\.0\.1:{port}/lab\?token=([0-9a-f]{{32,}}))\s*$",
                         re.MULTILINE)
    with log.open("w") as output:
        # -o: the .venv stamp counts as up to date (never reinstall from a test).
        server = subprocess.Popen(
            [MAKE, "--no-print-directory", "-o", ".venv/.installed", "lab",
             f"LAB_ARGS={options}"],
            cwd=ROOT, env=env, stdout=output, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        deadline = time.monotonic() + 180
        found = None
        while found is None and time.monotonic() < deadline and server.poll() is None:
            time.sleep(0.5)
            found = printed.search(log.read_text())
        assert found, f"make lab printed no URL (exit {server.poll()}):\n{log.read_text()}"
        url, token = found.groups()
        # The server answers with the printed token, and refuses without it.
        assert answers(f"http://127.0.0.1:{port}/api/status?token={token}"), log.read_text()
        assert answers(url), log.read_text()
        assert not answers(f"http://127.0.0.1:{port}/api/status")
    finally:
        os.killpg(server.pid, signal.SIGTERM)
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
            server.wait(timeout=30)
    text = log.read_text()
    lines = text.splitlines()
    assert any(line.startswith("make lab: no browser to open here") for line in lines), text
    root_line = "make lab: running as root, so JupyterLab is started with --allow-root"
    assert (root_line in lines) == IS_ROOT, text
    assert "Running as root is not recommended" not in text
