"""Shared test configuration: Hypothesis profiles, the ``kernel`` marker, worker groups.

- Hypothesis: CI (``CI`` set) draws the same examples every run.
- ``kernel`` (registered in pyproject.toml) marks a test that starts a Jupyter kernel or
  executes a notebook; ``make test-fast`` leaves those out. nbval's notebook cells are
  marked here, and a test that starts a kernel in this process without the marker fails,
  naming the marker, so the fast lane stays fast.
- pytest-xdist: ``make test`` runs ``--dist loadfile``, so the tests of one file (the cells
  of one notebook, on its one kernel, in order) run in one worker and share its session
  fixtures; :data:`WORKER_GROUPS` puts files that share a costly resource in one worker
  too.
- The costly artefacts that tests share (the handouts, the student edition and pack) are
  the fixtures of ``tests/artefacts.py``, loaded below where it exists: the student pack
  leaves out that instructor's side of the suite (and this file names none of them, so
  that a test that names one can be told from the student's tests).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

pytest_plugins = ["artefacts"] if (Path(__file__).parent / "artefacts.py").is_file() else []

# CI must be reproducible: the same examples every run. Local runs keep exploring new
# examples (and remember failures in .hypothesis/).
settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("thorough", max_examples=2000)
_default_profile = "ci" if os.environ.get("CI") else "default"
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", _default_profile))

#: Kernels started by the test now running although it is not marked ``kernel``.
_UNMARKED_KERNELS = pytest.StashKey[int]()
_running: pytest.Item | None = None


def _watch_kernel_starts() -> None:
    """Count, on the running test, each kernel it starts in this process without the marker."""
    try:
        from jupyter_client.provisioning.local_provisioner import LocalProvisioner
    except ImportError:  # no jupyter_client: nothing here can start a kernel
        return
    launch = LocalProvisioner.launch_kernel
    if getattr(launch, "lqe_watched", False):
        return

    async def launch_kernel(self, cmd, **kwargs):
        item = _running
        if item is not None and item.get_closest_marker("kernel") is None:
            item.stash[_UNMARKED_KERNELS] = item.stash.get(_UNMARKED_KERNELS, 0) + 1
        return await launch(self, cmd, **kwargs)

    launch_kernel.lqe_watched = True
    LocalProvisioner.launch_kernel = launch_kernel


def pytest_configure(config: pytest.Config) -> None:
    _watch_kernel_starts()


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """nbval's notebook cells are marked ``kernel``; the work units of :data:`FIRST` run
    first, in its order (see there)."""
    for item in items:
        if item.path.suffix == ".ipynb":
            item.add_marker(pytest.mark.kernel)
    items.sort(key=lambda item: FIRST.get(work_unit(item.nodeid), len(FIRST)))


#: The work units (:func:`work_unit`) that start a run, in this order; the rest follow in
#: file order. The longest start at once, one on each worker: the handout pages (the
#: handouts built, then every page read in Chromium, in one worker: none waits for the
#: build), the grading pipeline, then the JupyterLab group.
FIRST = {"handout pages": 0, "tests/grading/test_grading_pipeline.py": 1, "jupyterlab": 2}


#: Test files (relative to the top folder) that share a costly resource of their pytest
#: session, so pytest-xdist runs each group in one worker: the handouts' build and one
#: Chromium for every handout page; one JupyterLab server.
WORKER_GROUPS = {
    "tests/authoring/test_handouts.py": "handout pages",  # builds them (tests/artefacts.py)
    "tests/browser/test_handouts_a11y.py": "handout pages",
    "tests/browser/test_handouts_offline.py": "handout pages",
    "tests/browser/test_harness.py": "jupyterlab",
    "tests/browser/test_notebooks_in_jupyterlab.py": "jupyterlab",
}


def work_unit(nodeid: str) -> str:
    """What pytest-xdist hands one worker with the test ``nodeid``: its file, or its group."""
    path = nodeid.split("::", 1)[0]
    return WORKER_GROUPS.get(path, path)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log):
    """``--dist loadfile`` with the files of a :data:`WORKER_GROUPS` group in one worker.

    Not ``--dist loadgroup`` with ``xdist_group`` marks: on pytest 9.2 pytest-xdist 3.8
    no longer groups by them, silently (pytest-xdist issue 1386).
    """
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class GroupedFileScheduling(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return work_unit(nodeid)

    return GroupedFileScheduling(config, log)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None):
    global _running
    _running = item
    try:
        return (yield)
    finally:
        _running = None


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]):
    """Fail the phase in which an unmarked test started a kernel."""
    report = yield
    started = item.stash.get(_UNMARKED_KERNELS, 0)
    if started:
        item.stash[_UNMARKED_KERNELS] = 0
        message = (f"{item.nodeid} started {started} Jupyter kernel(s) but is not marked "
                   "@pytest.mark.kernel: mark it, so that make test-fast leaves it out")
        if report.passed:
            report.outcome = "failed"
            report.longrepr = message
        else:
            report.sections.append(("kernel marker", message))
    return report


@pytest.fixture(autouse=True)
def _fresh_save_folder(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each test is a new session for ``student_code.save``/``load``: their default folder
    is fixed at a test's first use, in the folder it works in (see ``keeping.save_folder``)."""
    from lqe_helpers.student_code import keeping

    monkeypatch.setattr(keeping, "_home", None, raising=False)
