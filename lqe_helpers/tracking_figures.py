"""A tracking run's further pictures (notebooks 00 and 02), drawn by the run itself.

:class:`TrackingFigures`, which :class:`~lqe_helpers.experiments.Tracking` inherits, hands
a run's own arrays (times, truth, readings, estimates, gains, the filter's variances and
steady state), with the values a notebook passes (a student's results stay arguments), to
the one painter of each picture in :mod:`lqe_helpers.figures` (imported when a figure is
asked for): a notebook passes one object, not six arrays. Each method checks its inputs
once, here; the painter draws.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from . import validation
from .prediction import OpenLoop

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from .experiments import Tracking

#: Style roles of a sweep's filters in :meth:`TrackingFigures.gains_figure` and
#: :meth:`TrackingFigures.belief_figure`, in the sweep's order.
SWEEP_ROLES = ("estimate", "alternative", "reference")


class TrackingFigures:
    """Pictures of a :class:`~lqe_helpers.experiments.Tracking` beyond its standard figure."""

    def _vision_run(self: Tracking, run: int | tuple[int, ...] | None
                    ) -> tuple[np.ndarray, np.ndarray]:
        """Run ``run``'s vision readings and positions (cm), each (n,), checked."""
        if self.sensors != ("vision",):
            raise ValueError(f"this figure draws a run of vision alone, this tracking has "
                             f"sensors {self.sensors}")
        return (validation.one_run(self.measurements, run, trailing=2)[:, 0],
                validation.one_run(self.positions, run))

    def open_loop_figure(self: Tracking, prediction: OpenLoop, close: int,
                         prediction_std: np.ndarray, *,
                         run: int | tuple[int, ...] | None = None) -> Figure:
        """Notebook 00's Figure 1: this run until the eyes close, then the prediction.

        Built by :func:`lqe_helpers.figures.open_loop_figure`.

        Parameters
        ----------
        prediction : OpenLoop
            The prediction from this run's estimate at sample ``close``
            (:func:`~lqe_helpers.prediction.open_loop`); its mean position is drawn.
        close : int
            The sample at which the eyes close (time ``close · Δt``), 0 ≤ close < n.
        prediction_std : array_like, shape (h,)
            The predicted position's σ (cm) at each of the prediction's h times, drawn as
            a ±2σ band (e.g. a student's ``two_sigma / 2``).
        run : int or tuple of int, optional
            Which run of a batch; required when there are leading axes.

        Raises
        ------
        ValueError
            If this is not a run of vision alone, ``run`` does not pick one run,
            ``prediction`` is not an OpenLoop from this run's estimate at ``close``,
            ``close`` is not a sample of the trial, or ``prediction_std`` is not finite of
            shape (h,).
        """
        readings, positions = self._vision_run(run)
        validation.instance("prediction", prediction, OpenLoop, "from prediction.open_loop()")
        times = self.scenario.times
        close = validation.count("close", close, 0, times.size - 1)
        start = validation.one_run(self.result.estimates, run, trailing=2)[close]
        if not np.allclose(prediction.means[0], start, rtol=0, atol=1e-9):
            raise ValueError(f"prediction must start from this run's estimate at sample close "
                             f"= {close}, {start}, got {prediction.means[0]}")
        std = validation.shaped_array("prediction_std", prediction_std, prediction.times.shape,
                                      "σ (cm) at each time of the prediction")
        from . import figures

        return figures.open_loop_figure(times, self.scenario.truth[:, 0], readings, positions,
                                        times[close], times[close] + prediction.times,
                                        prediction.means[:, 0], std)

    def panels_figure(self: Tracking, panels: Mapping[str, Tracking],
                      window: tuple[float, float], *,
                      run: int | tuple[int, ...] | None = None) -> Figure:
        """Notebook 00's Figure 5: this run's readings filtered several ways, a panel each.

        Built by :func:`lqe_helpers.figures.tracking_panels_figure`.

        Parameters
        ----------
        panels : mapping of str to Tracking
            Panel title → a run of the same readings and true path (e.g. the same trial
            with another σ_j), whose positions that panel draws.
        window : tuple of float
            (start, end) of the time shown (s).
        run : int or tuple of int, optional
            Which run of a batch, the same in every tracking; required when there are
            leading axes.

        Raises
        ------
        ValueError
            If this is not a run of vision alone, ``run`` does not pick one run, or
            ``panels`` is empty or holds anything but runs of these readings.
        """
        readings, _ = self._vision_run(run)
        truth = self.scenario.truth[:, 0]
        panels = dict(panels) if isinstance(panels, Mapping) else {}

        def of_these_readings(other: object) -> bool:
            return (isinstance(other, type(self)) and other.sensors == self.sensors
                    and np.array_equal(other.scenario.truth[:, 0], truth)
                    and np.array_equal(other._vision_run(run)[0], readings))

        if not panels or not all(of_these_readings(other) for other in panels.values()):
            got = {title: type(other).__name__ for title, other in panels.items()}
            raise ValueError("panels must map titles to Trackings of this run's readings and "
                             f"true path (at least one), got {got or 'none'}")
        estimates = {title: other._vision_run(run)[1] for title, other in panels.items()}
        from . import figures

        return figures.tracking_panels_figure(self.scenario.times, truth, readings, estimates,
                                              window=window)

    def _sweep(self: Tracking, labels: Sequence[str], run: int | tuple[int, ...] | None,
               ) -> tuple[list[str], np.ndarray]:
        """``labels`` checked against a sweep over P0, and run ``run``'s gains (s, n, k, 1)."""
        gains = validation.one_run(self.result.gains, run, trailing=4)
        labels = list(labels) if isinstance(labels, Sequence) and not isinstance(
            labels, str) else []
        if (self.model.R.ndim != 2 or not 1 <= gains.shape[0] <= len(SWEEP_ROLES)
                or gains.shape[-1] != 1 or len(labels) != gains.shape[0]
                or not all(isinstance(label, str) for label in labels)):
            raise ValueError(
                f"labels must be one legend label (str) per P0 of a sweep of 1 to "
                f"{len(SWEEP_ROLES)} P0 of one sensor with one R (gains of run {run!r} of "
                f"shape (s, n, k, 1)), got {labels or type(labels).__name__} for gains of "
                f"shape {gains.shape} and R of shape {self.model.R.shape}")
        return labels, gains

    def gains_figure(self: Tracking, labels: Sequence[str], *,
                     run: int | tuple[int, ...] | None = 0) -> Figure:
        """Notebook 02's Figure 3: the gains of each P0 of this sweep over time, and K∞.

        Built by :func:`lqe_helpers.figures.gains_figure`: run ``run``'s gains (the same in
        every run), one line per P0 labelled ``labels`` (roles :data:`SWEEP_ROLES`), and
        the steady-state gain of this run's model.

        Raises
        ------
        ValueError
            If this is not a sweep over P0 of one sensor, ``run`` does not pick one run,
            or ``labels`` does not hold one label per P0.
        """
        labels, gains = self._sweep(labels, run)
        from . import figures

        return figures.gains_figure(
            self.scenario.times, {label: (gains[i, :, :, 0], role) for i, (label, role) in
                                  enumerate(zip(labels, SWEEP_ROLES, strict=False))},
            self.model.steady_state().gain[:, 0])

    def belief_figure(self: Tracking, mean_squared_error: np.ndarray,
                      convergence_times: Sequence[float], threshold: float,
                      labels: Sequence[str]) -> Figure:
        """Notebook 02's Figure 4: each P0's actual squared error beside the filter's belief.

        Built by :func:`lqe_helpers.figures.belief_and_error_figure`, with this sweep's
        own position variances, steady-state variance and number of runs.

        Parameters
        ----------
        mean_squared_error : array_like, shape (s, n)
            Each P0's Monte Carlo mean squared position error (cm²) over these runs.
        convergence_times : sequence of float
            Each P0's convergence time (s), s of them.
        threshold : float
            The convergence threshold (cm²), > 0.
        labels : sequence of str
            One legend label per P0 (roles :data:`SWEEP_ROLES`).

        Raises
        ------
        ValueError
            If this is not Monte Carlo runs (one leading axis) of a sweep over P0 of one
            sensor, or an argument is not of that sweep's shape or range.
        """
        if self.positions.ndim != 3:
            raise ValueError(f"belief_figure draws Monte Carlo runs of a sweep, positions of "
                             f"shape (runs, s, n), got shape {self.positions.shape}")
        labels, _ = self._sweep(labels, 0)
        runs, count, n = self.positions.shape
        errors = validation.shaped_array("mean_squared_error", mean_squared_error, (count, n),
                                         "cm², one row per P0")
        converged = validation.numeric_array("convergence_times", convergence_times)
        if converged.shape != (count,):
            raise ValueError(f"convergence_times must be one time (s) per P0, shape "
                             f"({count},), got shape {converged.shape}")
        threshold = validation.positive("threshold", threshold, "cm²")
        variances = self.position_variances[0]
        from . import figures

        return figures.belief_and_error_figure(
            self.scenario.times,
            {label: (errors[i], variances[i], float(converged[i]), role)
             for i, (label, role) in enumerate(zip(labels, SWEEP_ROLES, strict=False))},
            self.model.steady_state().estimate_covariance[0, 0], threshold, runs)
