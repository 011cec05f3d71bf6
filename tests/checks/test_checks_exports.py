"""Every check of every checks module is reachable as ``checks.<name>``, and is that one.

Two modules defining the same public ``check_…`` name would make one of them unreachable
(the later import wins, silently): the notebook would call another notebook's check.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from collections import defaultdict

from lqe_helpers import checks


def defined_checks() -> dict[str, list[object]]:
    found: dict[str, list[object]] = defaultdict(list)
    for info in pkgutil.iter_modules(checks.__path__):
        module = importlib.import_module(f"{checks.__name__}.{info.name}")
        for name, value in vars(module).items():
            if (name.startswith("check_") and inspect.isfunction(value)
                    and value.__module__ == module.__name__):
                found[name].append(value)
    return found


def test_no_two_modules_define_the_same_check() -> None:
    twice = {name: [f.__module__ for f in functions]
             for name, functions in defined_checks().items() if len(functions) > 1}
    assert twice == {}


def test_every_check_is_exported_as_itself() -> None:
    for name, (function, *_) in defined_checks().items():
        assert name in checks.__all__, name
        assert getattr(checks, name).__wrapped__ is function, name  # own_work.judged
