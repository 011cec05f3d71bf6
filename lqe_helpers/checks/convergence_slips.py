"""The slips of a convergence time (notebook 02, Task 2): a curve's band crossed the
wrong way, a step late, another band, the mean over the wrong axis; the times they give
(s)."""

from __future__ import annotations

import numpy as np

from .. import metrics


def crossing_times(curve: np.ndarray, dt: float) -> dict[str, float]:
    """Times (s) a convergence time takes under the usual misreadings of its definition.

    ``curve`` is the right squared-error curve (cm², shape (n,)); the keys name the
    mistake, for the checks' messages.
    """
    n = curve.size
    right = float(metrics.convergence_time(curve, dt))
    inside = curve <= 2.0 * np.mean(curve[n // 2:])
    times = {
        "your convergence time is in samples (time steps): give it in seconds, samples × "
        f"Δt (Δt = {dt:g} s)": right / dt,
        "your convergence time is in milliseconds: give it in seconds": right * 1000.0,
        "it is the first time the curve enters the band; the definition asks for the time "
        "after which it stays inside for good (it leaves the band again after entering it)":
            float(np.argmax(inside)) * dt if inside.any() else None,
        "it is the time of the last sample outside the band; the convergence time is the "
        "sample just after it, the first that stays inside": right - dt if right > 0 else None,
    }
    for level, text in ((np.mean(curve), "the mean of the whole curve"),
                        (curve[-1], "the last sample")):
        outside = curve > 2.0 * level
        times[f"the steady level is taken as {text}; the definition uses the mean over the "
              f"second half of the trial"] = ((n - int(np.argmax(outside[::-1]))) * dt
                                              if outside.any() else 0.0)
    return times


#: The band of the definition of a convergence time: ``factor`` × the steady level
#: (:func:`metrics.convergence_time`'s default), and other bands a student may take.
BAND_FACTOR = 2.0
OTHER_FACTORS = (1.5, 3.0, 4.0, 5.0, 10.0)


def wrong_axis_times(squared: np.ndarray, dt: float) -> list[dict[str, float]]:
    """Times (s) of the Monte Carlo mean taken over the wrong axis, one dict per P0.

    ``squared`` are the squared errors (cm²), shape (runs, P0s, n); the task's mean over the
    runs (axis 0) gives one curve per P0. Over the samples (axis 2) it gives one MSE per run
    and P0, whose column for a P0 is read as a curve over the runs; over the P0s (axis 1) one
    curve per run, whose rows 0, 1, … are read as the P0s' curves. Keys name the mistake.
    """
    over_samples = squared.mean(axis=2)                       # (runs, P0s)
    over_p0 = squared.mean(axis=1)                            # (runs, n)
    ask = ("mean_squared_error is the mean over the runs, axis 0 of squared_error "
           "(runs, 2, n), one curve over time per P0, shape (2, n)")
    return [{
        f"the mean was taken over axis 2, the samples (time), not over the runs: {ask}":
            float(metrics.convergence_time(over_samples[:, index], dt)),
        f"the mean was taken over axis 1, the two P0, not over the runs: {ask}":
            float(metrics.convergence_time(over_p0[index], dt)),
    } for index in range(squared.shape[1])]
