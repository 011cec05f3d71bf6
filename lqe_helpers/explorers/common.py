"""The one-trial layout shared by the fusion explorers of questions (c) and (d).

Both :mod:`lqe_helpers.explorers.fusion` and
:mod:`lqe_helpers.explorers.noisier_proprioception` show one trial of a vision-only
and a fused filter in a left column (signals over errors) beside a side panel of
their own, with a legend above. The trial's MSEs are not drawn in the figure: the
drawing function returns them as text (:func:`trial_numbers`), which the explorer
shows between its sliders and the picture. This module holds that common part; each
explorer fills its side panel.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from .. import experiments
from ..figures.common import TrialLine, trial_column
from ..scenario import Scenario

__all__ = ["TrialLine", "TrialPanels", "build_trial_panels", "estimate_lines",
           "legend_handles", "position_shares", "significant", "trial_numbers"]


class TrialPanels(NamedTuple):
    """A trial's signals (top left) and errors (bottom left), a side panel, the lines."""

    signals: Axes
    errors: Axes
    side: Axes
    lines: dict[str, Line2D]


def build_trial_panels(figure: Figure, scenario: Scenario, lines: Mapping[str, TrialLine], *,
                       width_ratios: tuple[float, float], height_ratios: tuple[float, float],
                       top: float, wspace: float, signal_limit: float,
                       error_limit: float) -> TrialPanels:
    """Lay out one trial over ``scenario.times`` beside a side panel, on an empty figure.

    The left column holds the signals (position, ±``signal_limit`` cm) above the
    errors (estimate − true position, ±``error_limit`` cm, with a zero line); each
    entry of ``lines`` becomes a line of zeros, its key as gid, waiting for data,
    drawn by the notebooks' painter of this picture
    (:func:`lqe_helpers.figures.common.trial_column`). The caller adds the legend and
    fills the side panel.
    """
    grid = figure.add_gridspec(2, 2, width_ratios=width_ratios, height_ratios=height_ratios,
                               left=0.07, right=0.98, bottom=0.1, top=top,
                               hspace=0.1, wspace=wspace)
    signals = figure.add_subplot(grid[0, 0])
    errors = figure.add_subplot(grid[1, 0], sharex=signals)
    side = figure.add_subplot(grid[:, 1])
    drawn = trial_column(signals, errors, scenario.times, lines, error_linewidth=1.0,
                         zero_line_first=False)
    signals.set_ylim(-signal_limit, signal_limit)
    signals.set_ylabel("position (cm)")
    signals.tick_params(labelbottom=False)
    errors.set_ylim(-error_limit, error_limit)
    errors.set_xlim(0.0, scenario.duration)
    errors.set_xlabel("time (s)")
    errors.set_ylabel("error (cm)")
    figure.align_ylabels((signals, errors))
    return TrialPanels(signals, errors, side, drawn)


def legend_handles(panels: TrialPanels, lines: Mapping[str, TrialLine]) -> list[Line2D]:
    """The lines of ``panels`` that ``lines`` gives a legend label, in its order."""
    return [panels.lines[gid] for gid, (_, _, label) in lines.items() if label is not None]


def estimate_lines(truth: np.ndarray, vision: experiments.Tracking,
                   fused: experiments.Tracking) -> dict[str, np.ndarray]:
    """y data (cm) of the truth, both estimates and their errors, by line gid."""
    return {
        "truth": truth,
        "vision-only": vision.positions,
        "fused": fused.positions,
        "vision-only error": vision.positions - truth,
        "fused error": fused.positions - truth,
    }


def position_shares(gain: np.ndarray) -> np.ndarray:
    """Each sensor's share of the position correction: the gain's position row, normalised.

    ``gain`` (3, m) is a settled gain K∞. Its position row is ``P[0, 0] · (1/σ_i²)``
    (K = P Cᵀ R⁻¹ with identical rows of C), so the shares are the reliability weights
    (:func:`lqe_helpers.cue_combination.reliability_weights`,
    ``tests/test_cue_combination.py``): here they come from the filter itself.
    """
    row = gain[0]
    return row / row.sum()


def significant(value: float, digits: int) -> str:
    """``value`` to ``digits`` significant figures, trailing zeros kept.

    E.g. 0.06251 → "0.06251" and 10 → "10.00" at 4 digits; 0.249 → "0.25" at 2. A
    fixed number of decimals would print a small value as 0.00 at some slider settings.
    """
    return f"{value:#.{digits}g}".rstrip(".")


def trial_numbers(scenario: Scenario, sigma_v: float, sigma_p: float,
                  vision: experiments.Tracking, fused: experiments.Tracking) -> str:
    """Both σ's (cm) and the trial's MSEs (cm²) after the burn-in, as one sentence.

    Each MSE to 4 significant figures, enough to tell the two apart at every σ of the
    sliders, e.g. "σ_v = 1.5 cm, σ_p = 2 cm. MSE of this trial after 1 s: vision only
    0.3041 cm², fused 0.2739 cm²."
    """
    return (
        f"σ_v = {sigma_v:g} cm, σ_p = {sigma_p:g} cm. MSE of this trial after "
        f"{scenario.burn_in:g} s: vision only {significant(float(vision.mse()), 4)} cm², "
        f"fused {significant(float(fused.mse()), 4)} cm²."
    )
