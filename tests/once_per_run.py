"""Build a test artefact once per test run, shared by every session of the run.

Under pytest-xdist every worker is a pytest session of its own, and a session-scoped
fixture is set up once in each. :class:`SharedArtefacts` shares a build between them
through a folder that every worker of the run sees (the controller's base temporary
folder), under a file lock, as the pytest-xdist documentation does it: the first session
that needs an artefact builds it; any other waits, then reads it. A build that failed is
not tried again. Artefacts are made read-only (every user but root is stopped) and can be
checked unchanged later; :func:`writable_copy` gives a test its own copy to change.
tests/artefacts.py uses this for the suite's costly builds.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import stat
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from filelock import FileLock


@dataclass(frozen=True)
class Build:
    """One build of a shared artefact: which, by which session, and how long it took (s)."""

    artefact: str
    worker: str
    seconds: float


def _digests(folder: Path) -> dict[str, str]:
    """SHA-256 of every file under ``folder``, by path relative to it."""
    return {path.relative_to(folder).as_posix(): hashlib.sha256(path.read_bytes()).hexdigest()
            for path in sorted(folder.rglob("*")) if path.is_file()}


def _make_read_only(folder: Path) -> None:
    """Take the write bits off every file and folder under ``folder`` (and ``folder``)."""
    for path in [*folder.rglob("*"), folder]:
        if not path.is_symlink():
            path.chmod(stat.S_IMODE(path.stat().st_mode) & ~0o222)


def writable_copy(source: Path, target: Path) -> Path:
    """Copy the folder ``source`` (an artefact, read-only) to ``target``, writable; return it."""
    shutil.copytree(source, target, copy_function=shutil.copyfile)
    for path in [target, *target.rglob("*")]:
        if path.is_dir() and not path.is_symlink():
            path.chmod(stat.S_IMODE(path.stat().st_mode) | stat.S_IWUSR)
    return target


def _write_json(path: Path, data: object) -> None:
    """Write ``data`` to ``path`` as JSON, atomically (a reader sees all of it or nothing)."""
    temporary = path.with_name(f".{path.name}.tmp")
    temporary.write_text(json.dumps(data), encoding="utf-8")
    os.replace(temporary, path)


class SharedArtefacts:
    """The artefacts of one test run, shared by its sessions (pytest-xdist workers).

    Parameters
    ----------
    root : Path
        Folder of the run's artefacts (the same for every worker of the run).
    worker : str
        This session's name ("gw0", or "main" without pytest-xdist).
    builds : list of Build
        Where the builds this session makes are recorded.
    """

    def __init__(self, root: Path, worker: str, builds: list[Build]) -> None:
        self.root = root
        self.worker = worker
        self._builds = builds
        self._used: dict[str, dict[str, str]] = {}

    def get(self, name: str, build: Callable[[Path], object]) -> tuple[Path, object]:
        """The folder of artefact ``name`` and the data its build returned; built once a run.

        Parameters
        ----------
        name : str
            The artefact's name (a file name).
        build : callable
            ``build(folder)`` writes the artefact into ``folder`` (which does not exist
            yet) and returns data that JSON can hold. Called only if no session of this
            run has built ``name`` yet.

        Returns
        -------
        (Path, object)
            The artefact's folder (read-only) and what ``build`` returned.
        """
        folder = self.root / name
        record = self.root / f"{name}.json"
        with FileLock(self.root / f"{name}.lock"):
            if not record.exists():
                start = time.perf_counter()
                try:
                    data = build(folder)
                except Exception as error:
                    _write_json(record, {"worker": self.worker,
                                         "error": f"{type(error).__name__}: {error}"})
                    raise
                seconds = time.perf_counter() - start
                self._builds.append(Build(name, self.worker, seconds))
                if folder.exists():
                    _make_read_only(folder)
                digests = _digests(folder) if folder.exists() else {}
                _write_json(record, {"worker": self.worker, "data": data, "digests": digests})
        saved = json.loads(record.read_text(encoding="utf-8"))
        if "error" in saved:
            pytest.fail(f"the shared build of {name!r} failed (in session {saved['worker']}); "
                        f"every test that needs it fails: {saved['error']}", pytrace=False)
        self._used[name] = saved["digests"]
        return folder, saved["data"]

    def changed(self) -> list[str]:
        """Files of the artefacts this session used that differ from what was built."""
        problems = []
        for name, built in self._used.items():
            now = _digests(self.root / name)
            problems += [f"{name}/{path}: {'changed' if path in now else 'deleted'}"
                         for path in built if now.get(path) != built[path]]
            problems += [f"{name}/{path}: added" for path in now if path not in built]
        return problems
