"""The engine's Monte Carlo runs that the checks of several tasks compare with, made once.

Checks of notebooks 00, 03, 05 and 06 (core and Going further) judge a student's
numbers against the vision-only filter's ``DEFAULT.mc_runs`` runs of the scenario's
draws. :func:`vision_runs` makes those runs once per kernel, read-only, and every such
check reads them there instead of keeping a copy of its own.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .. import experiments
from ..scenario import DEFAULT
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback


@remembered
def vision_runs() -> experiments.Tracking:
    """``experiments.track(DEFAULT, runs=DEFAULT.mc_runs)``, with every array read-only.

    The vision-only filter (σ_v = ``DEFAULT.sigma_v``, the scenario's model) on the
    scenario's ``DEFAULT.mc_runs`` draws: readings (runs, n, 1) in cm and the filter's
    result (estimates (runs, n, 3), gains, covariances). The notebooks' Task 3 runs
    (``experiments.track(DEFAULT, runs=DEFAULT.mc_runs)``) are these, run by run.
    """
    tracking = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    tracking.measurements.setflags(write=False)
    for field in dataclasses.fields(tracking.result):
        value = getattr(tracking.result, field.name)
        if isinstance(value, np.ndarray):
            value.setflags(write=False)
    return tracking
