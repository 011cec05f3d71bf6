"""Explorer of question (c): vision alone against vision fused with proprioception.

Two sliders set the noise of each sense. The left column shows one trial: the
butterfly, both senses' readings and the two filters' estimates, with the
estimation errors below. The right panel shows how the fused filter splits its
trust between the senses once its gain has settled: the shares of the position
correction, each printed on its bar (to 2 significant figures). Both σ's and the
trial's MSEs are not drawn in the figure: the drawing function returns them as one line
of text, shown between the sliders and the picture.

Given the student's own filter (``explore_fusion(filter=my_filter)``), the sliders run it
for both estimates (through :func:`lqe_helpers.student_code.call`, so a hang is stopped
and a failure is one line in the explorer), and the numbers line says whose filter it
is. The ±2 SD band and the shares come from the engine's covariances and gain, which do
not depend on the readings: a student's ``my_filter`` returns estimates only.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

import numpy as np
from matplotlib.figure import Figure

from .. import experiments, validation
from ..figures.fusion import (  # noqa: F401  (SHARES_TITLE: tests find it here)
    SHARES_TITLE,
    FusionPanels,
    fusion_panels,
)
from ..scenario import DEFAULT, Scenario
from .base import Explorer, with_explorer_seed
from .cache import LastResults
from .common import estimate_lines, position_shares, significant, trial_numbers
from .panels import pin_axis_labels, reuse_panels
from .sliders import float_slider, starting_value
from .student_functions import StudentFilter, checked_function, refiltered, whose

#: The fused filter's sensors, in the column order of its noise and gains.
FUSED = ("vision", "proprioception")

#: Slider range for either σ (cm): low, high, step; 1.5 and 4.5 cm lie on the grid.
SIGMA_RANGE = (0.5, 6.0, 0.25)
#: How many vision-only runs (one per σ_v, about 0.2 MB each) the explorer keeps.
VISION_RUNS_KEPT = 16

def unit_noise(scenario: Scenario, noise: np.ndarray | None = None) -> np.ndarray:
    """Unit noise of vision (column 0) and proprioception (column 1), shape (n, 2).

    ``noise`` is validated and returned; None gives the scenario's fixed draw.
    """
    if noise is None:
        return scenario.unit_noise(sensors=FUSED)
    return validation.shaped_array("noise", noise, (scenario.n_steps, len(FUSED)),
                                   ", ".join(FUSED))


def vision_only(scenario: Scenario, sigma_v: float, noise: np.ndarray,
                filter: StudentFilter | None = None) -> experiments.Tracking:
    """Vision-only tracking of one trial with unit noise ``noise[:, 0]`` scaled by ``sigma_v``.

    ``noise`` (n, 2) as :func:`unit_noise` gives it; ``filter`` a student's filter that
    makes the estimates (:func:`~lqe_helpers.explorers.student_functions.refiltered`),
    or None for the engine's.
    Moving σ_p does not change this run, so the explorers keep it between moves
    (:class:`~lqe_helpers.explorers.cache.LastResults`).
    """
    tracking = experiments.track(scenario, ("vision",), sigmas=[sigma_v], noise=noise[:, :1])
    return refiltered(tracking, filter, f"the explorer's trial of vision at σ_v = "
                                        f"{sigma_v:g} cm")


def draw_fusion(figure: Figure, *, sigma_v: float, sigma_p: float,
                scenario: Scenario = DEFAULT, noise: np.ndarray | None = None,
                filter: StudentFilter | None = None) -> str:
    """Draw vision-only and fused tracking of one trial at ``sigma_v`` and ``sigma_p``.

    Both filters see the same visual readings; the fused one also sees proprioception
    (C with two rows ``[1, 0, 0]``, ``R = diag(σ_v², σ_p²)``, Tutorial eq. (6)). Top
    left: readings, true position and both estimates. Bottom left: both errors
    (estimate − true position) with the fused filter's own ±2 SD band. Right: each
    sense's share of the settled position gain, in % on its bar. Returns both σ's,
    this trial's MSEs after the scenario's burn-in and whose filter ran as one line of
    text (the explorer shows it beside the figure), e.g. "σ_v = 1.5 cm, σ_p = 2 cm. MSE
    of this trial after 1 s: vision only 0.4450 cm², fused 0.2786 cm². Filter: your
    my_filter." (the explorer's draw).

    A figure this function drew before (for the same scenario) keeps its panels and
    only has its data replaced, which halves the redraw time of a slider; any other
    figure is cleared first. The picture is the same either way.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        Figure to draw on.
    sigma_v : float
        Vision noise σ_v in cm, > 0.
    sigma_p : float
        Proprioception noise σ_p in cm, > 0.
    scenario : Scenario
        Butterfly, filter and simulation constants.
    noise : array_like, shape (n, 2), optional
        Unit noise of vision (column 0) and proprioception (column 1), scaled by the
        σ's; default the scenario's fixed draw. The vision-only filter uses column 0.
    filter : callable, optional
        The student's ``my_filter(y, A, C, Q, R, z0, P0)``, returning the estimates
        (n, 3): it makes both estimates
        (:func:`~lqe_helpers.explorers.student_functions.refiltered`). Default: the
        pack's engine.

    Returns
    -------
    str
        Both σ's (cm), the trial's MSEs (cm²) of both filters after the burn-in, and
        whose filter ran.

    Notes
    -----
    Lines carry a ``gid`` for tests: the keys of ``figures.fusion.FUSION_LINES``
    (``"vision readings"``, ``"proprioception readings"``, ``"truth"``, ``"vision-only"``,
    ``"fused"``, ``"vision-only error"``, ``"fused error"``); the bars ``"weight vision"`` and
    ``"weight proprioception"``.

    Raises
    ------
    ValueError
        If a σ is not a finite number > 0, ``noise`` has the wrong shape, or ``filter``
        is neither None nor a function.
    StudentCodeError
        If the student's filter fails (one line, see
        :func:`~lqe_helpers.explorers.student_functions.refiltered`).
    """
    noise = unit_noise(scenario, noise)
    filter = checked_function("filter", filter)
    return _draw(figure, sigma_v=validation.positive("sigma_v", sigma_v, "cm"),
                 sigma_p=validation.positive("sigma_p", sigma_p, "cm"), scenario=scenario,
                 noise=noise, filter=filter,
                 vision_runs=partial(vision_only, scenario, noise=noise, filter=filter))


def _draw(figure: Figure, *, sigma_v: float, sigma_p: float, scenario: Scenario,
          noise: np.ndarray, filter: StudentFilter | None,
          vision_runs: Callable[[float], experiments.Tracking]) -> str:
    """:func:`draw_fusion` of inputs already checked; ``vision_runs(σ_v)`` makes or keeps
    the vision-only run (with ``filter``'s estimates)."""
    vision = vision_runs(sigma_v)
    fused = refiltered(
        experiments.track(scenario, FUSED, sigmas=[sigma_v, sigma_p], noise=noise), filter,
        f"the explorer's trial of both senses at σ_v = {sigma_v:g}, σ_p = {sigma_p:g} cm")
    truth = scenario.truth[:, 0]
    # Share of the position correction each sense receives in the settled filter: the
    # reliability weights 1/σ² normalised, read off the fused filter's own gain.
    weights = position_shares(fused.model.steady_state().gain)

    panels = reuse_panels(figure, _build, scenario)
    data = {
        "vision readings": fused.measurements[:, 0],
        "proprioception readings": fused.measurements[:, 1],
        **estimate_lines(truth, vision, fused),
    }
    for gid, values in data.items():
        panels.trial.lines[gid].set_ydata(values)
    std = np.sqrt(fused.position_variances)
    panels.band.set_data(scenario.times, -2 * std, 2 * std)
    for bar, text, weight in zip(panels.bars, panels.texts, weights, strict=True):
        bar.set_height(weight)
        text.set_text(f"{significant(100 * weight, 2)} %")
        text.xy = (bar.get_x() + bar.get_width() / 2, weight)
    return f"{trial_numbers(scenario, sigma_v, sigma_p, vision, fused)} Filter: {whose(filter)}."


def _build(figure: Figure, scenario: Scenario) -> FusionPanels:
    """The explorer's panels on the empty ``figure``, by its painter in figures/."""
    panels = fusion_panels(figure, scenario.times, scenario.duration, scenario.amplitude)
    pin_axis_labels(figure)
    return panels


def describe_fusion(*, sigma_v: float, sigma_p: float) -> str:
    """What :func:`draw_fusion` shows at ``sigma_v`` and ``sigma_p`` (its alt text)."""
    return (f"One trial at σ_v = {sigma_v:.2f} cm and σ_p = {sigma_p:.2f} cm. Top left: true "
            f"position, both senses' readings, the vision-only and the fused estimate; bottom "
            f"left: their errors with the fused filter's ±2 SD band (from the engine's "
            f"covariances, which do not depend on the readings); right: each sense's share "
            f"of the position correction.")


def explore_fusion(scenario: Scenario = DEFAULT, *,
                   filter: StudentFilter | None = None) -> Explorer:
    """Sliders for σ_v and σ_p over vision-only and fused tracking of one fixed trial.

    ``filter`` is the student's ``my_filter(y, A, C, Q, R, z0, P0)``: the sliders then run
    it for both estimates, and the numbers line says so; a failure of it shows as one
    line in place of the numbers (:attr:`Explorer.problem`), and the next move tries
    again. Default: the pack's engine.

    The unit noise is drawn once from the scenario's explorer seed (another draw than
    the tasks', :func:`~lqe_helpers.explorers.base.with_explorer_seed`) and kept, so a
    slider changes only how loud a sense is, never its noise pattern; moving σ_p (or σ_v
    back to a recent value) reuses a kept vision-only run. The sliders start at the
    scenario's σ_v and σ_p (question (c): 1.5 cm each).

    Raises
    ------
    ValueError
        If ``scenario.sigma_v`` or ``scenario.sigma_p`` lies outside the sliders' range
        :data:`SIGMA_RANGE`, or ``filter`` is neither None nor a function.
    """
    filter = checked_function("filter", filter)
    low, high, step = SIGMA_RANGE
    start_v = starting_value("sigma_v", scenario.sigma_v, low, high, "cm")
    start_p = starting_value("sigma_p", scenario.sigma_p, low, high, "cm")
    sliders = {
        "sigma_v": float_slider("σ_v (cm)", start_v, low, high, step),
        "sigma_p": float_slider("σ_p (cm)", start_p, low, high, step),
    }
    noise = unit_noise(with_explorer_seed(scenario))
    # The vision-only runs of the last VISION_RUNS_KEPT σ_v: moving σ_p, or σ_v back to a
    # recent value, reuses one.
    vision_runs = LastResults(partial(vision_only, scenario, noise=noise, filter=filter),
                              size=VISION_RUNS_KEPT)
    draw = partial(_draw, scenario=scenario, noise=noise, filter=filter,
                   vision_runs=vision_runs)
    return Explorer(f"Vision alone against vision + proprioception ({whose(filter)})",
                    sliders, draw, figsize=(10.0, 5.0), describe=describe_fusion)
