"""Figures of notebook 03 (fusion): one trial of vision alone against vision + proprioception.

Notebook 04 draws the same comparison with a noisier proprioception. Both notebooks'
Monte Carlo comparisons use the shared :func:`~lqe_helpers.figures.common.paired_mse_figure`.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .common import tracking_comparison_figure


def fusion_trial_figure(times: np.ndarray, truth: np.ndarray, vision_only: np.ndarray,
                        fused: np.ndarray, readings: np.ndarray | None = None,
                        fused_label: str = "vision + proprioception",
                        title: str = "") -> Figure:
    """One trial: the vision-only and the fused estimate beside the truth, their errors below.

    Parameters
    ----------
    times : array_like, shape (n,)
        Sample times (s).
    truth : array_like, shape (n,)
        True position (cm).
    vision_only, fused : array_like, shape (n,)
        Position estimates (cm) of the vision-only filter (drawn green dash-dotted) and
        of the fused filter (blue).
    readings : array_like, shape (n, 2), optional
        The trial's readings (cm), vision then proprioception, drawn in the top panel.
    fused_label : str
        Legend label of the fused estimate (e.g. "vision + noisier proprioception").
    title : str
        Title of the top panel (say what changed, e.g. "σ_v = σ_p = 1.5 cm").

    Returns
    -------
    Figure
        :func:`~lqe_helpers.figures.common.tracking_comparison_figure` of the two
        estimates: lines in the order readings, truth, vision only, fused.

    Raises
    ------
    ValueError
        If ``readings`` is not of shape (n, 2).
    """
    shown = None
    if readings is not None:
        readings = np.asarray(readings, dtype=float)
        if readings.shape != (np.size(times), 2):
            raise ValueError(f"readings must have shape (n, 2) = ({np.size(times)}, 2), "
                             f"vision then proprioception, got shape {readings.shape}")
        shown = {"vision readings": (readings[:, 0], "vision"),
                 "proprioception readings": (readings[:, 1], "proprioception")}
    estimates = {"vision only": (vision_only, "alternative"), fused_label: (fused, "estimate")}
    return tracking_comparison_figure(times, truth, estimates, readings=shown, title=title)
