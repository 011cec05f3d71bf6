"""Explorer of notebook 00: the jerk noise σ_j behind Q, open loop and in tracking.

Left panel: how fast the position uncertainty grows once the measurements stop
(Lesson 0.5 eq. (9) with no correction). Right panel: one tracking run at the same
σ_j, to see the trade-off between lag (σ_j too small) and noise (σ_j too large).
The numbers of the view (whose filter runs: the pack's; σ_j, when the uncertainty
reaches the flight's amplitude, this run's MSE and the variance the filter expects)
are returned as one line of text that the explorer shows between the slider and the
figure.

Speed: building the axes, ticks and legends costs more than the filter run, so
:func:`draw_background` builds the panels once per figure and afterwards only
replaces the data of the same artists; the panels' titles never change, and the
numbers stay out of the figure, where text would be rendered again on every move.
"""

from __future__ import annotations

import dataclasses
from functools import partial

import numpy as np
from matplotlib.figure import Figure

from .. import experiments, validation
from ..figures.background import (  # noqa: F401  (the labels: tests and readers find them here)
    AMPLITUDE_LABEL,
    ESTIMATE_LABEL,
    GROWTH_LABEL,
    GROWTH_TITLE,
    REFERENCE_LABEL,
    TRACKING_TITLE,
    TRUTH_LABEL,
    VISION_LABEL,
    BackgroundPanels,
    background_panels,
)
from ..prediction import OpenLoop, amplitude_crossing, open_loop
from ..scenario import DEFAULT, Scenario
from .base import Explorer, with_explorer_seed
from .panels import reuse_panels
from .sliders import log_slider

#: Seconds of open-loop prediction drawn in the left panel.
OPEN_LOOP_DURATION = 1.0
#: Time window (s) of the tracking panel: two periods of the flight after the burn-in.
TRACKING_WINDOW = (1.0, 5.0)
#: Slider range of σ_j (cm/s³): two decades either side of the matched ≈ 1 400 cm/s³.
JERK_STD_RANGE = (10.0, 1.0e5)
#: Where the slider starts (cm/s³): a value on its grid near, but not at, the scenario's
#: σ_j. At the scenario's σ_j the numbers line would give the time at which 2σ reaches
#: the amplitude, the answer of a task in notebook 00 (issue 15); the scenario's σ_j
#: stays in the left panel as the reference curve.
START_JERK_STD = 1000.0

#: How the numbers line starts: whose filter runs (the student writes theirs in notebook 01).
WHOSE_FILTER = "The pack's vision-only filter (yours comes in notebook 01),"

def steady_estimate_covariance(scenario: Scenario) -> np.ndarray:
    """Covariance (3, 3) of the vision-only filter's estimate once it has settled.

    What the observer knows about the butterfly after watching it for a while: the
    starting point of an open-loop prediction in :func:`draw_background`.
    """
    return experiments.filter_model(scenario).steady_state().estimate_covariance


def format_jerk(jerk_std: float) -> str:
    """σ_j as text: whole numbers from 100 cm/s³ up ("1,396"), 3 digits below ("31.6")."""
    return f"{jerk_std:,.0f}" if jerk_std >= 100 else f"{jerk_std:.3g}"


def _crossing_text(loop: OpenLoop, amplitude: float) -> str:
    """When 2σ of ``loop``'s position first reaches ``amplitude`` (cm), as text."""
    crossing = amplitude_crossing(loop, amplitude)
    if crossing is None:
        return f"after more than {loop.times[-1]:g} s"
    return f"after {crossing:.2f} s"


def _build(figure: Figure, scenario: Scenario) -> BackgroundPanels:
    """The explorer's panels on the empty ``figure``, by notebook 00's painter of them."""
    reference = open_loop(scenario, np.zeros(3), steady_estimate_covariance(scenario),
                          OPEN_LOOP_DURATION)
    return background_panels(figure, reference.times, 2 * reference.position_stds,
                             scenario.times, scenario.truth[:, 0], amplitude=scenario.amplitude,
                             growth_duration=OPEN_LOOP_DURATION, window=TRACKING_WINDOW)


def draw_background(figure: Figure, *, jerk_std: float, scenario: Scenario = DEFAULT,
                    noise: np.ndarray | None = None) -> str:
    """Draw open-loop growth and tracking for the jerk noise ``jerk_std`` (cm/s³).

    Left: twice the standard deviation of the predicted position when the
    measurements stop after the filter has settled (Lesson 0.5 eq. (9)), at
    ``jerk_std`` and at the scenario's own σ_j, against the flight's amplitude.
    Right: one vision-only tracking run with Q built from ``jerk_std``.

    A figure not drawn by this function is cleared first; on one it drew before,
    for the same scenario, the same artists receive the new data (rebuilding the
    axes would take longer than the filter and the prediction together).

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to draw on.
    jerk_std : float
        σ_j behind Q in cm/s³, > 0.
    scenario : Scenario
        Everything else; its own σ_j is drawn as the reference curve.
    noise : array_like, shape (n, 1), optional
        Vision's unit noise; default the scenario's fixed draw.

    Returns
    -------
    str
        The numbers of this view, for the line beside the figure: whose filter runs
        (:data:`WHOSE_FILTER`), σ_j, when 2σ of
        the predicted position first reaches the amplitude, and this run's position
        MSE after the burn-in (cm²) with the error variance the filter expects there.

    Raises
    ------
    ValueError
        If ``jerk_std`` is not a finite number > 0, or ``noise`` has the wrong shape.
    """
    return _draw(figure, jerk_std=validation.positive("jerk_std", jerk_std, "cm/s³"),
                 scenario=scenario, noise=noise)


def _draw(figure: Figure, *, jerk_std: float, scenario: Scenario,
          noise: np.ndarray | None) -> str:
    """:func:`draw_background` of a σ_j already checked (by it, or by the slider's range)."""
    variant = dataclasses.replace(scenario, jerk_std=jerk_std)
    tracking = experiments.track(variant, noise=noise)
    # The filter settled on vision: what the observer knows when the measurements stop.
    settled = tracking.model.steady_state().estimate_covariance
    growth = open_loop(variant, np.zeros(3), settled, OPEN_LOOP_DURATION)
    times = scenario.times
    window = (times >= TRACKING_WINDOW[0]) & (times <= TRACKING_WINDOW[1])
    expected = float(np.mean(tracking.position_variances[scenario.burn_in_steps:]))

    panels = reuse_panels(figure, _build, scenario)
    panels.growth.set_ydata(2 * growth.position_stds)
    panels.vision.set_ydata(tracking.measurements[window, 0])
    panels.estimate.set_ydata(tracking.positions[window])
    return (f"{WHOSE_FILTER} σ_j = {format_jerk(jerk_std)} cm/s³. Without measurements, 2σ "
            f"of the predicted position reaches the flight's amplitude of "
            f"{scenario.amplitude:g} cm {_crossing_text(growth, scenario.amplitude)}. "
            f"Tracking MSE of this run after "
            f"{scenario.burn_in:g} s: {float(tracking.mse()):.3g} cm², the filter expects "
            f"{expected:.3g} cm².")


def describe_background(*, jerk_std: float, scenario: Scenario = DEFAULT) -> str:
    """What :func:`draw_background` shows at ``jerk_std`` (its alt text)."""
    return (f"Left: twice the standard deviation of the predicted position over "
            f"{OPEN_LOOP_DURATION:g} s without measurements, at σ_j = {format_jerk(jerk_std)} "
            f"cm/s³ and at the scenario's σ_j, against the flight's amplitude. Right: vision, "
            f"the true path and the filtered estimate from {TRACKING_WINDOW[0]:g} to "
            f"{TRACKING_WINDOW[1]:g} s.")


def explore_background(scenario: Scenario = DEFAULT) -> Explorer:
    """Slider for σ_j (log scale): open-loop growth and tracking respond together.

    The slider starts at :data:`START_JERK_STD`, not at the scenario's σ_j
    (:attr:`~lqe_helpers.scenario.Scenario.process_jerk_std`, the reference curve);
    vision's unit noise is drawn once from the scenario's explorer seed
    (:func:`~lqe_helpers.explorers.base.with_explorer_seed`) and kept.
    """
    noise = with_explorer_seed(scenario).unit_noise(sensors=("vision",))
    slider = log_slider("σ_j (cm/s³)", START_JERK_STD, *JERK_STD_RANGE, steps_per_decade=8,
                        readout_format=".0f")
    return Explorer(
        "Jerk noise σ_j: open-loop growth and tracking",
        {"jerk_std": slider},
        partial(_draw, scenario=scenario, noise=noise),
        figsize=(10.0, 4.8),
        describe=partial(describe_background, scenario=scenario),
    )
