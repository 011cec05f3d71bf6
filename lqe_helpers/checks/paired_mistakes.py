"""The usual mistakes of a paired difference of per-run MSEs with its 95 % interval: the
pairing, the interval's arithmetic, either condition alone, the readings for the truth
(:func:`interval_mistakes`), and slips of unit (:func:`unit_mistakes`)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .. import metrics
from .judging import NORMAL_95

#: How :func:`interval_mistakes` names the readings of ``readings``: each run's own, or
#: those of the one trial of a task's earlier part (y), broadcast over every run.
OWN_READINGS = "the readings"
TRIAL_READINGS = "the readings of one trial (y), the same for every run"
_TRUTH = ("an estimate's error is estimate − true position (the truth), not estimate − "
          "reading")


def _around(mean: float, half: float, runs: int) -> metrics.Interval:
    return metrics.Interval(mean, mean - half, mean + half, runs)


def interval_mistakes(first: np.ndarray, second: np.ndarray, first_name: str,
                      second_name: str, *,
                      readings: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
                      ) -> dict[str, metrics.Interval]:
    """The usual mistakes of a paired difference ``first − second`` with its 95 % interval.

    Parameters
    ----------
    first, second : ndarray, shape (runs,)
        Per-run values of the two conditions, run r of both on the same noise.
    first_name, second_name : str
        What they are, for the messages ("the raw readings' MSE").
    readings : mapping of str to (ndarray, ndarray), optional
        The same per-run MSEs measured against readings instead of the truth, by which
        readings: each run's own (:data:`OWN_READINGS`) or one trial's y, the same for
        every run (:data:`TRIAL_READINGS`).

    Returns
    -------
    dict of str to metrics.Interval
        Cause → the interval it gives: the sign reversed, the runs treated as unpaired,
        the two separate intervals combined, the standard deviation for the standard
        error, 1.96 for Student's t, the population standard deviation, each condition
        alone, the MSEs against the readings (slips of unit: :func:`unit_mistakes`, which a
        check puts after its own causes).
    """
    runs = first.size
    difference = first - second
    right = metrics.mean_ci95(difference)
    t = metrics.t_critical_95(runs - 1)
    s = float(np.std(difference, ddof=1))
    alone_first, alone_second = metrics.mean_ci95(first), metrics.mean_ci95(second)
    unpaired = t * np.sqrt((np.var(first, ddof=1) + np.var(second, ddof=1)) / runs)
    both = f"{first_name} − {second_name}"
    return {
        f"the sign is reversed: it is {second_name} − {first_name}; the task asks for "
        f"{both}": metrics.mean_ci95(second - first),
        "it combines the two separate intervals. The runs are paired (the same noise in run "
        "r), so take the interval of the per-run differences: it is much narrower because "
        "the shared noise cancels":
            _around(right.mean, alone_first.half_width + alone_second.half_width, runs),
        "it treats the two as independent samples (unpaired). The runs are paired (the same "
        "noise in run r): take the interval of the per-run differences":
            _around(right.mean, unpaired, runs),
        "its half-width uses the standard deviation of the differences; a 95 % interval of "
        "the mean uses its standard error, the standard deviation divided by √runs":
            _around(right.mean, t * s, runs),
        f"its half-width uses the normal 1.96 instead of Student's t value for {runs - 1} "
        f"degrees of freedom (metrics.mean_ci95 does this for you)":
            _around(right.mean, NORMAL_95 * s / np.sqrt(runs), runs),
        "the standard deviation is the population one (divided by runs); a sample standard "
        "deviation divides by runs − 1":
            _around(right.mean, t * float(np.std(difference)) / np.sqrt(runs), runs),
        f"it is the interval of {first_name} alone, not of the per-run differences "
        f"{both}": alone_first,
        f"it is the interval of {second_name} alone, not of the per-run differences "
        f"{both}": alone_second,
        **{cause: interval for which, pair in (readings or {}).items()
           for cause, interval in {
               f"the MSEs are measured against {which}: {_TRUTH}":
                   metrics.mean_ci95(pair[0] - pair[1]),
               f"{first_name} is measured against {which}: {_TRUTH}":
                   metrics.mean_ci95(pair[0] - second)}.items()},
    }


def unit_mistakes(first: np.ndarray, second: np.ndarray, first_name: str,
                  second_name: str) -> dict[str, metrics.Interval]:
    """Slips of unit in a paired difference of MSEs ``first − second`` (cm²), each (runs,):
    a per cent or a fraction of either (of its mean or run by run), the difference of the
    root MSEs (cm), their ratio."""
    difference = first - second
    own = {name: name.removeprefix("the ") for name in (first_name, second_name)}
    asked = "the task asks for the difference itself, in cm²"
    with np.errstate(divide="ignore", invalid="ignore"):
        slips = {
            **{f"it is in % of {name} (its mean over the runs); {asked}":
                   metrics.mean_ci95(100 * difference / values.mean())
               for name, values in ((first_name, first), (second_name, second))},
            **{f"it is in % of each run's {own[name]}; {asked}":
                   metrics.mean_ci95(100 * difference / values)
               for name, values in ((first_name, first), (second_name, second))},
            f"it is a fraction of {first_name}; {asked}":
                metrics.mean_ci95(difference / first.mean()),
            f"each run's difference is divided by that run's {own[first_name]}; {asked}":
                metrics.mean_ci95(difference / first),
            "it is the difference of the root mean squared errors (√MSE, in cm), run by "
            "run; the task asks for the difference of the MSEs themselves, in cm²":
                metrics.mean_ci95(np.sqrt(first) - np.sqrt(second)),
            f"it is a ratio of the MSEs ({own[first_name]} / {own[second_name]}); the task "
            f"asks for their difference, in cm²": metrics.mean_ci95(first / second),
        }
    return {cause: interval for cause, interval in slips.items()
            if np.all(np.isfinite([interval.mean, interval.low, interval.high]))}
