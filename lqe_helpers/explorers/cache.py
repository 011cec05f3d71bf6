"""What an explorer keeps between slider moves: the one caching pattern of the explorers.

A slider move redraws the whole view, but often only part of the computation depends
on the slider that moved: the fusion explorer's vision-only run ignores σ_p, the delay
explorer's filter run ignores the delay, the bias explorer's filter run ignores b. An
explorer wraps such a computation in :class:`LastResults`, keyed by the slider values
it does depend on, and asks it again on every move; the computation runs only when
those values changed.

One pattern for every explorer, with three promises:

* kept per explorer (the instance lives in the explorer's drawing function), so it
  lives and dies with the explorer and two explorers never share a result;
* a few entries only (one by default: the values of the last move), so memory stays
  small; a slider moved back to an earlier value pays for the computation again;
* a kept result is made read-only (every NumPy array in it), so no caller can change
  what a later move gets back.
"""

from __future__ import annotations

import dataclasses
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

import numpy as np

from .. import validation

Result = TypeVar("Result")


class LastResults(Generic[Result]):
    """``compute(*key)`` for the last ``size`` distinct keys, computed once each.

    Parameters
    ----------
    compute : callable
        ``compute(*key)``: the computation, e.g. a filter run at the slider values it
        depends on (``functools.partial`` binds the rest: scenario, noise).
    size : int
        How many distinct keys to keep, a whole number >= 1; the least recently asked
        for is dropped first.

    Attributes
    ----------
    computed : int
        How many times ``compute`` ran (for tests and benchmarks).
    """

    def __init__(self, compute: Callable[..., Result], size: int = 1) -> None:
        self.compute = compute
        self.size = validation.count("size", size, minimum=1)
        self.computed = 0
        self._kept: OrderedDict[tuple, Result] = OrderedDict()

    def __call__(self, *key: Hashable) -> Result:
        """The result of ``compute(*key)``: kept from an earlier call, or computed now.

        Keys are compared with ``==`` (slider values are floats); the result is
        read-only (:func:`read_only`).
        """
        if key in self._kept:
            self._kept.move_to_end(key)
            return self._kept[key]
        result = read_only(self.compute(*key))
        self.computed += 1
        self._kept[key] = result
        if len(self._kept) > self.size:
            self._kept.popitem(last=False)
        return result


def read_only(result: Result) -> Result:
    """``result`` with every NumPy array in it made read-only; returns ``result`` itself.

    Arrays are found in (nested) dataclasses, tuples, lists and dict values.
    """
    if isinstance(result, np.ndarray):
        result.flags.writeable = False
    elif dataclasses.is_dataclass(result) and not isinstance(result, type):
        for field in dataclasses.fields(result):
            read_only(getattr(result, field.name))
    elif isinstance(result, (tuple, list)):
        for item in result:
            read_only(item)
    elif isinstance(result, dict):
        for item in result.values():
            read_only(item)
    return result
