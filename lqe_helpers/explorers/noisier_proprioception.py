"""Explorer of question (d): how much does a noisier proprioception still help vision?

One slider sets σ_p while σ_v stays at the scenario's value. The left column shows
one trial: the butterfly, the vision-only and the fused estimate, and their errors.
The right panel places the slider's σ_p on the theoretical curve of the fused
filter's steady-state position variance, below the vision-only level that the
curve approaches but never crosses. The numbers of the view (both σ's, the trial's
MSEs, proprioception's weight, whose filter made the estimates) are not drawn in the
figure: the drawing function returns them as one line of text, shown between the
slider and the picture.

Given the student's own filter (``filter=my_filter``, notebook 01's function), the
estimates of the trial are the student's, run through
:func:`lqe_helpers.student_code.call` (copies of the inputs, a time limit; a failure is
one line in the explorer); the theory curve and the weight come from the pack's steady
state, which does not depend on the readings.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial

import numpy as np
from matplotlib.figure import Figure

from .. import experiments, validation
from ..figures.noisier_proprioception import (  # noqa: F401  (THEORY_TITLE: found here too)
    THEORY_TITLE,
    NoisierPanels,
    noisier_panels,
)
from ..scenario import DEFAULT, Scenario
from .base import Explorer, with_explorer_seed
from .cache import LastResults
from .common import estimate_lines, position_shares, significant, trial_numbers
from .fusion import FUSED, unit_noise, vision_only
from .panels import pin_axis_labels, reuse_panels
from .sliders import float_slider
from .student_functions import checked_function, refiltered, whose

#: σ_p (cm) of question (d). The numbers line does not give proprioception's weight at
#: this σ_p (10.0 %): Going further 1 of notebook 04 asks for it, and the Explore
#: section sends the student to this σ_p before it (issue 23 §5).
QUESTION_SIGMA_P = 4.5
#: Where the slider starts (cm): near question (d)'s σ_p, not at it (issue 15).
START_SIGMA_P = 6.0

#: Slider range for σ_p (cm): low, high, step; 1.5 and 4.5 cm lie on the grid.
SIGMA_P_RANGE = (0.5, 30.0, 0.5)

#: σ_p (cm) spanned by the theoretical curve in the right panel.
CURVE_RANGE = (0.3, 100.0)

def steady_position_variances(scenario: Scenario, sigma_v: float,
                              sigma_p: np.ndarray) -> tuple[float, np.ndarray]:
    """Theoretical steady-state position variance (cm²) without and with proprioception.

    The [0, 0] entry of ``(I − K∞ C) P∞`` (:func:`~lqe_helpers.steady_state.steady_state`)
    for vision alone and for vision + proprioception (Tutorial eq. (6)).

    Parameters
    ----------
    scenario : Scenario
        Supplies A and Q.
    sigma_v : float
        Vision noise σ_v in cm, > 0.
    sigma_p : array_like, shape (S,)
        Proprioception noise values σ_p in cm, each > 0.

    Returns
    -------
    vision_only : float
        Steady-state position variance of the vision-only filter.
    fused : ndarray, shape (S,)
        The same for the fused filter at each σ_p (one batched Riccati solve).
    """
    sigma_v = validation.positive("sigma_v", sigma_v, "cm")
    sigma_p = validation.finite_array("sigma_p", sigma_p, min_ndim=1)
    if sigma_p.ndim != 1 or np.any(sigma_p <= 0):
        raise ValueError(
            f"sigma_p must be a 1-D array of values > 0 cm, got {np.ravel(sigma_p)[:6].tolist()}"
        )
    alone = experiments.filter_model(scenario, ("vision",), [sigma_v]).steady_state()
    sigmas = np.stack([np.full_like(sigma_p, sigma_v), sigma_p], axis=-1)
    both = experiments.filter_model(scenario, FUSED, sigmas).steady_state()
    return float(alone.estimate_covariance[0, 0]), both.estimate_covariance[:, 0, 0]


def draw_noisier_proprioception(figure: Figure, *, sigma_p: float,
                                scenario: Scenario = DEFAULT,
                                noise: np.ndarray | None = None,
                                filter: Callable[..., np.ndarray] | None = None) -> str:
    """Draw one trial of vision-only and fused tracking at ``sigma_p`` on ``figure``.

    Top left: true position and both estimates. Bottom left: both errors (estimate −
    true position). Right: the fused filter's theoretical steady-state position
    variance against σ_p (log axis), the vision-only level, and a marker at
    ``sigma_p``. Returns both σ's, this trial's MSEs after the scenario's burn-in,
    proprioception's share of the settled position gain (withheld at question (d)'s
    σ_p, :data:`QUESTION_SIGMA_P`) and whose filter made the estimates as one line of
    text (the explorer shows it beside the figure), e.g.
    "σ_v = 1.5 cm, σ_p = 6 cm. MSE of this trial after 1 s: vision only 0.4450 cm²,
    fused 0.4200 cm². Proprioception's weight in the steady state: 5.88 %. Estimates
    from your my_filter." (the explorer's draw).

    A figure this function drew before (for the same scenario) keeps its panels and
    only has its data replaced, which halves the redraw time of a slider; any other
    figure is cleared first. The picture is the same either way.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        Figure to draw on.
    sigma_p : float
        Proprioception noise σ_p in cm, > 0. Vision keeps the scenario's σ_v.
    scenario : Scenario
        Butterfly, filter and simulation constants.
    noise : array_like, shape (n, 2), optional
        Unit noise of vision (column 0) and proprioception (column 1); default the
        scenario's fixed draw. The vision-only filter uses column 0.
    filter : callable, optional
        The student's filter ``filter(y, A, C, Q, R, z0, P0) -> estimates (n, k)``
        (notebook 01's ``my_filter``), run on the trial's readings with each filter's
        model (:func:`lqe_helpers.experiments.filter_model`); default the pack's engine.

    Returns
    -------
    str
        Both σ's (cm), the trial's MSEs (cm²) of both filters after the burn-in (4
        significant figures), proprioception's weight (%, 3 significant figures) and
        whose filter it is.

    Notes
    -----
    Lines carry a ``gid`` for tests: ``"truth"``, ``"vision-only"``, ``"fused"``,
    ``"vision-only error"``, ``"fused error"`` (left); ``"theory fused"`` (curve),
    ``"theory vision-only"`` (level) and ``"theory now"`` (marker) on the right.

    Raises
    ------
    ValueError
        If ``sigma_p`` is not a finite number > 0, ``noise`` has the wrong shape, or
        ``filter`` is neither None nor a function.
    StudentCodeError
        If ``filter`` fails: raises, does not return in time, or returns something
        other than the estimates (one line; the explorer shows it).
    """
    noise = unit_noise(scenario, noise)
    filter = checked_function("filter", filter)
    return _draw(figure, sigma_p=validation.positive("sigma_p", sigma_p, "cm"),
                 scenario=scenario, noise=noise, filter=filter,
                 vision_run=partial(_vision_run, scenario, noise, filter))


def _vision_run(scenario: Scenario, noise: np.ndarray,
                filter: Callable[..., np.ndarray] | None) -> experiments.Tracking:
    """The vision-only run of the trial at the scenario's σ_v, by ``filter``."""
    return refiltered(vision_only(scenario, scenario.sigma_v, noise), filter,
                      f"the explorer's trial with vision alone, σ_v = {scenario.sigma_v:g} cm")


def _draw(figure: Figure, *, sigma_p: float, scenario: Scenario, noise: np.ndarray,
          vision_run: Callable[[], experiments.Tracking],
          filter: Callable[..., np.ndarray] | None) -> str:
    """:func:`draw_noisier_proprioception` of a σ_p already checked; ``vision_run()``
    makes or keeps the vision-only run (σ_v is the scenario's, whatever the slider)."""
    sigma_v = scenario.sigma_v
    vision = vision_run()
    fused = refiltered(experiments.track(scenario, FUSED, sigmas=[sigma_v, sigma_p],
                                         noise=noise),
                       filter, f"the explorer's trial with both senses, σ_p = {sigma_p:g} cm")
    truth = scenario.truth[:, 0]
    # The theory at the slider's σ_p: the steady state of the very model the fused
    # filter ran with (the curve's value at this σ_p), and proprioception's share of
    # its settled position gain (its reliability weight).
    settled = fused.model.steady_state()
    theory_now = settled.estimate_covariance[0, 0]
    weight_p = float(position_shares(settled.gain)[1])

    panels = reuse_panels(figure, _build, scenario)
    for gid, values in estimate_lines(truth, vision, fused).items():
        panels.trial.lines[gid].set_ydata(values)
    panels.marker.set_data([sigma_p], [theory_now])
    return (f"{trial_numbers(scenario, sigma_v, sigma_p, vision, fused)} "
            f"{_weight_text(sigma_p, weight_p)} Estimates from {whose(filter)}.")


def _weight_text(sigma_p: float, weight_p: float) -> str:
    """Proprioception's steady-state weight (a fraction) as the numbers line gives it:
    withheld at question (d)'s σ_p, where a task of Going further 1 computes it."""
    if math.isclose(sigma_p, QUESTION_SIGMA_P, rel_tol=1e-9):
        return (f"Proprioception's weight in the steady state at σ_p = {QUESTION_SIGMA_P:g} cm: "
                f"Going further 1 asks you to compute it.")
    return f"Proprioception's weight in the steady state: {significant(100 * weight_p, 3)} %."


def _build(figure: Figure, scenario: Scenario) -> NoisierPanels:
    """The explorer's panels on the empty ``figure``, by its painter in figures/."""
    curve_sigma = np.geomspace(*CURVE_RANGE, 120)
    level, curve = steady_position_variances(scenario, scenario.sigma_v, curve_sigma)
    panels = noisier_panels(figure, scenario.times, scenario.duration, scenario.amplitude,
                            curve_sigma, level, curve)
    pin_axis_labels(figure)
    return panels


def describe_noisier_proprioception(*, sigma_p: float, scenario: Scenario = DEFAULT,
                                    filter: Callable[..., object] | None = None) -> str:
    """What :func:`draw_noisier_proprioception` shows at ``sigma_p`` (its alt text).

    ``filter`` is the student's filter that made the estimates, or None (the engine).
    """
    return (f"One trial at σ_v = {scenario.sigma_v:g} cm and σ_p = {sigma_p:.1f} cm. Left: "
            f"true position, the vision-only and the fused estimate ({whose(filter)}), and their "
            f"errors; right: the fused filter's steady-state position variance against σ_p "
            f"(the pack's steady state, which does not depend on the readings), with "
            f"the vision-only filter's level as a line and σ_p = {sigma_p:.1f} cm marked.")


def explore_noisier_proprioception(scenario: Scenario = DEFAULT, *,
                                   filter: Callable[..., np.ndarray] | None = None) -> Explorer:
    """A σ_p slider over vision-only and fused tracking of one fixed trial.

    The unit noise is drawn once from the scenario's explorer seed (another draw than
    the tasks', :func:`~lqe_helpers.explorers.base.with_explorer_seed`) and kept, so
    moving σ_p rescales the same proprioceptive noise pattern; vision's readings and
    the vision-only run never change. The slider starts at :data:`START_SIGMA_P`, near
    question (d)'s σ_p; σ_v is the scenario's.

    Parameters
    ----------
    scenario : Scenario
        Constants of the simulation.
    filter : callable, optional
        The student's filter (``explore_noisier_proprioception(filter=my_filter)``): the
        slider then runs it for both estimates (see :func:`draw_noisier_proprioception`)
        and a failure shows as one line above the last picture. Default the engine.

    Raises
    ------
    ValueError
        If ``filter`` is neither None nor a function.
    """
    filter = checked_function("filter", filter)
    low, high, step = SIGMA_P_RANGE
    sliders = {"sigma_p": float_slider("σ_p (cm)", START_SIGMA_P, low, high, step,
                                       readout_format=".1f")}
    noise = unit_noise(with_explorer_seed(scenario))
    vision_run = LastResults(partial(_vision_run, scenario, noise, filter))
    draw = partial(_draw, scenario=scenario, noise=noise, vision_run=vision_run, filter=filter)
    return Explorer("How much does a noisier proprioception help?", sliders, draw,
                    figsize=(10.0, 5.0),
                    describe=partial(describe_noisier_proprioception, scenario=scenario,
                                     filter=filter))
