"""Explorer of question (a): how well vision alone lets the filter follow the butterfly.

One slider sets the vision noise σ_v. The figure shows the true path, the noisy
visual samples and the filter's estimate with the ±2σ band of its own position
variance, for one fixed noise pattern scaled by σ_v. The estimate is the pack's
engine's, or that of the student's own filter (``explore_vision(filter=my_filter)``),
run through :func:`lqe_helpers.student_code.call` (copies of its inputs, a time limit;
a failure is one line in the explorer). The band comes from the engine's covariance
sequence, which does not depend on the readings, so it is the same for either filter.
The numbers of the view (σ_v, whose filter, this run's MSEs) are returned as one line
of text that the explorer shows between the slider and the figure.

Speed: building a matplotlib figure (axes, ticks, legend) costs more than the whole
filter run, so :func:`draw_vision` builds the panel once per figure
(:func:`~lqe_helpers.explorers.panels.reuse_panels`) and afterwards only replaces the data
and limits of the same artists; the numbers stay out of the figure, where text would
be rendered again on every move. The picture is the same as a fresh drawing (a test
checks the PNG bytes); only the redraw is faster.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

import numpy as np
from matplotlib.figure import Figure

from .. import experiments, metrics, validation
from ..figures.vision import (  # noqa: F401  (the labels: tests and readers find them here)
    BAND_LABEL,
    ESTIMATE_LABEL,
    TRUTH_LABEL,
    VISION_LABEL,
    VisionPanel,
    vision_panel,
)
from ..scenario import DEFAULT, Scenario
from .base import Explorer, with_explorer_seed
from .panels import reuse_panels, set_ylim_in_steps
from .sliders import float_slider, starting_value
from .student_functions import checked_function, refiltered, whose

#: Slider range for σ_v (cm): from a nearly perfect eye to noise as large as the flight.
SIGMA_V_RANGE = (0.1, 10.0)
#: Slider step for σ_v (cm).
SIGMA_V_STEP = 0.1

def _build(figure: Figure, scenario: Scenario) -> VisionPanel:
    """The explorer's panel on the empty ``figure``, by notebook 01's painter of it."""
    return vision_panel(figure, scenario.times, scenario.truth[:, 0], scenario.duration)


def draw_vision(figure: Figure, *, sigma_v: float, scenario: Scenario = DEFAULT,
                noise: np.ndarray | None = None,
                filter: Callable[..., np.ndarray] | None = None) -> str:
    """Draw one vision-only tracking run at vision noise ``sigma_v`` on ``figure``.

    Draws the whole figure: the true position, the noisy visual measurements
    (Tutorial eq. (3)), the filtered estimate (Tutorial eq. (5)) and a band of ±2
    standard deviations of the filter's own position variance. A figure not drawn
    by this function is cleared first; on one it drew before, the same artists
    receive the new data.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to draw on.
    sigma_v : float
        Vision noise standard deviation σ_v in cm, > 0; both the true noise level
        and the one the filter assumes in R.
    scenario : Scenario
        Every other constant (Δt, the flight, Q, z0, P0, burn-in).
    noise : ndarray, shape (n, 1), optional
        Unit noise scaled by σ_v; default the scenario's fixed vision draw.
    filter : callable, optional
        A student's ``filter(y, A, C, Q, R, z0, P0)`` returning the estimates (n, 3),
        e.g. ``my_filter``; it gets the readings (n, 1) and the model of
        :func:`lqe_helpers.experiments.filter_model`. Default: the pack's engine.

    Returns
    -------
    str
        The numbers of this view, for the line beside the figure: σ_v, whose filter
        made the estimate, this run's mean squared error (cm²) of the raw vision and of
        the filtered estimate after the scenario's burn-in, and their ratio, each to
        three significant figures (readable from σ_v = 0.1 to 10 cm).

    Raises
    ------
    ValueError
        If ``sigma_v`` is not a finite number > 0, or ``noise`` has the wrong shape.
    lqe_helpers.student_code.StudentCodeError
        If ``filter`` is not a function, fails, runs too long or returns anything but
        an (n, 3) array of real numbers (one line, naming the student's own line).
    """
    return _draw(figure, sigma_v=validation.positive("sigma_v", sigma_v, "cm"),
                 scenario=scenario, noise=noise, filter=filter)


def _draw(figure: Figure, *, sigma_v: float, scenario: Scenario,
          noise: np.ndarray | None, filter: Callable[..., np.ndarray] | None = None) -> str:
    """:func:`draw_vision` of a σ_v already checked (by it, or by the slider's range)."""
    tracking = experiments.track(scenario, ("vision",), sigmas=[sigma_v], noise=noise)
    measured = tracking.measurements[:, 0]
    estimate = refiltered(tracking, filter,
                          f"the explorer's readings at σ_v = {sigma_v:.1f} cm").positions
    std = np.sqrt(tracking.position_variances)
    raw_mse = float(tracking.measurement_mse("vision"))
    filtered_mse = float(metrics.mse(estimate, scenario.truth[:, 0], scenario.burn_in_steps))

    panel = reuse_panels(figure, _build, scenario)
    panel.vision.set_ydata(measured)
    panel.band.set_data(scenario.times, estimate - 2 * std, estimate + 2 * std)
    panel.estimate.set_ydata(estimate)
    low = min(measured.min(), (estimate - 2 * std).min(), -scenario.amplitude)
    high = max(measured.max(), (estimate + 2 * std).max(), scenario.amplitude)
    margin = 0.05 * (high - low)
    # In steps of half the amplitude: most slider moves keep the axis as it was.
    set_ylim_in_steps(panel.ax, low - margin, high + margin, scenario.amplitude / 2)
    ratio = f"{raw_mse / filtered_mse:.3g}" if filtered_mse > 0 else "undefined"
    return (f"σ_v = {sigma_v:.1f} cm, filtered by {whose(filter)}. MSE of this run after "
            f"{scenario.burn_in:g} s: raw vision {raw_mse:.3g} cm², filtered "
            f"{filtered_mse:.3g} cm², ratio raw / filtered {ratio}.")


def describe_vision(*, sigma_v: float, scenario: Scenario = DEFAULT,
                    filter: Callable[..., np.ndarray] | None = None) -> str:
    """One sentence saying what :func:`draw_vision` shows at ``sigma_v`` (its alt text)."""
    return (f"Position against time, 0–{scenario.duration:g} s: true path, noisy vision at "
            f"σ_v = {sigma_v:.1f} cm and the estimate of {whose(filter)} with a ±2σ band from the "
            f"engine's covariance sequence, which does not depend on the readings.")


def explore_vision(scenario: Scenario = DEFAULT, *,
                   filter: Callable[..., np.ndarray] | None = None) -> Explorer:
    """Slider for σ_v (cm) over :func:`draw_vision`, with one fixed noise pattern.

    The unit noise is drawn once from the scenario's explorer seed (another draw than
    the tasks', :func:`~lqe_helpers.explorers.base.with_explorer_seed`) and kept, so
    moving the slider rescales the same noise instead of drawing new noise.

    Parameters
    ----------
    scenario : Scenario
        Constants of the simulation; the slider starts at its ``sigma_v``.
    filter : callable, optional
        The student's ``my_filter(y, A, C, Q, R, z0, P0)``: the slider then runs it, and
        the numbers line says so. If it fails, the explorer shows its one-line message
        and tries again on the next move. Default: the pack's engine.

    Returns
    -------
    Explorer
        Display it in JupyterLab to get the live slider.

    Raises
    ------
    ValueError
        If ``scenario.sigma_v`` lies outside the slider's range :data:`SIGMA_V_RANGE`,
        or ``filter`` is given but is not a function.
    """
    low, high = SIGMA_V_RANGE
    start = starting_value("sigma_v", scenario.sigma_v, low, high, "cm")
    filter = checked_function("filter", filter)
    noise = with_explorer_seed(scenario).unit_noise(sensors=("vision",))
    slider = float_slider("σ_v (cm)", start, low, high, SIGMA_V_STEP, readout_format=".1f")
    return Explorer(
        "Vision-only tracking as the vision noise σ_v changes",
        {"sigma_v": slider},
        partial(_draw, scenario=scenario, noise=noise, filter=filter),
        describe=partial(describe_vision, scenario=scenario, filter=filter),
    )
