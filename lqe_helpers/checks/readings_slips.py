"""MSEs taken against readings instead of the truth (notebooks 03 and 04): against each
sense's readings of the same run, or of the one trial y of an earlier task, broadcast over
every run of a Monte Carlo task."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..model import SENSORS
from .judging import readings_mistakes
from .paired_mistakes import OWN_READINGS, TRIAL_READINGS


def sensor_readings(y: np.ndarray, one_trial: bool = False) -> dict[str, np.ndarray]:
    """Each sense's readings (..., n) (cm) of ``y`` (..., n, m), by how a message names them.

    For :func:`~lqe_helpers.checks.judging.mse_mistakes`: an MSE taken against the readings
    instead of the truth; ``one_trial``: against the earlier task's one trial y (n, m),
    the same for every run of a Monte Carlo task.
    """
    trial = " of one trial" if one_trial else ""
    every = ", the same for every run" if one_trial else ""
    return {f"{sense}'s readings{trial} (column {column} of y){every}": y[..., column]
            for column, sense in enumerate(SENSORS[:y.shape[-1]])}


def monte_carlo_readings_slips(positions: Mapping[str, np.ndarray],
                               readings: Mapping[str, np.ndarray], y: np.ndarray,
                               burn_in_steps: int) -> dict[str, dict]:
    """Per-run MSEs after the burn-in (cm², shape (runs,)) against readings, not the truth.

    Parameters
    ----------
    positions : mapping of str to ndarray, shape (runs, n)
        Each filter's positions (cm): keys ``"vision"`` (vision alone) and ``"fused"``.
    readings : mapping of str to ndarray, shape (runs, n, m)
        Each filter's readings of the same runs (cm), same keys.
    y : ndarray, shape (n, 2)
        The earlier task's one trial (cm): vision, proprioception.
    burn_in_steps : int
        Samples left out at the start.

    Returns
    -------
    dict
        ``"vision"``, ``"fused"``: cause → that filter's MSEs, for ``judge``'s mistakes;
        ``"pairs"``: which readings → (vision-only, fused) MSEs against vision's readings,
        for :func:`~lqe_helpers.checks.paired_mistakes.interval_mistakes`.
    """
    slips: dict[str, dict] = {
        kind: readings_mistakes(positions[kind], burn_in_steps,
                                {**sensor_readings(readings[kind]),
                                 **sensor_readings(y, one_trial=True)})
        for kind in ("vision", "fused")}
    slips["pairs"] = {
        which: tuple(np.mean((positions[kind] - against[kind])[:, burn_in_steps:] ** 2,
                             axis=-1) for kind in ("vision", "fused"))
        for which, against in (
            (OWN_READINGS, {kind: readings[kind][..., 0] for kind in ("vision", "fused")}),
            (TRIAL_READINGS, {kind: y[:, 0] for kind in ("vision", "fused")}))}
    return slips
