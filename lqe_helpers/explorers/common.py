"""What the fusion explorers of questions (c) and (d) share, besides their painter.

Both :mod:`lqe_helpers.explorers.fusion` and
:mod:`lqe_helpers.explorers.noisier_proprioception` show one trial of a vision-only
and a fused filter in a left column (signals over errors) beside a side panel of
their own, drawn by :func:`lqe_helpers.figures.common.trial_panels`. This module holds
the data they refill it with (:func:`estimate_lines`, :func:`position_shares`) and the
trial's MSEs as text (:func:`trial_numbers`), which the explorer shows between its
sliders and the picture.
"""

from __future__ import annotations

import numpy as np

from .. import experiments
from ..scenario import Scenario

__all__ = ["estimate_lines", "position_shares", "significant", "trial_numbers"]


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
