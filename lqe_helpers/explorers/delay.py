"""Explorer of notebook 05: a sensory delay and its compensation by prediction.

One slider sets the visual delay d. The figure shows, on the wall-clock time axis,
what the observer has at each moment: the delayed noisy readings ``y_{j−δ}``, the
filter's newest (delayed) estimate ``ẑ_{j−δ}`` and the compensated prediction
``z*_j = A^δ ẑ_{j−δ}`` (Tutorial eqs. (7)–(8)), next to the true path, with the
errors of both estimates in a panel below. The numbers of the view (d, δ and this
run's MSEs) are not drawn in the figure: the drawing function returns them as one
line of text, which the explorer shows between the slider and the picture.

The filter and the compensation may be the student's own (``my_filter`` of notebook
01, ``compensate`` of notebook 05's Task 1): they are then called through
:func:`lqe_helpers.student_code.call` (copies of the inputs, a time limit), the numbers
line says whose code ran, and a function that fails raises
:class:`~lqe_helpers.student_code.StudentCodeError`, which the explorer shows as one
line.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from functools import partial

import numpy as np
from matplotlib.figure import Figure

from .. import experiments, student_code
from ..figures.delay import DELAY_LINES, DelayPanels, delay_panels
from ..scenario import DEFAULT, Scenario
from .base import Explorer, with_explorer_seed
from .cache import LastResults
from .panels import reuse_panels
from .sliders import float_slider, starting_value
from .student_functions import RERUN, checked_function, refiltered, whose

#: Longest delay the slider offers (s): a quarter of the butterfly's period, far past
#: the point where prediction stops paying off.
MAX_DELAY = 0.5
#: Seconds of the trial shown (s): the start, where nothing has arrived yet, and two
#: periods of steady tracking. The MSEs returned cover the whole trial after burn-in.
WINDOW = 4.0

#: The question's sensor: vision alone.
SENSORS = ("vision",)

#: Smallest y half-range (in units of the flight's amplitude) of each axes.
_FLOORS = (1.5, 0.8)


def draw_delay(figure: Figure, *, delay: float, scenario: Scenario = DEFAULT,
               noise: np.ndarray | None = None, filter: Callable | None = None,
               compensate: Callable | None = None) -> str:
    """Draw one run of the delayed, compensated vision-only filter on ``figure``.

    The top axes show the true position, the delayed visual readings, the delayed
    estimate and the compensated prediction over the first :data:`WINDOW` s; a grey
    band covers the first d seconds, when nothing has arrived yet. The bottom axes
    show both estimates' errors (estimate − truth). Returns the delay and this run's
    MSEs (cm², over the whole trial after the burn-in or the delay, whichever is
    longer) with and without compensation, and of the same filter with no delay, as
    one line of text that says whose code ran (the explorer shows it beside the
    figure), each MSE to :data:`SIGNIFICANT` significant figures, e.g. "Delay d = 0.10 s
    (δ = 10 steps). MSE of this run (the pack's engine): delayed 4.99 cm², compensated
    1.92 cm², no delay 0.304 cm²."

    A figure already drawn by this function for the same scenario keeps its axes and
    only has its data replaced (redrawing axes from scratch costs more than the
    100 ms a slider may take); any other figure is cleared first.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to draw on.
    delay : float
        Visual delay d in s, a whole number of time steps, ``0 <= d < duration``.
    scenario : Scenario
        Constants of the simulation (σ_v, Δt, the butterfly).
    noise : array_like, shape (n, 1), optional
        Unit noise of vision; default the scenario's fixed draw.
    filter : callable, optional
        A student's ``my_filter(y, A, C, Q, R, z0, P0)`` returning the estimates (n, 3)
        (notebook 01), run in place of the pack's engine; default the engine.
    compensate : callable, optional
        A student's ``compensate(estimates, A, delay_steps)`` returning z* (n, 3)
        (notebook 05, Task 1), run in place of the pack's eq. (7); default the pack's.

    Returns
    -------
    str
        d (s), δ (steps), whose code ran and the three MSEs (cm²).

    Raises
    ------
    ValueError
        If ``delay`` is negative, not a multiple of Δt, or not shorter than the trial,
        or ``filter`` or ``compensate`` is neither None nor a function.
    StudentCodeError
        If the student's function fails, does not return in time, or returns something
        that is not the array asked for.
    """
    scenario.delay_steps(delay)  # validate before any work
    _check_functions(filter, compensate)
    if noise is None:
        noise = scenario.unit_noise(sensors=SENSORS)
    return _draw_tracking(figure, delay, _filter_run(scenario, noise, filter), compensate,
                          _whose(filter, compensate))


#: What the numbers line calls the pack's filter and eq. (7) beside a student's function.
PACK_FILTER, PACK_COMPENSATION = "the pack's filter", "the pack's eq. (7)"


def _whose(filter: Callable | None, compensate: Callable | None) -> str:
    """Whose code the numbers line reports: "your my_filter and your compensate", …"""
    if filter is None and compensate is None:
        return whose(None)
    return (f"{whose(filter, PACK_FILTER)} and "
            f"{whose(compensate, PACK_COMPENSATION)}")


def _check_functions(filter: object, compensate: object) -> None:
    checked_function("filter", filter)
    checked_function("compensate", compensate)


#: Names of the parameters of a student's ``compensate``, for messages.
_COMPENSATE_ARGS = ("estimates", "A", "delay_steps")


def _filter_run(scenario: Scenario, noise: np.ndarray,
                filter: Callable | None) -> experiments.Tracking:
    """The vision-only run on ``noise``: the engine's, or its readings filtered by ``filter``.

    With a student's filter the result holds the student's estimates
    (:func:`~lqe_helpers.explorers.student_functions.refiltered`, shared with the other
    explorer); its gains and covariances (which this explorer does not draw) stay the
    engine's.
    """
    return refiltered(experiments.track(scenario, SENSORS, noise=noise), filter,
                      "the explorer's trial of vision")


def _compensated(delayed: experiments.DelayedTracking,
                 compensate: Callable | None) -> experiments.DelayedTracking:
    """``delayed`` with its predictions made by ``compensate`` (if given)."""
    if compensate is None:
        return delayed
    name = student_code.function_name(compensate)
    estimates = delayed.tracking.result.estimates
    steps = delayed.steps
    output = student_code.call(compensate, estimates, delayed.tracking.scenario.A, steps,
                               name=name, where=f"the explorer's trial with δ = {steps}",
                               arg_names=_COMPENSATE_ARGS, rerun=RERUN)
    predictions = student_code.result_array(output, name=name, shape=estimates.shape,
                                            allow_nan=True,
                                            what=f"z*, shape {estimates.shape}")
    missing = ~np.all(np.isfinite(predictions[steps:]), axis=-1)
    if missing.any():
        raise student_code.StudentCodeError(
            f"{name} returned NaN in row {steps + int(np.argmax(missing))} with δ = {steps}: "
            f"eq. (7) gives a prediction in every row j >= δ")
    return dataclasses.replace(delayed, predictions=predictions)


def _draw_tracking(figure: Figure, delay: float, tracking: experiments.Tracking,
                   compensate: Callable | None, who: str) -> str:
    """:func:`draw_delay` for a filter run already made (the delay only shifts it)."""
    scenario = tracking.scenario
    delayed = _compensated(experiments.delay_and_compensate(tracking, delay), compensate)
    steps = delayed.steps
    mse_now = float(tracking.mse())
    mse_delayed = float(delayed.mse("delayed"))
    mse_predicted = float(delayed.mse("predicted"))

    truth = scenario.truth[:, 0]
    shown = scenario.times <= min(WINDOW, scenario.duration)
    panels = reuse_panels(figure, _build, scenario)
    data = {
        "vision": delayed.delayed_measurements[:, 0],
        "truth": truth,
        "delayed": delayed.delayed_estimates[:, 0],
        "prediction": delayed.predictions[:, 0],
        "delayed-error": delayed.delayed_estimates[:, 0] - truth,
        "prediction-error": delayed.predictions[:, 0] - truth,
    }
    largest = [0.0] * len(panels.axes)
    for gid, values in data.items():
        values = values[shown]
        panels.lines[gid].set_data(scenario.times[shown], values)
        if np.any(np.isfinite(values)):
            index = DELAY_LINES[gid][0]
            largest[index] = max(largest[index], float(np.nanmax(np.abs(values))))
    for ax, span, floor, extent in zip(panels.axes, panels.spans, _FLOORS, largest,
                                       strict=True):
        # Fixed limits while everything fits, so small changes stay comparable; wider
        # ones when a long extrapolation overshoots, so the overshoot stays visible.
        # Set only when they change: the explorer then repaints just the data.
        # Rounded up to half the amplitude, so the limits change only in steps.
        step = scenario.amplitude / 2
        limit = step * math.ceil(max(floor * scenario.amplitude, 1.08 * extent) / step)
        if ax.get_ylim() != (-limit, limit):
            ax.set_ylim(-limit, limit)
        # The same span every time, resized (a new one would force a full repaint).
        span.set_width(steps * scenario.dt)
        span.set_visible(steps > 0)
    unit = "step" if steps == 1 else "steps"
    return (f"Delay d = {steps * scenario.dt:.2f} s (δ = {steps} {unit}). MSE of this run "
            f"({who}): delayed {_significant(mse_delayed)} cm², compensated "
            f"{_significant(mse_predicted)} cm², no delay {_significant(mse_now)} cm².")


#: Significant figures of the MSEs in the numbers line: enough to compare the three at
#: every delay (at 0.01 s the delayed and the undelayed MSE differ by under 0.03 cm²).
SIGNIFICANT = 3


def _significant(value: float) -> str:
    """``value`` with :data:`SIGNIFICANT` significant figures, never in e-notation."""
    return np.format_float_positional(value, precision=SIGNIFICANT, unique=False,
                                      fractional=False, trim="k").rstrip(".")


def _build(figure: Figure, scenario: Scenario) -> DelayPanels:
    """The explorer's panels on the empty ``figure``, by notebook 05's painter of them."""
    return delay_panels(figure, min(WINDOW, scenario.duration))


def explore_delay(scenario: Scenario = DEFAULT, *, filter: Callable | None = None,
                  compensate: Callable | None = None) -> Explorer:
    """Slider for the visual delay d (s) over one fixed draw of vision noise.

    The slider runs from 0 to :data:`MAX_DELAY` (or the last whole step before the
    end of the trial, if that is shorter) in steps of Δt, starting at the scenario's
    delay; a value between steps is rounded to the nearest step. Vision's noise is
    drawn from the scenario's explorer seed (another draw than the tasks',
    :func:`~lqe_helpers.explorers.base.with_explorer_seed`).

    Parameters
    ----------
    scenario : Scenario
        Constants of the simulation.
    filter : callable, optional
        The student's ``my_filter`` (notebook 01), run once on the explorer's readings
        in place of the pack's engine.
    compensate : callable, optional
        The student's ``compensate`` (notebook 05, Task 1), run at every move in place
        of the pack's eq. (7).

    Raises
    ------
    ValueError
        If ``scenario.delay`` lies beyond the slider's range, or ``filter`` or
        ``compensate`` is neither None nor a function.
    """
    _check_functions(filter, compensate)
    high = math.floor(min(MAX_DELAY, (scenario.n_steps - 1) * scenario.dt) / scenario.dt
                      + 1e-9) * scenario.dt
    start = starting_value("delay", scenario.delay, 0.0, high, "s")
    noise = with_explorer_seed(scenario).unit_noise(sensors=SENSORS)
    # A delay changes only when the filter's output arrives, not the output itself:
    # filter the fixed noise once, keep it, and let the slider shift and predict it.
    run = LastResults(partial(_filter_run, scenario, noise, filter))
    decimals = max(2, math.ceil(-math.log10(scenario.dt) - 1e-9))
    slider = float_slider("delay (s)", value=start, low=0.0, high=high,
                          step=scenario.dt, readout_format=f".{decimals}f")
    return Explorer(
        "Sensory delay and its compensation: truth, delayed vision, delayed estimate and "
        "prediction",
        {"delay": slider},
        partial(_draw, run=run, compensate=compensate, who=_whose(filter, compensate)),
        figsize=(9.0, 5.2),
        describe=partial(describe_delay, scenario=scenario),
    )


def describe_delay(*, delay: float, scenario: Scenario = DEFAULT) -> str:
    """What :func:`draw_delay` shows at ``delay`` (its alt text); rounds to whole steps."""
    shown = round(delay / scenario.dt) * scenario.dt
    window = min(WINDOW, scenario.duration)
    return (f"Position against time, 0–{window:g} s, with vision delayed by d = {shown:.2f} s: "
            f"true path, delayed readings, the delayed estimate and the compensated "
            f"prediction, with both estimates' errors below.")


def _draw(figure: Figure, *, delay: float, run: Callable[[], experiments.Tracking],
          compensate: Callable | None, who: str) -> str:
    """Round the slider's float to the nearest whole step, then draw the kept run."""
    tracking = run()
    dt = tracking.scenario.dt
    return _draw_tracking(figure, round(delay / dt) * dt, tracking, compensate, who)
