"""A student's own functions inside an explorer: checked once, run safely, named.

An explorer that runs a filter can run the student's instead of the pack's engine
(``explore_vision(filter=my_filter)``): its sliders then redraw with the student's code.
This module is the one place that does it for every explorer:

- :func:`checked_function`: the argument is None (the pack's engine) or a function;
- :func:`refiltered`: a tracking run whose estimates the student's filter made from the
  same readings and model, called through :func:`lqe_helpers.student_code.call` (copies of
  the inputs, a time limit, one line per failure, which the explorer shows in its
  numbers line);
- :func:`whose`: what the numbers line says made the estimates.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from .. import experiments, student_code
from ..filter import FILTER_ARGS

#: What the numbers line says made the estimates when no student's filter is given.
ENGINE = "the pack's engine"
#: The last step of the "not written yet" advice in an explorer: the explorer keeps the
#: function it was given, so a function written since needs the Explore cell run again.
RERUN = "run its check, then run the Explore cell again"

#: A student's filter ``my_filter(y, A, C, Q, R, z0, P0) -> estimates (n, k)``.
StudentFilter = Callable[..., object]


def checked_function(name: str, function: object) -> Callable[..., object] | None:
    """``function`` if it is None (the pack's own) or callable; else a ``ValueError``.

    ``name`` is the explorer's parameter ("filter", "compensate").
    """
    if function is not None and not callable(function):
        raise ValueError(f"{name} must be None (the pack's own) or a function, e.g. your "
                         f"my_filter without parentheses, got a {type(function).__name__}")
    return function


def whose(function: Callable[..., object] | None, engine: str = ENGINE) -> str:
    """Who made the estimates: "your my_filter", or ``engine`` for None."""
    return engine if function is None else student_code.function_name(function, yours=True)


def refiltered(tracking: experiments.Tracking, filter: StudentFilter | None,
               where: str) -> experiments.Tracking:
    """``tracking`` with its estimates made by ``filter`` from the same readings and model.

    ``filter(y, A, C, Q, R, z0, P0)`` gets the run's readings (n, m) and the model the
    engine assumed (:attr:`~lqe_helpers.experiments.Tracking.model`) and must return the
    estimates, shape (n, k). The gains and covariances stay the engine's: they do not
    depend on the readings. None returns ``tracking`` itself.

    Parameters
    ----------
    tracking : Tracking
        One run (no Monte Carlo axis): a student's loop filters one trial.
    filter : callable or None
        The student's filter.
    where : str
        What the run is, for messages ("the explorer's trial at σ_v = 1.5 cm").

    Raises
    ------
    lqe_helpers.student_code.StudentCodeError
        One line, if the filter is not written (or saved) yet, raises, runs too long or
        returns anything but a real array of the estimates' shape.
    """
    if filter is None:
        return tracking
    model = tracking.model
    name = student_code.function_name(filter)
    shape = tracking.result.estimates.shape
    output = student_code.call(
        filter, tracking.measurements, model.A, model.C, model.Q, model.R, model.z0, model.P0,
        name=name, where=where, arg_names=FILTER_ARGS, rerun=RERUN)
    estimates = student_code.result_array(
        output, name=name, shape=shape, where=where,
        what=f"the estimates ẑ, an array of shape (n, k) = {shape}")
    return dataclasses.replace(
        tracking, result=dataclasses.replace(tracking.result, estimates=estimates))
