"""Choosing the jerk noise σ_j from the readings alone, through the innovations.

Notebook 00 settles σ_j with the true path (the Monte Carlo MSE), which no observer
has. The innovations need no truth: a σ_j is consistent when the mean NIS equals the
number of sensors, and likely when the innovations' log-likelihood is largest
(issue 17 §2). :func:`tune_jerk_std` computes all three on the same draws so that the
choices can be compared.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from . import experiments, metrics, model, validation
from .scenario import Scenario

#: Most σ_j values :func:`tune_jerk_std` accepts in one grid. Each value runs the filter over
#: every Monte Carlo run (about 0.1 s at the scenario's 300 runs), so 200 values take about
#: 20 s; notebook 00's grid has 17. A longer grid is refused before anything runs.
MAX_GRID_SIZE = 200


@dataclass(frozen=True)
class JerkChoice:
    """Three ways to pick σ_j on one grid, the first two without the true path.

    Attributes
    ----------
    jerk_stds : ndarray, shape (g,)
        The grid of σ_j (cm/s³), increasing.
    nis_mean : ndarray, shape (g,)
        Mean NIS after the burn-in over all runs (expected: the number of sensors).
    log_likelihood : ndarray, shape (runs, g)
        Each run's innovation log-likelihood after the burn-in (nats).
    mse : ndarray, shape (runs, g)
        Each run's position MSE (cm²) after the burn-in: needs the truth, shown for
        comparison only.
    sensors : int
        Number of sensors m.
    """

    jerk_stds: np.ndarray
    nis_mean: np.ndarray
    log_likelihood: np.ndarray
    mse: np.ndarray
    sensors: int

    @property
    def by_likelihood(self) -> float:
        """σ_j (cm/s³) of the largest mean log-likelihood, refined by a parabola in ln σ_j."""
        return _refined_extreme(self.jerk_stds, self.log_likelihood.mean(axis=0), largest=True)

    @property
    def by_nis(self) -> float:
        """σ_j (cm/s³) where the mean NIS crosses the number of sensors (interpolated in
        ln σ_j), or NaN if it does not cross on the grid."""
        excess = self.nis_mean - self.sensors
        crossings = np.flatnonzero(np.sign(excess[:-1]) != np.sign(excess[1:]))
        if crossings.size == 0:
            return float("nan")
        i = int(crossings[0])
        logs = np.log(self.jerk_stds[i:i + 2])
        fraction = excess[i] / (excess[i] - excess[i + 1])
        return float(np.exp(logs[0] + fraction * (logs[1] - logs[0])))

    @property
    def by_mse(self) -> float:
        """σ_j (cm/s³) of the smallest Monte Carlo mean MSE (uses the truth), refined by a
        parabola in ln σ_j."""
        return _refined_extreme(self.jerk_stds, self.mse.mean(axis=0), largest=False)

    def figure(self, chosen: dict[str, float]):
        """The three criteria against σ_j, with the σ_j each picks marked (``chosen``: keys
        "likelihood", "NIS", "MSE", σ_j in cm/s³), drawn by
        :func:`lqe_helpers.figures.jerk_choice_figure` from the means over the runs."""
        from . import figures

        return figures.jerk_choice_figure(self.jerk_stds, self.log_likelihood.mean(axis=0),
                                          self.nis_mean, self.mse.mean(axis=0), chosen,
                                          expected_nis=float(self.sensors))

    @property
    def by_likelihood_per_run(self) -> np.ndarray:
        """The σ_j (cm/s³) each single run's likelihood picks, shape (runs,): what one
        observer with one trial would choose; refined between grid points by a parabola
        in ln σ_j, as :attr:`by_likelihood`."""
        return np.array([_refined_extreme(self.jerk_stds, run, largest=True)
                         for run in self.log_likelihood])


def _refined_extreme(grid: np.ndarray, values: np.ndarray, largest: bool) -> float:
    """Grid point of the extreme of ``values``, refined by a parabola through it and its
    two neighbours in ln(grid); the grid point itself at either end of the grid."""
    i = int(np.argmax(values) if largest else np.argmin(values))
    if i == 0 or i == grid.size - 1:
        return float(grid[i])
    x = np.log(grid[i - 1:i + 2])
    a, b, _ = np.polyfit(x, values[i - 1:i + 2], 2)
    if a == 0:
        return float(grid[i])
    return float(np.exp(np.clip(-b / (2 * a), x[0], x[2])))


def tune_jerk_std(scenario: Scenario, jerk_stds: Sequence[float] | np.ndarray,
                  sensors: Sequence[str] = ("vision",), runs: int | None = None) -> JerkChoice:
    """Run the filter at every σ_j of a grid on the same draws; collect NIS, likelihood, MSE.

    Parameters
    ----------
    scenario : Scenario
        Everything but σ_j; its seed fixes the draws, shared by every σ_j.
    jerk_stds : array_like, shape (g,)
        σ_j values (cm/s³), > 0, increasing, 3 <= g <= :data:`MAX_GRID_SIZE`.
    sensors : sequence of str
        As for :func:`~lqe_helpers.experiments.track`.
    runs : int, optional
        Monte Carlo runs, >= 2; default the scenario's ``mc_runs``.

    Returns
    -------
    JerkChoice
    """
    validation.instance("scenario", scenario, Scenario, "e.g. scenario.DEFAULT")
    size = validation.elements(np.shape(jerk_stds))  # before any work on the values
    if size > MAX_GRID_SIZE:
        raise ValueError(
            f"jerk_stds must hold at most {MAX_GRID_SIZE} values (jerk_tuning.MAX_GRID_SIZE: "
            f"each runs the filter over every run, about 0.1 s), got {size} values")
    grid = validation.positive_array("jerk_stds", jerk_stds, "cm/s³", min_ndim=1)
    if grid.ndim != 1 or grid.size < 3 or np.any(np.diff(grid) <= 0):
        raise ValueError(f"jerk_stds must be an increasing grid of at least 3 values, got "
                         f"{_short(grid)}")
    runs = scenario.mc_runs if runs is None else validation.count("runs", runs, minimum=2)
    sensors = model.sensor_names(sensors)
    noise = scenario.unit_noise(runs, sensors)  # one draw for every σ_j
    nis_mean, likelihood, mse = [], [], []
    for jerk_std in grid:
        variant = dataclasses.replace(scenario, jerk_std=float(jerk_std))
        tracking = experiments.track(variant, sensors, runs=runs, noise=noise)
        innovations = tracking.innovations()
        nis_mean.append(metrics.nis_test(innovations, variant.burn_in_steps).mean)
        likelihood.append(metrics.innovation_log_likelihood(innovations,
                                                            variant.burn_in_steps))
        mse.append(tracking.mse())
    return JerkChoice(grid, np.array(nis_mean), np.stack(likelihood, axis=-1),
                      np.stack(mse, axis=-1), len(sensors))


def _short(array: np.ndarray) -> str:
    values = np.ravel(array)
    text = ", ".join(f"{v:g}" for v in values[:6])
    return f"[{text}{', …' if values.size > 6 else ''}] (shape {array.shape})"
