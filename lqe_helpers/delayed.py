"""Question (e)'s result: a filter's output delayed by δ samples and compensated.

:class:`DelayedTracking` is made by :func:`lqe_helpers.experiments.delay_and_compensate`
(the pack's engine) or :func:`lqe_helpers.own_runs.delayed` (a student's own arrays), and
draws its standard figures through :mod:`lqe_helpers.figures` (imported only when a
figure is asked for). :func:`one_run` picks one run of a batch, for every result's figure.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from . import metrics, simulation

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from .experiments import Tracking


def one_run(values: np.ndarray, run: int | tuple[int, ...] | None,
            trailing: int = 1) -> np.ndarray:
    """``values[run]``, which must leave ``trailing`` axes (one run of a batch).

    Raises
    ------
    ValueError
        If ``run`` does not pick one run of the leading axes.
    """
    index = () if run is None else np.index_exp[run]
    try:
        one = values[index]
    except (IndexError, TypeError):
        one = None
    if one is None or one.ndim != trailing:
        raise ValueError(
            f"run must pick one run of the leading axes {values.shape[:-trailing]}, got {run!r}")
    return one


@dataclass(frozen=True)
class DelayedTracking:
    """Question (e): the filter fed a signal that arrives ``steps`` samples late.

    All arrays are on the wall-clock time axis: sample j is what the observer has at
    time j·Δt. The first δ samples are NaN: nothing has arrived yet.

    Attributes
    ----------
    tracking : Tracking
        The filter run on the measurement stream (indexed by when it was sensed).
    steps : int
        The delay δ in samples.
    delayed_measurements : ndarray, shape (..., n, m)
        ``y_{j−δ}``, the reading available at time j.
    delayed_estimates : ndarray, shape (..., n, 3)
        ``ẑ_{j−δ}``, the newest estimate at time j, uncompensated (Tutorial eq. (8)).
    predictions : ndarray, shape (..., n, 3)
        ``z*_j = A^δ ẑ_{j−δ}``, the compensated estimate (Tutorial eq. (7)).

    A student's own run (:func:`lqe_helpers.own_runs.delayed`) may hold positions only:
    ``delayed_measurements``, ``delayed_estimates`` and ``predictions`` of shape (n, 1).
    """

    tracking: Tracking
    steps: int
    delayed_measurements: np.ndarray
    delayed_estimates: np.ndarray
    predictions: np.ndarray

    @property
    def delay(self) -> float:
        """The delay d = δ Δt (s)."""
        return self.steps * self.tracking.scenario.dt

    def figure(self, fast_window: tuple[float, float] = (3.75, 4.35), *,
               run: int | tuple[int, ...] | None = None) -> Figure:
        """Question (e)'s standard figure: truth, late readings, late and compensated estimate.

        Built by :func:`lqe_helpers.figures.delay_figure` (the whole trial, the start
        with nothing arrived yet shaded, and ``fast_window`` (s) of fast flight), so a
        notebook writes ``delayed.figure()`` instead of passing six arrays.

        Parameters
        ----------
        fast_window : tuple of float
            (start, end) of the bottom-right zoom (s).
        run : int or tuple of int, optional
            Which run of a batch (an index into the leading axes); required when there
            are leading axes.

        Raises
        ------
        ValueError
            If ``run`` does not pick one run, or the delay is 0 (nothing to show).
        """
        from . import figures

        scenario = self.tracking.scenario
        return figures.delay_figure(
            scenario.times, scenario.truth[:, 0],
            one_run(self.delayed_measurements, run, trailing=2)[:, 0],
            one_run(self.delayed_estimates, run, trailing=2)[:, 0],
            one_run(self.predictions, run, trailing=2)[:, 0], self.delay, fast_window)

    def comparison_figure(self, title: str = "", *,
                          run: int | tuple[int, ...] | None = None) -> Figure:
        """The delayed and the compensated estimate beside a perfect but late eye.

        Built by :func:`lqe_helpers.figures.tracking_comparison_figure`: estimates on top
        (ẑ_{j−δ} blue, p*_j vermillion, the true position δ samples late pink dotted), their
        errors below. ``title`` heads the top panel; ``run`` as in :meth:`figure`.
        """
        from . import figures

        scenario = self.tracking.scenario
        truth = scenario.truth[:, 0]
        late_eye = simulation.delay_signal(truth, self.steps, axis=-1)
        return figures.tracking_comparison_figure(scenario.times, truth, {
            r"delayed estimate $\hat p_{j-\delta}$":
                (one_run(self.delayed_estimates, run, trailing=2)[:, 0], "estimate"),
            r"compensated $p^*_j$": (one_run(self.predictions, run, trailing=2)[:, 0],
                                     "prediction"),
            r"perfect but late eye $p_{j-\delta}$": (late_eye, "reference")}, title=title)

    def mse(self, which: str) -> np.ndarray:
        """Per-run position MSE (cm²) of ``"delayed"`` or ``"predicted"`` estimates.

        Skips the scenario's burn-in or the delay, whichever is longer.
        """
        arrays = {"delayed": self.delayed_estimates, "predicted": self.predictions}
        if not isinstance(which, str) or which not in arrays:
            raise ValueError(f"which must be one of {tuple(arrays)}, got {which!r}")
        scenario = self.tracking.scenario
        skip = max(scenario.burn_in_steps, self.steps)
        return metrics.mse(arrays[which][..., 0], scenario.truth[:, 0], skip)
