"""Explorer of question (b): how the initial covariance P0 shapes the filter's start.

One logarithmic slider sets P0 = p0_variance · I. The figure shows the first
seconds of one run: position (truth, noisy vision, estimate) and velocity (truth,
estimate), each estimate with the ±2σ band of the filter's own variance, so the
reader sees both how fast the wrong initial guess is corrected and how confident
the filter is while it is still wrong. The numbers of the view (whose filter, P0 and
this run's position MSEs) are returned as one line of text that the explorer shows
between the slider and the figure.

The estimates come from the pack's engine, or from the student's own filter (notebook
01's ``my_filter``) when one is given: it is then called through
:func:`lqe_helpers.student_code.call` on every move, and a failure is one line in the
explorer. The bands always come from the engine's covariance sequence, which does not
depend on the readings (a student's filter returns estimates only).

Speed: as in :mod:`lqe_helpers.explorers.vision`, the panels are built once per
figure and later calls replace the data and limits of the same artists; the numbers
stay out of the figure, where text would be rendered again on every move. The
picture equals a fresh drawing.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

import numpy as np
from matplotlib.figure import Figure

from .. import experiments, metrics, validation
from ..figures.initial_covariance import (  # noqa: F401  (the labels, found here too)
    BAND_LABEL,
    ESTIMATE_LABEL,
    TRUTH_LABEL,
    VISION_LABEL,
    StartUpPanels,
    start_up_panels,
)
from ..scenario import DEFAULT, Scenario
from .base import Explorer, with_explorer_seed
from .panels import reuse_panels, set_ylim_in_steps
from .sliders import log_slider, starting_value
from .student_functions import checked_function, refiltered, whose

#: Slider range for P0 (cm², same number for cm²/s² and cm²/s⁴): from "certain of
#: the initial guess" to "no idea at all".
P0_RANGE = (1e-2, 1e6)
#: Slider positions per decade of P0.
P0_STEPS_PER_DECADE = 4
#: Time shown (s): the start-up transient and a little of the steady state.
WINDOW = 2.0

def shown_steps(scenario: Scenario) -> int:
    """Number of samples drawn: the first :data:`WINDOW` seconds (or the whole trial)."""
    return min(scenario.n_steps, round(WINDOW / scenario.dt) + 1)


def _build(figure: Figure, scenario: Scenario) -> StartUpPanels:
    """The explorer's panels on the empty ``figure``, by notebook 02's painter of them."""
    times = scenario.times[:shown_steps(scenario)]
    return start_up_panels(figure, times, scenario.truth[:times.size], scenario.peak_speed)


def draw_initial_covariance(figure: Figure, *, p0_variance: float,
                            scenario: Scenario = DEFAULT, noise: np.ndarray | None = None,
                            filter: Callable[..., np.ndarray] | None = None) -> str:
    """Draw the first :data:`WINDOW` seconds of one vision-only run with P0 = p0_variance · I.

    Draws the whole figure, two panels side by side. Left: true position, noisy
    vision and the estimated position. Right: true and estimated velocity. Each
    estimate carries a band of ±2 standard deviations of the filter's own variance
    (Tutorial eq. (5)), from the engine's covariance sequence (it does not depend on
    the readings). The velocity axis is fixed to twice the butterfly's top speed, so
    a huge initial band or an overshooting estimate runs off the panel instead of
    rescaling it. A figure not drawn by this function is cleared first; on one it drew
    before, the same artists receive the new data.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to draw on.
    p0_variance : float
        Diagonal entry of P0 = p0_variance · I, > 0 (cm² for position, cm²/s² for
        velocity, cm²/s⁴ for acceleration).
    scenario : Scenario
        Every other constant; vision noise is ``scenario.sigma_v``.
    noise : ndarray, shape (n, 1), optional
        Unit vision noise; default the scenario's fixed draw.
    filter : callable, optional
        A student's filter ``filter(y, A, C, Q, R, z0, P0) -> estimates (n, 3)``
        (notebook 01's ``my_filter``), called through
        :func:`lqe_helpers.student_code.call`; default the pack's engine.

    Returns
    -------
    str
        The numbers of this view, for the line beside the figure: whose filter, P0 and
        this run's position MSE (cm²) before and after the scenario's burn-in, to three
        significant figures.

    Raises
    ------
    ValueError
        If ``p0_variance`` is not a finite number > 0, ``noise`` has the wrong shape, or
        ``filter`` is neither None nor a function.
    lqe_helpers.student_code.StudentCodeError
        One line, if the student's filter fails or returns something other than the
        estimates.
    """
    return _draw(figure, p0_variance=validation.positive("p0_variance", p0_variance, "cm²"),
                 scenario=scenario, noise=noise, filter=checked_function("filter", filter))


def _draw(figure: Figure, *, p0_variance: float, scenario: Scenario,
          noise: np.ndarray | None, filter: Callable[..., np.ndarray] | None = None) -> str:
    """:func:`draw_initial_covariance` of inputs already checked (by it, or by the slider)."""
    tracking = experiments.track(scenario, ("vision",), p0_variance=p0_variance, noise=noise)
    where = f"the explorer's trial with P0 = {p0_variance:.3g} · I"
    estimates = refiltered(tracking, filter, where).result.estimates
    positions, truth = estimates[:, 0], scenario.truth[:, 0]
    burn_in = scenario.burn_in_steps
    early_mse = float(metrics.mse(positions[:burn_in], truth[:burn_in]))
    late_mse = float(metrics.mse(positions, truth, burn_in))
    shown = shown_steps(scenario)
    measured = tracking.measurements[:shown, 0]
    estimates = estimates[:shown]
    variances = tracking.result.estimate_covariances[:shown]

    panels = reuse_panels(figure, _build, scenario)
    times = scenario.times[:shown]
    panels.vision.set_ydata(measured)
    for column, (band, line) in enumerate(zip(panels.bands, panels.estimates, strict=True)):
        std = np.sqrt(variances[:, column, column])
        band.set_data(times, estimates[:, column] - 2 * std, estimates[:, column] + 2 * std)
        line.set_ydata(estimates[:, column])
    low = min(measured.min(), estimates[:, 0].min(), -scenario.amplitude)
    high = max(measured.max(), estimates[:, 0].max(), scenario.amplitude)
    margin = 0.05 * (high - low)
    # In steps of half the amplitude: most slider moves keep the axis as it was.
    set_ylim_in_steps(panels.axes[0], low - margin, high + margin, scenario.amplitude / 2)
    who = whose(filter)
    return (f"{who[0].upper()}{who[1:]}, P0 = {p0_variance:.3g} · I. Position MSE of this "
            f"run: {early_mse:.3g} cm² in the first {scenario.burn_in:g} s, {late_mse:.3g} "
            f"cm² after.")


def describe_initial_covariance(*, p0_variance: float, scenario: Scenario = DEFAULT,
                                filter: Callable[..., np.ndarray] | None = None) -> str:
    """What :func:`draw_initial_covariance` shows at ``p0_variance`` (its alt text)."""
    seconds = (shown_steps(scenario) - 1) * scenario.dt
    return (f"The first {seconds:g} s of vision-only tracking by {whose(filter)} with P0 = "
            f"{p0_variance:.3g} · I. Left: true position, noisy vision and the estimate with "
            f"its ±2σ band; right: true and estimated velocity with its ±2σ band. The bands "
            f"are the engine's covariances, which do not depend on the readings.")


def explore_initial_covariance(scenario: Scenario = DEFAULT,
                               filter: Callable[..., np.ndarray] | None = None) -> Explorer:
    """Logarithmic slider for P0 (cm²) over :func:`draw_initial_covariance`.

    The unit noise is drawn once from the scenario's explorer seed (another draw than
    the tasks', :func:`~lqe_helpers.explorers.base.with_explorer_seed`) and kept, so
    moving the slider changes only P0, never the noise the filter sees.

    Parameters
    ----------
    scenario : Scenario
        Constants of the simulation; the slider starts at its ``p0_variance``.
    filter : callable, optional
        The student's filter ``filter(y, A, C, Q, R, z0, P0)`` (notebook 01's
        ``my_filter``): the slider then runs it, and the numbers line says so. If it
        fails, the explorer shows its one-line message and keeps the last picture.
        Default: the pack's engine.

    Returns
    -------
    Explorer
        Display it in JupyterLab to get the live slider.

    Raises
    ------
    ValueError
        If ``scenario.p0_variance`` lies outside the slider's range :data:`P0_RANGE`, or
        ``filter`` is neither None nor a function.
    """
    filter = checked_function("filter", filter)
    low, high = P0_RANGE
    start = starting_value("p0_variance", scenario.p0_variance, low, high, "cm²")
    noise = with_explorer_seed(scenario).unit_noise(sensors=("vision",))
    slider = log_slider("P0 (cm²)", start, low, high, steps_per_decade=P0_STEPS_PER_DECADE,
                        readout_format=".3g")
    return Explorer(
        "The start of vision-only tracking as the initial covariance P0 changes",
        {"p0_variance": slider},
        partial(_draw, scenario=scenario, noise=noise, filter=filter),
        describe=partial(describe_initial_covariance, scenario=scenario, filter=filter),
    )
