"""Figures of notebook 03 (fusion): the settled filters' frequency response (Going further).

Notebooks 03 and 04 draw one trial of vision alone against vision + proprioception with
:meth:`lqe_helpers.experiments.Tracking.figure`
(:func:`~lqe_helpers.figures.common.tracking_comparison_figure`), their Monte Carlo
comparisons with :func:`~lqe_helpers.figures.common.paired_mse_figure`.
Also the painter of notebook 03's explorer (:func:`fusion_panels`): the trial by
:func:`~lqe_helpers.figures.common.trial_panels` beside each sense's share of the gain,
built once with no data and refilled by :mod:`lqe_helpers.explorers.fusion`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import FillBetweenPolyCollection
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle
from matplotlib.text import Annotation

from ..plotting import COLORS, DATA_UNDER_LINES, plot_band, style
from .common import (
    TRUE_POSITION_LABEL,
    VISION_READINGS_LABEL,
    TrialLine,
    TrialPanels,
    label_axes,
    legend_handles,
    mark_values,
    plain_log_ticks,
    trial_panels,
)

#: A curve of :func:`frequency_response_figure`: (gain |H|, shape (f,); lead in s, shape
#: (f,); style role).
ResponseCurve = tuple[np.ndarray, np.ndarray, str]
#: A simulated point of :func:`frequency_response_figure`: (gain, lead in s, style role).
ResponsePoint = tuple[float, float, str]


def frequency_response_figure(frequency: np.ndarray, curves: Mapping[str, ResponseCurve], *,
                              marked: float,
                              points: Mapping[str, ResponsePoint] | None = None,
                              title: str = "") -> Figure:
    """The settled filters' frequency response: gain (top) and lead (bottom) against f.

    A true position ``sin(2π f t)`` read without noise comes out of a settled filter as
    ``|H| sin(2π f (t + lead))``. Each curve is one filter (from
    :func:`lqe_helpers.lowpass.position_response`); each point a simulated run at
    ``marked`` (a sinusoid fitted to a noise-free estimate), to set beside its curve.

    Parameters
    ----------
    frequency : array_like, shape (f,)
        Frequencies (Hz), > 0, drawn on a log axis.
    curves : mapping of str to (gain, lead, role)
        Legend label → gain ``|H|`` (unitless) and lead (s, > 0 ahead of the movement),
        each of shape (f,), drawn in the role's style (e.g. ``"alternative"`` for vision
        alone, ``"estimate"`` for the fused filter).
    marked : float
        The flight's frequency (Hz), marked by a vertical line in both panels.
    points : mapping of str to (gain, lead, role), optional
        Legend label → a simulated gain and lead (s) at ``marked``, drawn as a circle in
        the role's colour.
    title : str
        Title of the top panel.

    Returns
    -------
    Figure
        Two panels sharing the frequency axis; in each the curves, then the points.

    Raises
    ------
    ValueError
        If ``frequency`` is not positive and of shape (f,), a curve does not match it,
        or ``marked`` is not > 0.
    """
    frequency = np.asarray(frequency, dtype=float)
    if frequency.ndim != 1 or frequency.size < 2 or np.any(frequency <= 0):
        raise ValueError(f"frequency must be frequencies > 0 Hz of shape (f,), f >= 2, got "
                         f"shape {frequency.shape}")
    if not marked > 0:
        raise ValueError(f"marked must be a frequency > 0 Hz, got {marked}")
    fig, (ax_gain, ax_lead) = plt.subplots(2, 1, figsize=(8.5, 6.0), sharex=True)
    ax_gain.axhline(1.0, **style("truth", linewidth=0.8, label="|H| = 1: passed unchanged"))
    ax_lead.axhline(0.0, **style("truth", linewidth=0.8))
    for label, (gain, lead, role) in curves.items():
        gain, lead = np.asarray(gain, dtype=float), np.asarray(lead, dtype=float)
        if gain.shape != frequency.shape or lead.shape != frequency.shape:
            raise ValueError(f"curve {label!r} must have gain and lead of shape "
                             f"{frequency.shape}, got {gain.shape} and {lead.shape}")
        ax_gain.plot(frequency, gain, **style(role, label=label))
        ax_lead.plot(frequency, 1000 * lead, **style(role, label=label))
    for label, (gain, lead, role) in (points or {}).items():
        marker = {"color": COLORS[role], "linestyle": "none", "marker": "o", "markersize": 7,
                  "markerfacecolor": "none", "markeredgewidth": 1.6}
        ax_gain.plot([marked], [gain], label=label, **marker)
        ax_lead.plot([marked], [1000 * lead], label=label, **marker)
    mark_values(ax_gain, {f"{marked:g} Hz": marked}, COLORS["reference"], linestyle=":",
                linewidth=1.2)
    ax_lead.axvline(marked, color=COLORS["reference"], linestyle=":", linewidth=1.2)
    label_axes(ax_gain, ylabel="gain |H| (estimate / movement)", title=title,
               xscale="log", legend={"loc": "lower left", "fontsize": 8})
    label_axes(ax_lead, "frequency of the movement (Hz)", "lead (ms), > 0 = ahead",
               xlim=(frequency[0], frequency[-1]))
    plain_log_ticks(ax_lead, "x", [tick for tick in (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2,
                                                     5, 10, 20, 50)
                                   if frequency[0] <= tick <= frequency[-1]])
    fig.tight_layout()
    return fig


#: The explorer's lines by gid (see :data:`~lqe_helpers.figures.common.TrialLine`).
FUSION_LINES: dict[str, TrialLine] = {
    "vision readings": (0, "vision", VISION_READINGS_LABEL),
    "proprioception readings": (0, "proprioception", "proprioception readings"),
    "truth": (0, "truth", TRUE_POSITION_LABEL),
    "vision-only": (0, "alternative", "vision-only estimate"),
    "fused": (0, "estimate", "fused estimate"),
    "vision-only error": (1, "alternative", None),
    "fused error": (1, "estimate", None),
}
_BAND = "fused band"
_BAND_LABEL = "fused filter's own ±2 SD"
#: Title of the explorer's right panel; it never changes, so it stays in the cached
#: background. It names what is drawn, not the rule the shares follow (Going further 5
#: of notebook 03).
SHARES_TITLE = "each sense's share\nof the position gain"


class FusionPanels(NamedTuple):
    """The artists :func:`fusion_panels` draws; the explorer refills all of them."""

    trial: TrialPanels
    band: FillBetweenPolyCollection
    bars: tuple[Rectangle, Rectangle]
    texts: tuple[Annotation, Annotation]


def fusion_panels(figure: Figure, times: np.ndarray, duration: float,
                  amplitude: float) -> FusionPanels:
    """Notebook 03's explorer on the empty ``figure``: a trial and the shares, no data yet.

    Left: the lines of :data:`FUSION_LINES` over ``times`` (s), 0 to ``duration`` s,
    signals ±1.7 ``amplitude`` (cm), errors with the fused filter's ±2 SD band. Right:
    one bar per sense for its share of the position correction, its value printed on it.
    """
    trial = trial_panels(figure, duration, times, FUSION_LINES, width_ratios=(3.4, 1.0),
                         height_ratios=(1.6, 1.0), top=0.88, wspace=0.25,
                         signal_limit=1.7 * amplitude, error_limit=3.5)
    errors, shares = trial.errors, trial.side
    plot_band(errors, times, np.zeros_like(times), np.ones_like(times), label=_BAND_LABEL)
    band = errors.collections[-1]
    band.set_gid(_BAND)
    band.set_zorder(DATA_UNDER_LINES)
    figure.legend(handles=[*legend_handles(trial, FUSION_LINES), band], loc="upper left",
                  bbox_to_anchor=(0.07, 0.99), ncol=3, fontsize=8, markerscale=2.5)
    errors.set_yticks([-2, 0, 2])

    names = ("vision", "proprioception")
    bars = shares.bar([0, 1], [0.5, 0.5], color=[COLORS[name] for name in names],
                      edgecolor="black", linewidth=0.6, zorder=DATA_UNDER_LINES)
    texts = []
    for bar, name in zip(bars, names, strict=True):
        bar.set_gid(f"weight {name}")
        texts.append(shares.annotate("", (bar.get_x() + bar.get_width() / 2, 0.5),
                                     xytext=(0, 3), textcoords="offset points", ha="center",
                                     fontsize=9))
    shares.set_xticks([0, 1], ["vision", "proprio-\nception"])
    shares.set_ylim(0.0, 1.1)
    shares.set_yticks([0.0, 0.25, 0.5, 0.75, 1.0])
    shares.set_ylabel("share of the position correction")
    # Lifted clear of the axes area, which the bars (clipped to it) repaint on every
    # move: at the default pad the title would be repainted with them.
    shares.set_title(SHARES_TITLE, fontsize=10, pad=12)
    return FusionPanels(trial, band, tuple(bars), tuple(texts))
