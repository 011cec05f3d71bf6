"""One cache for the checks' costly recomputations, seen by the task-cell record.

``functools.cache`` wraps a function in C: a call that finds its value cached runs no
Python code, so the record of a task cell (:mod:`~lqe_helpers.student_code.task_runs`, a
profile hook) would not see a student's cell take a check's cached answer. The wrapper of
:func:`remembered` is a Python function that bears the wrapped function's file and name,
so every call, cached or not, is recorded as that function of the pack.
"""

from __future__ import annotations

import functools
import types
from collections.abc import Callable
from typing import TypeVar

Result = TypeVar("Result")


def remembered(function: Callable[..., Result]) -> Callable[..., Result]:
    """``function`` computing each value once per set of (hashable) arguments, like
    ``functools.cache``; ``.cache_clear()`` forgets them."""
    values: dict[tuple, Result] = {}

    def remembered_call(*args: object, **kwargs: object) -> Result:
        key = (args, tuple(sorted(kwargs.items())))
        if key not in values:
            values[key] = function(*args, **kwargs)
        return values[key]

    code = remembered_call.__code__.replace(co_name=function.__name__,
                                           co_qualname=function.__qualname__,
                                           co_filename=function.__code__.co_filename)
    named = types.FunctionType(code, function.__globals__, function.__name__,
                               remembered_call.__defaults__, remembered_call.__closure__)
    functools.update_wrapper(named, function)
    named.cache_clear = values.clear  # type: ignore[attr-defined]
    return named
