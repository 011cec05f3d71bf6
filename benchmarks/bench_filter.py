"""Speed of lqe_helpers.filter.kalman_filter against filterpy, measured in one process.

Run: ``.venv/bin/python benchmarks/bench_filter.py`` (or ``make bench``). Prints the
median time of each contender and their ratio; the ratios, not the seconds, are what
carry over between machines. Targets: single run >= 2x, sweep >= 200x, estimates
identical to 1e-9 cm. Both sides keep the same things per step (estimate, gain and
covariance), so neither is timed doing less work; the gains and covariances are
compared too. Exits with 1 if the estimates miss their target (the speed targets
depend on the machine and are only reported).
"""

from __future__ import annotations

import statistics
import sys
import time
from collections.abc import Callable

import numpy as np
from filterpy.kalman import KalmanFilter

from lqe_helpers import experiments, model
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT

SENSORS = ("vision", "proprioception")
RUNS = 300
REPEATS = 7
#: Largest allowed difference between our estimates and filterpy's (cm).
ESTIMATE_TOLERANCE_CM = 1e-9


def filterpy_run(y: np.ndarray, A, C, Q, R, z0, P0
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tutorial eq. (5) with filterpy, keeping what ``kalman_filter`` returns.

    Returns
    -------
    estimates, gains, covariances : ndarray, shapes (n, k), (n, k, m), (n, k, k)
        As ``FilterResult.estimates``, ``.gains`` and ``.covariances`` (the
        covariance of the one-step prediction after each measurement).
    """
    kf = KalmanFilter(dim_x=A.shape[0], dim_z=C.shape[0])
    kf.F, kf.H, kf.Q, kf.R = A, C, Q, R
    kf.x, kf.P = A @ z0, P0.copy()
    estimates, gains, covariances = [], [], []
    for y_j in y:
        kf.update(y_j)
        estimates.append(kf.x.copy())
        gains.append(kf.K.copy())
        kf.predict()
        covariances.append(kf.P.copy())
    return np.array(estimates), np.array(gains), np.array(covariances)


def worst_relative(ours: np.ndarray, theirs: np.ndarray) -> float:
    """Largest difference relative to the largest magnitude of ``theirs``."""
    return float(np.max(np.abs(ours - theirs)) / np.max(np.abs(theirs)))


def median_seconds(call: Callable[[], object], repeats: int) -> float:
    """Median wall time of ``repeats`` calls, after one warm-up call."""
    call()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> int:
    scenario = DEFAULT
    model_args = (scenario.A, model.observation_matrix(SENSORS), scenario.Q,
                  model.measurement_noise_covariance([scenario.sigma_v, scenario.sigma_p]),
                  np.asarray(scenario.z0, float), scenario.P0)
    y_batch = experiments.track(scenario, sensors=SENSORS, runs=RUNS).measurements
    y_single = y_batch[0]

    ours = kalman_filter(y_batch[:20], *model_args)
    runs = [filterpy_run(y, *model_args) for y in y_batch[:20]]
    estimates, gains, covariances = (np.stack(parts) for parts in zip(*runs, strict=True))
    worst = float(np.max(np.abs(ours.estimates - estimates)))
    worst_gain = worst_relative(ours.gains, gains)
    worst_covariance = worst_relative(ours.covariances, covariances)

    single_ours = median_seconds(lambda: kalman_filter(y_single, *model_args), REPEATS)
    single_theirs = median_seconds(lambda: filterpy_run(y_single, *model_args), REPEATS)
    sweep_ours = median_seconds(lambda: kalman_filter(y_batch, *model_args), REPEATS)
    # filterpy has no batch axis: its sweep is a Python loop over the runs, timed once
    # (about 10 s; its per-run cost is the single-run figure above, already warmed up).
    start = time.perf_counter()
    for y in y_batch:
        filterpy_run(y, *model_args)
    sweep_theirs = time.perf_counter() - start

    n = scenario.n_steps
    print(f"kalman_filter vs filterpy {__import__('filterpy').__version__}, two sensors, "
          f"{n} steps")
    print(f"  single run      : ours {single_ours * 1e3:7.2f} ms, filterpy "
          f"{single_theirs * 1e3:7.2f} ms -> {single_theirs / single_ours:6.1f}x  (target >= 2x)")
    print(f"  {RUNS} runs sweep  : ours {sweep_ours * 1e3:7.2f} ms, filterpy "
          f"{sweep_theirs * 1e3:7.0f} ms -> {sweep_theirs / sweep_ours:6.0f}x  (target >= 200x)")
    print(f"  max |estimate difference| over 20 runs: {worst:.1e} cm  (target <= 1e-9)")
    print(f"  gains and covariances agree to {max(worst_gain, worst_covariance):.1e} "
          f"of their largest entry")
    if not worst <= ESTIMATE_TOLERANCE_CM:
        print(f"error: the estimates differ from filterpy's by {worst:.1e} cm, more than "
              "1e-9 cm", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
