"""Checks of notebook 02's Going further tasks, each judged against the task's own inputs.

- :func:`check_flight_scales` (1): the error of the first guess and the squared scales of
  the flight, ``A²``, ``(Aω)²``, ``(Aω²)²``;
- :func:`check_first_gains` (2): the gains K₁ and K₂ of eq. (5) from each P0, by hand,
  against the pack's engine;
- :func:`check_overconfidence` (3): the Monte Carlo mean squared error over the filter's
  own variance, in the first second;
- :func:`check_convergence_intervals` (4): bootstrap 95 % intervals on the convergence
  times;
- :func:`check_p0_sweep` (5): MSEs and convergence times over a grid of P0 = p0 · I.

The core path's checks, and the engine's runs these share with them, are in
:mod:`lqe_helpers.checks.initial_covariance`.
"""

from __future__ import annotations

import numpy as np

from .. import experiments, metrics
from ..scenario import DEFAULT
from .initial_covariance import (
    P0_NAMES,
    QUESTION_P0,
    judge_seconds,
    question_runs,
    squared_errors,
)
from .judging import judge
from .machinery import (
    FUNCTION_RTOL,
    MATRIX_RTOL,
    MSE_RTOL,
    TIME_ATOL,
    CheckFailed,
    argument_array,
    passed,
    tolerance_text,
)
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: Tolerance (s) of the ends of a bootstrap interval of a convergence time: two samples.
#: Another generator seed moves the ends by at most one sample (20 seeds tried).
BOOTSTRAP_ATOL = 0.02

#: The grid of Going further 5: p0 in P0 = p0 · I (cm², cm²/s², cm²/s⁴), 2 per decade.
P0_GRID = np.logspace(-2, 6, 17)
P0_GRID.setflags(write=False)
#: The columns of :data:`P0_GRID` that :func:`check_p0_sweep` recomputes: both ends, the
#: question's two values and p0 = 10³ between them. All 17 would take the engine over a
#: second; every column comes out of the same student code, and the runs of these five
#: are the very runs of the whole grid (the noise of run r is the same for every p0).
SWEEP_CHECKED = (0, 4, 10, 14, 16)


# ------------------------------------------------------------------------------------------
# 1. The wrong first guess and the scales of the flight
# ------------------------------------------------------------------------------------------

def _scales(amplitude: float, omega: float) -> np.ndarray:
    return np.array([amplitude, amplitude * omega, amplitude * omega**2]) ** 2


def check_flight_scales(initial_error: np.ndarray, flight_scales: np.ndarray) -> None:
    """Check Going further 1: the first guess's error and the squared scales of the flight.

    Recomputed from the scenario: ``initial_error`` is the true state at t = 0 minus the
    guess z0 (cm, cm/s, cm/s²), ``flight_scales`` is ``[A², (Aω)², (Aω²)²]`` (cm², cm²/s²,
    cm²/s⁴) with A the amplitude and ω = 2π f. Each within :data:`MATRIX_RTOL` relative.

    Parameters
    ----------
    initial_error, flight_scales : array_like, shape (3,)
        The student's values.

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: the error the wrong way round or squared,
        ω in Hz or as 2π/f, the scales not squared, ω² where (Aω)² belongs, their order.
    """
    truth, z0 = DEFAULT.truth[0], np.asarray(DEFAULT.z0, dtype=float)
    judge("initial_error", initial_error, truth - z0, MATRIX_RTOL, unit="cm, cm/s, cm/s²",
          what="the true state at t = 0 minus the guess z0",
          mistakes={"it is the guess minus the true state; the error of the guess is the "
                    "true state minus the guess": z0 - truth,
                    "it is squared: keep the error itself, with its sign": (truth - z0) ** 2})
    amplitude, frequency = DEFAULT.amplitude, DEFAULT.frequency
    omega = 2 * np.pi * frequency
    right = _scales(amplitude, omega)
    judge("flight_scales", flight_scales, right, MATRIX_RTOL, unit="cm², cm²/s², cm²/s⁴",
          what="[A², (Aω)², (Aω²)²] of the scenario's flight",
          mistakes={
              "ω is in Hz (ω = f): the angular frequency is ω = 2π f in rad/s":
                  _scales(amplitude, frequency),
              "ω = 2π / f: f is a frequency, so ω = 2π f": _scales(amplitude,
                                                                   2 * np.pi / frequency),
              "the scales are not squared: P0 holds variances, so square A, Aω and Aω²":
                  np.sqrt(right),
              "only ω was squared (A ω² for the velocity): square the whole product, (Aω)²":
                  np.array([amplitude**2, amplitude * omega**2, amplitude * omega**4]),
              "the order is reversed: position first, then velocity, then acceleration":
                  right[::-1],
          })
    passed(f"initial_error and flight_scales = [A², (Aω)², (Aω²)²] match the scenario's flight "
           f"(A = {amplitude:g} cm, f = {frequency:g} Hz) to {tolerance_text(MATRIX_RTOL)} "
           f"relative")


# ------------------------------------------------------------------------------------------
# 2. The first two gains, by hand
# ------------------------------------------------------------------------------------------

def _engine_gains(P0: np.ndarray, *, A: np.ndarray | None = None, Q: np.ndarray | None = None,
                  R: np.ndarray | None = None) -> np.ndarray:
    """K₁ and K₂ (2, 3) from the pack's engine, with the model's A, Q or R replaced if given.

    The gains do not depend on the readings, so two zero readings give them. The likely
    mistakes come from the engine too: no readable eq. (5) in the package.
    """
    model = experiments.filter_model(DEFAULT)
    return experiments.FilterModel(
        model.A if A is None else A, model.C, model.Q if Q is None else Q,
        model.R if R is None else R, model.z0, P0).filter(np.zeros((2, 1))).gains[:, :, 0]


@remembered
def _gains() -> dict[str, object]:
    """The engine's K₁ and K₂ from both P0, shape (2 P0, 2 gains, 3), and the mistakes."""
    right = question_runs().result.gains[0, :, :2, :, 0]
    model = experiments.filter_model(DEFAULT)
    mistakes = []
    for index, p0 in enumerate(QUESTION_P0):
        P0 = p0 * np.eye(3)
        first = right[index, 0]
        # P₁ = A P0 Aᵀ + Q (no correction): its gain is the first gain of a filter from it.
        uncorrected = _engine_gains(model.A @ P0 @ model.A.T + model.Q)[0]
        mistakes.append({
            "K₂ was computed from P0 again: carry P to the next step with the last line of "
            "eq. (5) first": np.array([first, first]),
            "Q is missing from P₁ = A(P0 − K₁CP0)Aᵀ + Q": _engine_gains(P0, Q=np.zeros((3, 3))),
            "A is missing from P₁ = A(P0 − K₁CP0)Aᵀ + Q: the covariance must be carried "
            "through the motion model": _engine_gains(P0, A=np.eye(3)),
            "P₁ misses the correction −K₁CP0: P₁ = A(P0 − K₁CP0)Aᵀ + Q":
                np.array([first, uncorrected]),
            "R holds σ_v (cm) where its variance σ_v² (cm²) belongs":
                _engine_gains(P0, R=np.array([[DEFAULT.sigma_v]])),
        })
    return {"right": right, "mistakes": mistakes}


def check_first_gains(gains_small: np.ndarray, gains_large: np.ndarray) -> None:
    """Check Going further 2: the gains K₁ and K₂ of eq. (5) from P0 = diag(1) and diag(10⁵).

    Recomputed before looking at the student's values: the gains of the first two
    readings in the pack's engine (they do not depend on the readings), with the model
    of :func:`~lqe_helpers.experiments.filter_model`. Within :data:`FUNCTION_RTOL` of the
    largest gain.

    Parameters
    ----------
    gains_small, gains_large : array_like, shape (2, 3)
        Row 0 is K₁, row 1 is K₂, each [position (no unit), velocity (1/s),
        acceleration (1/s²)].

    Raises
    ------
    CheckFailed
        Naming the array and the likely cause: the two swapped, K₂ from P0 again, Q or A
        or the correction missing from P₁, R of σ_v instead of σ_v², transposed.
    """
    gains = _gains()
    given = {"gains_small": gains_small, "gains_large": gains_large}
    for index, (name, value) in enumerate(given.items()):
        array = argument_array(value, name, "an array of shape (2, 3): rows K₁ and K₂")
        if array.shape == (3, 2):
            raise CheckFailed(f"{name} has shape (3, 2): it is transposed. Row 0 is K₁ and "
                              f"row 1 is K₂, each with the 3 gains of p, v and a")
        if array.shape == (2, 3, 1):
            raise CheckFailed(f"{name} has shape (2, 3, 1): each K is a 3 × 1 column; keep "
                              f"its 3 entries as a row (K[:, 0]), so {name} is (2, 3)")
        other = 1 - index
        judge(name, array, gains["right"][index], FUNCTION_RTOL,
              what=f"K₁ and K₂ of the pack's engine from P0 = {P0_NAMES[index]}",
              mistakes={f"it holds the gains from P0 = {P0_NAMES[other]}: {name} starts "
                        f"from P0 = {P0_NAMES[index]}": gains["right"][other],
                        **gains["mistakes"][index]})
    passed(f"gains_small and gains_large match K₁ and K₂ of the pack's engine from P0 = "
           f"{P0_NAMES[0]} and {P0_NAMES[1]} to {tolerance_text(FUNCTION_RTOL)} of the "
           f"largest gain")


# ------------------------------------------------------------------------------------------
# 3. Overconfidence: the actual error over the filter's own variance
# ------------------------------------------------------------------------------------------

@remembered
def _overconfidence() -> dict[str, np.ndarray]:
    """The right ratio (2, burn) and the ratios of the likely mistakes."""
    burn = DEFAULT.burn_in_steps
    runs = question_runs()
    squared = squared_errors()[..., :burn]
    mean = squared.mean(axis=0)
    own = runs.position_variances[0, :, :burn]
    prior = runs.result.covariances[0, :, :burn, 0, 0]
    right = mean / own
    return {"right": right, "mistakes": {
        "it is the other way round: the filter's own variance over its actual mean squared "
        "error. The task divides the error by the variance": own / mean,
        "it divides by the standard deviation (the root of the variance): divide the mean "
        "squared error by the variance itself": mean / np.sqrt(own),
        "it is the ratio of the roots (RMSE over the standard deviation): the task divides "
        "the mean squared error by the variance": np.sqrt(right),
        "it uses the squared error of one run (run 0), not the Monte Carlo mean over the "
        "runs": squared[0] / own,
        "it divides by the variance of the prediction (result.covariances, before the "
        "reading); the filter's variance of its estimate is position_variances":
            mean / prior,
        "the rows are swapped: row 0 is P0 = diag(1), row 1 is diag(1e5)": right[::-1],
    }}


def check_overconfidence(overconfidence: np.ndarray) -> None:
    """Check Going further 3: mean squared error over the filter's own variance, first second.

    Recomputed before looking at the student's values: the runs of the core path's Task
    2, the Monte Carlo mean of the squared position error over the samples before
    ``DEFAULT.burn_in_steps``, divided by the filter's own variance of its position
    estimate (:attr:`~lqe_helpers.experiments.Tracking.position_variances`), for each P0.
    Within :data:`MSE_RTOL` of the largest ratio.

    Parameters
    ----------
    overconfidence : array_like, shape (2, burn_in)
        Row 0 from P0 = diag(1), row 1 from diag(10⁵).

    Raises
    ------
    CheckFailed
        With the likely cause: the ratio inverted, the standard deviation or the RMSE,
        one run instead of the mean, the prediction's variance, the whole trial, the rows
        swapped.
    """
    right = _overconfidence()
    burn, n = DEFAULT.burn_in_steps, DEFAULT.n_steps
    array = argument_array(overconfidence, "overconfidence",
                           f"an array of shape (2, {burn}): one row per P0")
    if array.shape == (2, n):
        raise CheckFailed(f"overconfidence covers the whole trial ({n} samples): keep the "
                          f"first second, the {burn} samples before burn_in")
    if array.shape == (burn, 2):
        raise CheckFailed(f"overconfidence has shape ({burn}, 2): it is transposed. One row "
                          f"per P0, one column per sample, shape (2, {burn})")
    judge("overconfidence", array, right["right"], MSE_RTOL,
          what="the Monte Carlo mean squared error over the filter's own variance",
          mistakes=right["mistakes"])
    passed(f"overconfidence matches the Monte Carlo mean squared error over the filter's own "
           f"position variance, in the first {burn} samples from both P0, recomputed with the "
           f"pack's engine, to {tolerance_text(MSE_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# 4. Bootstrap intervals on the convergence times
# ------------------------------------------------------------------------------------------

@remembered
def _intervals() -> dict[str, object]:
    """The right intervals (a generator seeded with DEFAULT.seed, used for both in turn)."""
    squared, dt = squared_errors(), DEFAULT.dt
    rng = np.random.default_rng(DEFAULT.seed)
    right = [metrics.convergence_time_ci95(squared[:, i], dt, rng) for i in range(2)]
    per_run = metrics.convergence_time(np.moveaxis(squared, 1, 0), dt)   # (2, runs)
    mistakes = []
    for index in range(2):
        mistakes.append({
            f"it is the interval from P0 = {P0_NAMES[1 - index]}": right[1 - index],
            "it is the interval of the runs' own convergence times (metrics.mean_ci95); the "
            "convergence time belongs to the Monte Carlo mean curve, and its interval comes "
            "from resampling the runs (metrics.convergence_time_ci95)":
                metrics.mean_ci95(per_run[index]),
        })
    return {"right": right, "mistakes": mistakes, "runs": squared.shape[0]}


def _interval_numbers(name: str, interval: object) -> np.ndarray:
    """``[mean, low, high]`` of the student's interval, or CheckFailed naming it."""
    if not all(hasattr(interval, part) for part in ("mean", "low", "high")):
        found = "None" if interval is None else f"a {type(interval).__name__}"
        raise CheckFailed(f"{name} is {found}; it must be the metrics.Interval that "
                          f"metrics.convergence_time_ci95 returns")
    return np.array([float(argument_array(getattr(interval, part), f"{name}.{part}",
                                          "one number of seconds", shape=()))
                     for part in ("mean", "low", "high")])


def check_convergence_intervals(convergence_small: metrics.Interval,
                                convergence_large: metrics.Interval) -> None:
    """Check Going further 4: bootstrap 95 % intervals on the two convergence times.

    Recomputed before looking at the student's intervals:
    :func:`metrics.convergence_time_ci95` of each P0's squared errors over the runs of
    the core path's Task 2. The convergence time itself must agree within
    :data:`TIME_ATOL` s; the ends, which depend on the random resampling, within
    :data:`BOOTSTRAP_ATOL` s (any generator seed passes).

    Parameters
    ----------
    convergence_small, convergence_large : metrics.Interval
        The student's intervals (s), from P0 = diag(1) and diag(10⁵).

    Raises
    ------
    CheckFailed
        Naming the interval and the likely cause: the two swapped, samples instead of
        seconds, the squared errors transposed, the interval of per-run times.
    """
    right = _intervals()
    runs = right["runs"]

    def near(a: np.ndarray, b: np.ndarray) -> bool:
        return bool(abs(a[0] - b[0]) <= TIME_ATOL and np.all(np.abs(a[1:] - b[1:])
                                                              <= BOOTSTRAP_ATOL))

    for index, (name, interval) in enumerate((("convergence_small", convergence_small),
                                              ("convergence_large", convergence_large))):
        got = _interval_numbers(name, interval)
        if getattr(interval, "runs", runs) == DEFAULT.n_steps and runs != DEFAULT.n_steps:
            raise CheckFailed(
                f"{name} resampled {DEFAULT.n_steps} 'runs': the squared errors were "
                f"transposed. Pass shape (runs, n), one row per run: squared_error[:, "
                f"{index}]")
        expected = right["right"][index]
        as_numbers = np.array([expected.mean, expected.low, expected.high])
        if near(got, as_numbers):
            continue
        if near(got * DEFAULT.dt, as_numbers):
            raise CheckFailed(f"{name} is not right: it is in samples (dt was given as 1): "
                              f"pass DEFAULT.dt = {DEFAULT.dt:g} s")
        for cause, wrong in right["mistakes"][index].items():
            wrong = np.array([wrong.mean, wrong.low, wrong.high])
            if not near(wrong, as_numbers) and near(got, wrong):
                raise CheckFailed(f"{name} is not right: {cause}")
        if abs(got[0] - as_numbers[0]) <= TIME_ATOL:
            raise CheckFailed(
                f"{name}: the convergence time ({got[0]:g} s) is right, but the interval's "
                f"ends ({got[1]:g} to {got[2]:g} s) are not those of a bootstrap of the runs "
                f"(metrics.convergence_time_ci95), even allowing {BOOTSTRAP_ATOL:g} s for "
                f"the random resampling")
        raise CheckFailed(
            f"{name} (convergence time {got[0]:g} s) does not match the bootstrap interval "
            f"of the Monte Carlo mean from P0 = {P0_NAMES[index]}, and not by one of the "
            f"usual mistakes")
    passed(f"convergence_small and convergence_large match bootstrap intervals of the "
           f"convergence times from P0 = {P0_NAMES[0]} and {P0_NAMES[1]} ({runs} runs): the "
           f"time to {tolerance_text(TIME_ATOL)} s, the ends to {BOOTSTRAP_ATOL:g} s")


# ------------------------------------------------------------------------------------------
# 5. The sweep over P0
# ------------------------------------------------------------------------------------------

@remembered
def _sweep() -> dict[str, object]:
    """MSEs (runs, 5) and convergence times (5,) at :data:`SWEEP_CHECKED`, and the mistakes."""
    sweep = experiments.track(DEFAULT, p0_variance=P0_GRID[list(SWEEP_CHECKED)],
                              runs=DEFAULT.mc_runs)
    burn, dt = DEFAULT.burn_in_steps, DEFAULT.dt
    squared = (sweep.positions - DEFAULT.truth[:, 0]) ** 2          # (runs, s, n)
    start, after = squared[..., :burn].mean(-1), squared[..., burn:].mean(-1)
    whole = squared.mean(-1)
    times = metrics.convergence_time(squared.mean(axis=0), dt)
    per_run = metrics.convergence_time(squared, dt)                 # (runs, s)
    return {
        "start": start, "after": after, "times": times,
        "start_mistakes": {
            "it is over the whole trial: keep only the first second (the samples before "
            "burn_in)": whole,
            "it is the MSE after the first second; sweep_start is over the first second":
                after,
            "it is the root mean squared error (cm): the MSE is its square": np.sqrt(start),
            f"it covers only the first sample: the first second is {burn} samples":
                squared[..., 0],
        },
        "after_mistakes": {
            "it is over the whole trial: leave out the first second (the samples before "
            "burn_in)": whole,
            "it is the MSE over the first second; sweep_after is after it": start,
            "it is the root mean squared error (cm): the MSE is its square": np.sqrt(after),
            f"it leaves out only the first sample: the first second is {burn} samples":
                squared[..., 1:].mean(-1),
        },
        "time_mistakes": {
            f"the times are in samples: give them in seconds, samples × Δt (Δt = {dt:g} s)":
                times / dt,
            "they are the convergence times of one run (run 0), not of the Monte Carlo "
            "mean curve": per_run[0],
            "they are the means of the runs' convergence times; the definition averages the "
            "squared errors over the runs first": per_run.mean(axis=0),
            "the errors were averaged over the runs before squaring: square each run's "
            "error first, then average": metrics.convergence_time(
                (sweep.positions - DEFAULT.truth[:, 0]).mean(axis=0) ** 2, dt),
        },
    }


def check_p0_sweep(sweep_start: np.ndarray, sweep_after: np.ndarray,
                   sweep_times: np.ndarray) -> None:
    """Check Going further 5: MSEs and convergence times over the grid of p0.

    Recomputed before looking at the student's values, at the five values of p0 in
    :data:`SWEEP_CHECKED` (the grid's ends, the question's two values, p0 = 10³):
    ``DEFAULT.mc_runs`` runs from P0 = p0 · I (:func:`~lqe_helpers.experiments.track`),
    each run's position MSE over the first second and after it (within :data:`MSE_RTOL`
    relative), and the convergence time of the Monte Carlo mean squared error (within
    :data:`TIME_ATOL` s). The arrays must have the whole grid's shape.

    Parameters
    ----------
    sweep_start, sweep_after : array_like, shape (runs, 17)
        Per-run MSEs (cm²) over the first second and after it, one column per p0.
    sweep_times : array_like, shape (17,)
        Convergence times (s), one per p0.

    Raises
    ------
    CheckFailed
        Naming the array and the likely cause: transposed, means instead of per-run
        values, the windows swapped or the whole trial, the RMSE, times in samples, of
        one run or averaged over runs.
    """
    right = _sweep()
    runs, size = right["start"].shape[0], P0_GRID.size
    columns = list(SWEEP_CHECKED)
    at = "at p0 = " + ", ".join(f"{p0:g}" for p0 in P0_GRID[columns])
    for name, value, key in (("sweep_start", sweep_start, "start"),
                             ("sweep_after", sweep_after, "after")):
        array = argument_array(value, name, f"an array of shape ({runs}, {size}) (cm²)")
        if array.shape == (size, runs):
            raise CheckFailed(f"{name} has shape ({size}, {runs}): it is transposed. One "
                              f"row per run, one column per p0: shape ({runs}, {size})")
        if array.shape == (size,):
            raise CheckFailed(f"{name} holds one number per p0 (the mean over the runs?). "
                              f"Keep one MSE per run, shape ({runs}, {size}): the intervals "
                              f"and the paired comparisons need them")
        if array.shape != (runs, size):
            raise CheckFailed(f"{name} must have shape ({runs}, {size}) (one row per run, one "
                              f"column per p0), got {array.shape}")
        judge(f"{name} ({at})", array[:, columns], right[key], MSE_RTOL, unit="cm²",
              what=f"the per-run MSEs {'over' if key == 'start' else 'after'} the first "
                   f"second, recomputed with the pack's engine",
              mistakes=right[f"{key}_mistakes"])
    times = argument_array(sweep_times, "sweep_times", f"an array of shape ({size},) (s)")
    if times.shape != (size,):
        raise CheckFailed(f"sweep_times must have shape ({size},), one time per p0, got "
                          f"{times.shape}")
    judge_seconds(f"sweep_times ({at})", times[columns], right["times"],
                  right["time_mistakes"], "the convergence times of the Monte Carlo mean")
    passed(f"sweep_start, sweep_after and sweep_times have the grid's shape and match "
           f"{runs} runs of the pack's engine {at}: MSEs to {tolerance_text(MSE_RTOL)} "
           f"relative, times to {tolerance_text(TIME_ATOL)} s")
