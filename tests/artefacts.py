"""The costly artefacts of the test suite, each built once per test run and shared.

Session-scoped fixtures, for every test that needs one (unit and browser tests alike):

``handouts_build``
    :class:`HandoutsBuild`: the HTML handouts of ``notebooks/`` (both variants, MathJax
    copied in), built by ``build_handouts`` as ``make handouts`` builds them: every notebook
    executed once, in a fresh kernel.
``student_edition``
    :class:`StudentEdition`: the student edition of ``notebooks/``, built by
    ``build_student_edition`` as ``make student`` builds it.
``filled_edition``
    :class:`FilledEdition`: the core path of each question notebook's student edition with
    every task filled with its worked solution; :meth:`FilledEdition.run` executes one in a
    fresh kernel, at most once per run.
``student_pack``
    :class:`StudentPack`: ``lqe-student-pack.zip``, built by ``build_student_pack`` for this
    course folder, and the folder it unpacks to.

Once per run, pytest-xdist included: each worker is a session of its own, so a build is
shared through the run's base temporary folder under a file lock
(:class:`once_per_run.SharedArtefacts`). The first worker that needs an artefact builds it;
any other waits for it, then reads it. A build that failed is not tried again: every test
that needs it fails with its message. The end of the run lists every build (which, where,
how long), so a second build of anything shows.

Tests must not change an artefact. Its files are made read-only (which stops every user but
root), and at the end of each session they are checked against the digests taken when they
were built. A test that needs to change one, or to run a program in it that writes caches
(pytest, Python), works on a :func:`once_per_run.writable_copy`.

A test that requests ``handouts_build`` executes notebooks, so it is marked ``kernel`` here
(``make test-fast`` leaves it out); one that calls :meth:`FilledEdition.run` carries the
marker itself. This module is the instructor's
side of the suite (it imports the authoring tools): the student pack leaves it out, and
``tests/conftest.py`` loads it only where it exists.
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Iterator
from dataclasses import asdict, dataclass
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError
from once_per_run import Build, SharedArtefacts

from lqe_helpers.authoring import student_edition as se
from lqe_helpers.authoring import student_pack as sp
from lqe_helpers.authoring import task_cells as tc
from lqe_helpers.authoring.handouts import build_handouts

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
#: Fixtures that execute notebooks: a test that requests one is marked ``kernel``.
KERNEL_FIXTURES = frozenset({"handouts_build"})
#: Seconds one cell of a filled notebook may run.
CELL_TIMEOUT_S = 300
#: Key of this session's builds in ``config.stash`` and of a worker's in its output.
_BUILDS = pytest.StashKey[list]()
_WORKER_OUTPUT = "lqe_artefact_builds"


@dataclass(frozen=True)
class RunError:
    """What stopped a notebook run: the exception's name and value, and nbclient's message."""

    ename: str
    evalue: str
    message: str

    def __str__(self) -> str:
        return self.message


@pytest.fixture(scope="session")
def shared_artefacts(request: pytest.FixtureRequest,
                     tmp_path_factory: pytest.TempPathFactory) -> Iterator[SharedArtefacts]:
    """The run's :class:`SharedArtefacts`; at the end, fails if a test changed one."""
    workerinput = getattr(request.config, "workerinput", None)
    base = tmp_path_factory.getbasetemp()
    root = (base.parent if workerinput else base) / "shared-artefacts"
    root.mkdir(exist_ok=True)
    artefacts = SharedArtefacts(root, workerinput["workerid"] if workerinput else "main",
                                request.config.stash[_BUILDS])
    yield artefacts
    changed = artefacts.changed()
    assert not changed, ("a test changed a shared artefact (copy it with writable_copy "
                         "instead): " + "; ".join(changed[:10]))


# ------------------------------------------------------------------------ handouts


@dataclass(frozen=True)
class HandoutsBuild:
    """The handouts of ``notebooks/`` as ``make handouts`` builds them (read-only).

    Attributes
    ----------
    folder : Path
        The output folder: ``NN_name.html`` per notebook and ``index.html``; ``prose/``,
        the same pages without code; ``mathjax/``, the local MathJax; the tool's manifest.
    pages : tuple of Path
        What ``build_handouts`` returned: the pages with code in notebook order, then
        ``index.html``, then the prose pages and ``prose/index.html``.
    """

    folder: Path
    pages: tuple[Path, ...]


@pytest.fixture(scope="session")
def handouts_build(shared_artefacts: SharedArtefacts) -> HandoutsBuild:
    """The handouts of ``notebooks/``, built once per run (:class:`HandoutsBuild`)."""
    def build(folder: Path) -> list[str]:
        return [path.relative_to(folder).as_posix() for path in build_handouts(NOTEBOOKS, folder)]

    folder, pages = shared_artefacts.get("handouts", build)
    return HandoutsBuild(folder, tuple(folder / page for page in pages))


# ------------------------------------------------------------------ student edition


@dataclass(frozen=True)
class StudentEdition:
    """The student edition of ``notebooks/`` as ``make student`` builds it (read-only).

    Attributes
    ----------
    folder : Path
        ``NN_name.ipynb`` for every notebook of ``notebooks/`` (same names) and the
        tool's manifest.
    notebooks : tuple of Path
        The student notebooks, in name order.
    """

    folder: Path
    notebooks: tuple[Path, ...]


@pytest.fixture(scope="session")
def student_edition(shared_artefacts: SharedArtefacts) -> StudentEdition:
    """The student edition of ``notebooks/``, built once per run (:class:`StudentEdition`)."""
    def build(folder: Path) -> list[str]:
        return [path.name for path in se.build_student_edition(NOTEBOOKS, folder)]

    folder, names = shared_artefacts.get("student-edition", build)
    return StudentEdition(folder, tuple(folder / name for name in names))


def core_end(notebook: nbformat.NotebookNode) -> int:
    """Index of the ``## Going further`` heading cell (the end of the core path)."""
    return next((index for index, cell in enumerate(notebook.cells)
                 if cell.cell_type == "markdown"
                 and cell.source.lstrip().startswith(tc.GOING_FURTHER)), len(notebook.cells))


def filled_core(source: nbformat.NotebookNode,
                student: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """The core path of ``student`` with every task filled with ``source``'s worked solution.

    Parameters
    ----------
    source : NotebookNode
        A worked notebook.
    student : NotebookNode
        Its student edition (not changed). Task i gets the code of solution cell i of
        ``source`` (the edition keeps the cells in order).

    Returns
    -------
    NotebookNode
        A copy of ``student``, filled, without ``## Going further`` and what follows.
    """
    filled = nbformat.from_dict(json.loads(json.dumps(student)))
    solutions = [cell for cell in source.cells
                 if tc.SOLUTION_TAG in cell.get("metadata", {}).get("tags", [])]
    stubs = [cell for cell in filled.cells
             if tc.TASK_TAG in cell.get("metadata", {}).get("tags", [])]
    assert len(stubs) == len(solutions), f"{len(stubs)} tasks for {len(solutions)} solutions"
    for stub, solution in zip(stubs, solutions, strict=True):
        assert stub.source.splitlines()[0] == solution.source.splitlines()[0]
        stub.source = solution.source
    filled.cells = filled.cells[:core_end(filled)]
    return filled


def run_notebook(notebook: nbformat.NotebookNode, cwd: Path) -> RunError | None:
    """Execute ``notebook`` in place in a fresh kernel, in ``cwd``; what stopped it, if anything."""
    client = NotebookClient(notebook, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                            resources={"metadata": {"path": str(cwd)}})
    try:
        client.execute()
    except CellExecutionError as error:
        return RunError(error.ename, error.evalue, str(error))
    return None


@dataclass(frozen=True)
class FilledRun:
    """A filled notebook after its run in a fresh kernel.

    Attributes
    ----------
    notebook : NotebookNode
        The notebook with the outputs of the run (up to the cell that stopped it); each
        :meth:`FilledEdition.run` call reads a new copy.
    error : RunError or None
        What stopped the run, or None if every cell ran.
    """

    notebook: nbformat.NotebookNode
    error: RunError | None


class FilledEdition:
    """The filled core path of each question notebook (read-only).

    Attributes
    ----------
    folder : Path
        ``NN_name.ipynb`` per question notebook (names starting with
        ``student_pack.CHECKED_PREFIXES``): :func:`filled_core` of its student edition,
        not executed.
    names : tuple of str
        Their file names, in order.
    """

    def __init__(self, folder: Path, names: tuple[str, ...],
                 artefacts: SharedArtefacts) -> None:
        self.folder = folder
        self.names = names
        self._artefacts = artefacts

    def run(self, name: str) -> FilledRun:
        """``name`` executed in a fresh kernel in ``notebooks/``; once per test run."""
        if name not in self.names:
            raise ValueError(f"name must be one of {list(self.names)}, got {name!r}")

        def execute(folder: Path) -> dict[str, str] | None:
            notebook = nbformat.read(self.folder / name, as_version=4)
            error = run_notebook(notebook, NOTEBOOKS)
            folder.mkdir()
            nbformat.write(notebook, folder / name)
            return None if error is None else asdict(error)

        folder, error = self._artefacts.get(f"filled-run-{Path(name).stem}", execute)
        return FilledRun(nbformat.read(folder / name, as_version=4),
                         None if error is None else RunError(**error))


@pytest.fixture(scope="session")
def filled_edition(shared_artefacts: SharedArtefacts,
                   student_edition: StudentEdition) -> FilledEdition:
    """The filled core of each question notebook, built once per run (:class:`FilledEdition`)."""
    def build(folder: Path) -> list[str]:
        folder.mkdir()
        names = []
        for student in student_edition.notebooks:
            if student.name.startswith(sp.CHECKED_PREFIXES):
                source = nbformat.read(NOTEBOOKS / student.name, as_version=4)
                nbformat.write(filled_core(source, nbformat.read(student, as_version=4)),
                               folder / student.name)
                names.append(student.name)
        return names

    folder, names = shared_artefacts.get("filled-edition", build)
    return FilledEdition(folder, tuple(names), shared_artefacts)


# --------------------------------------------------------------------- student pack


@dataclass(frozen=True)
class StudentPack:
    """The student pack of this course folder (read-only).

    Attributes
    ----------
    archive : Path
        ``lqe-student-pack.zip`` as ``build_student_pack`` wrote it.
    folder : Path
        The ``lqe-student-pack/`` folder it unpacks to. Copy it (``once_per_run.writable_copy``)
        before running anything in it that writes (pytest, Python's caches).
    """

    archive: Path
    folder: Path


@pytest.fixture(scope="session")
def student_pack(shared_artefacts: SharedArtefacts) -> StudentPack:
    """The student pack, built and unpacked once per run (:class:`StudentPack`)."""
    def build(folder: Path) -> dict[str, str]:
        archive = sp.build_student_pack(ROOT, folder / "out")
        with zipfile.ZipFile(archive) as opened:
            opened.extractall(folder / "unpacked")
        return {"archive": archive.relative_to(folder).as_posix(),
                "folder": f"unpacked/{sp.PACK_NAME}"}

    folder, paths = shared_artefacts.get("student-pack", build)
    return StudentPack(folder / paths["archive"], folder / paths["folder"])


# -------------------------------------------------------------------------- hooks


def pytest_configure(config: pytest.Config) -> None:
    config.stash[_BUILDS] = []


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark ``kernel`` every test that requests a fixture of :data:`KERNEL_FIXTURES`."""
    for item in items:
        if KERNEL_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.kernel)


def pytest_sessionfinish(session: pytest.Session) -> None:
    """In a pytest-xdist worker: hand this session's builds to the controller."""
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:
        workeroutput[_WORKER_OUTPUT] = [asdict(build)
                                        for build in session.config.stash[_BUILDS]]


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error) -> None:
    """In the pytest-xdist controller: collect a finished worker's builds."""
    builds = getattr(node, "workeroutput", {}).get(_WORKER_OUTPUT, [])
    node.config.stash[_BUILDS].extend(Build(**build) for build in builds)


def pytest_terminal_summary(terminalreporter, config: pytest.Config) -> None:
    """List the shared artefacts built in this run; say so if one was built twice."""
    if getattr(config, "workerinput", None) is not None or not config.stash[_BUILDS]:
        return
    builds = sorted(config.stash[_BUILDS], key=lambda build: build.artefact)
    counts: dict[str, int] = {}
    for build in builds:
        counts[build.artefact] = counts.get(build.artefact, 0) + 1
    terminalreporter.write_sep("-", "shared artefacts built (tests/artefacts.py)")
    for build in builds:
        terminalreporter.write_line(f"{build.artefact}: {build.seconds:.1f} s in {build.worker}")
    twice = sorted(name for name, count in counts.items() if count > 1)
    if twice:
        terminalreporter.write_line(f"built more than once: {', '.join(twice)}", red=True)
