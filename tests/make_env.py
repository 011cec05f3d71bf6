"""The environment of a ``make`` (or pytest) that a test starts: nothing of how it was called.

``make test PYTEST_ARGS=--durations=60`` exports ``PYTEST_ARGS`` and passes it on to every
``make`` started below it through ``MAKEFLAGS``, so a ``make -n test`` run by a test would
print the caller's options instead of the Makefile's own command. Every test that runs
``make`` (or the pytest command of a ``make test``) takes its environment from
:func:`make_environment`, which leaves out make's own variables and every variable the
Makefile sets.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Variables through which make passes its options and command-line variables on.
MAKE_CONTROL = frozenset({"MAKEFLAGS", "MFLAGS", "MAKELEVEL", "MAKEOVERRIDES", "GNUMAKEFLAGS",
                          "MAKEFILES", "MAKE_TERMOUT", "MAKE_TERMERR"})
#: Variables through which pytest takes options from its caller.
PYTEST_CONTROL = frozenset({"PYTEST_ADDOPTS", "PYTEST_PLUGINS"})

#: A variable assignment at the start of a Makefile line (``NAME ?=``, ``override NAME :=``).
_ASSIGNMENT = re.compile(
    r"^(?:override\s+|export\s+)*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\?|:{1,3}|\+|!)?=", re.MULTILINE)


def makefile_variables(makefile: Path = ROOT / "Makefile") -> frozenset[str]:
    """Names of the variables ``makefile`` assigns (``PYTEST_ARGS ?=``, ``BIN :=``, …)."""
    return frozenset(_ASSIGNMENT.findall(makefile.read_text("utf-8")))


def make_environment(*, remove: Iterable[str] = (), **values: str) -> dict[str, str]:
    """This process's environment as a fresh shell would give it to ``make``.

    Parameters
    ----------
    remove : iterable of str
        More variables to leave out (``DISPLAY``, say).
    **values : str
        Variables to set, after the removals.

    Returns
    -------
    dict of str to str
        ``os.environ`` without :data:`MAKE_CONTROL`, :data:`PYTEST_CONTROL`, pytest-xdist's
        ``PYTEST_XDIST_*`` and every variable of the course Makefile
        (:func:`makefile_variables`), then ``values``.
    """
    dropped = MAKE_CONTROL | PYTEST_CONTROL | makefile_variables() | set(remove)
    environment = {key: value for key, value in os.environ.items()
                   if key not in dropped and not key.startswith("PYTEST_XDIST_")}
    environment.update(values)
    return environment
