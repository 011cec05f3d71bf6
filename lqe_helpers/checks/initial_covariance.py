"""Checks of notebook 02, question (b): the initial covariance P0 and the start-up it shapes.

The core path's tasks, each judged against the pack's engine on the task's own draw:

- :func:`check_start_of_trial` (Task 1): ``P0_small = diag(1, 1, 1)`` and
  ``P0_large = diag(10⁵, 10⁵, 10⁵)``, variances on the diagonal, and the student's
  ``my_filter`` run on one trial from each, against
  :meth:`~lqe_helpers.experiments.FilterModel.filter` on the scenario's draw;
- :func:`check_convergence_times` (Task 2): the convergence time of the Monte Carlo
  mean squared error from each P0, recomputed with :func:`~lqe_helpers.experiments.track`;
- :func:`check_start_and_after` (Task 3): the paired differences diag(1) − diag(10⁵) of
  the MSE over the first second and after it.

:func:`check_initial_covariance` checks one matrix against one variance. The checks of
the Going further tasks are in :mod:`lqe_helpers.checks.initial_covariance_further`.
"""

from __future__ import annotations

import numpy as np

from .. import experiments, metrics
from ..scenario import DEFAULT
from .convergence_slips import BAND_FACTOR, OTHER_FACTORS, crossing_times, wrong_axis_times
from .judging import (
    CM_PER_M,
    burn_in_slips,
    judge,
    judge_interval,
    judge_seconds,
    judge_seconds_together,
)
from .machinery import (
    FUNCTION_RTOL,
    INTERVAL_RTOL,
    MATRIX_RTOL,
    TIME_ATOL,
    CheckFailed,
    argument_array,
    passed,
    positive_number,
    tolerance_text,
)
from .paired_mistakes import (
    OWN_READINGS,
    TRIAL_READINGS,
    interval_mistakes,
    unit_mistakes,
)
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: The question's two initial variances p0 in P0 = p0 · I (cm², cm²/s², cm²/s⁴), in the
#: order of the tasks: the confident start first.
QUESTION_P0 = (1.0, 1e5)
#: How the messages name them.
P0_NAMES = ("diag(1)", "diag(1e5)")
#: The students' names of the task's two values, in the order of :data:`QUESTION_P0`.
_SMALL_LARGE = ("small", "large")


# ------------------------------------------------------------------------------------------
# The engine's runs of the task's draw, computed once
# ------------------------------------------------------------------------------------------

@remembered
def question_runs() -> experiments.Tracking:
    """``DEFAULT.mc_runs`` runs from both P0 of the question (axis 1), on the task's draws."""
    return experiments.track(DEFAULT, p0_variance=list(QUESTION_P0), runs=DEFAULT.mc_runs)


@remembered
def squared_errors() -> np.ndarray:
    """Squared position errors (cm²) of :func:`question_runs`, shape (runs, 2, n), read-only."""
    values = (question_runs().positions - DEFAULT.truth[:, 0]) ** 2
    values.setflags(write=False)
    return values


# ------------------------------------------------------------------------------------------
# Task 1: the two initial covariances (judged with the start of one trial)
# ------------------------------------------------------------------------------------------

def _p0_problem(P0: object, variance: float, name: str) -> str | None:
    """Why ``P0`` is not ``variance · I₃`` (a sentence about ``name``), or None if it is."""
    P0 = argument_array(P0, name, "the initial covariance, a 3 × 3 matrix (cm², cm²/s², "
                                  "cm²/s⁴)")
    if P0.ndim == 0:
        return (f"{name} is a single number ({float(P0):g}). The filter needs a 3 × 3 matrix, "
                f"one row and column per state (p, v, a), with the variances on its diagonal")
    if P0.shape == (3,):
        return (f"{name} is a vector of 3 numbers. It must be a 3 × 3 matrix with these "
                f"variances on its diagonal and 0 elsewhere")
    if P0.shape != (3, 3):
        return (f"{name} must be 3 × 3 (one row and column per state p, v, a), got shape "
                f"{P0.shape}")
    if np.any(P0 - np.diag(np.diag(P0)) != 0):
        if np.allclose(P0, variance, rtol=MATRIX_RTOL, atol=0):
            return (f"every entry of {name} is {variance:g}. Only the diagonal holds the "
                    f"variances; the off-diagonal entries (covariances between p, v and a) "
                    f"are 0")
        return (f"{name} has non-zero off-diagonal entries; diag(…) means the variances on "
                f"the diagonal and 0 everywhere else")
    diagonal = np.diag(P0)

    def same(value: float) -> bool:
        return bool(np.allclose(diagonal, value, rtol=MATRIX_RTOL, atol=0))

    if same(variance):
        return None
    if same(np.sqrt(variance)):
        return (f"{name}'s diagonal holds √{variance:g} = {np.sqrt(variance):g}, a standard "
                f"deviation. P0 is a covariance: its diagonal holds the variance, {variance:g}")
    if same(variance**2):
        return (f"{name}'s diagonal holds {variance:g}² = {variance**2:g}: the variance was "
                f"squared again. The diagonal holds the variance itself, {variance:g}")
    if not np.allclose(diagonal, diagonal[0], rtol=MATRIX_RTOL, atol=0):
        return (f"{name}'s diagonal entries differ ({diagonal.tolist()}); diag({variance:g}, "
                f"{variance:g}, {variance:g}) has the same variance for each state")
    return f"{name}'s diagonal holds {diagonal[0]:g}, expected the variance {variance:g}"


def check_initial_covariance(P0: np.ndarray, variance: float) -> None:
    """Check that ``P0 = variance · I₃`` (cm², cm²/s², cm²/s⁴ on the diagonal).

    The tutorial writes the initial covariance as ``P0 = diag(10⁵, 10⁵, 10⁵) cm²``:
    a 3 × 3 diagonal matrix of variances. Tolerance :data:`MATRIX_RTOL` relative.

    Parameters
    ----------
    P0 : array_like, shape (3, 3)
        The student's initial covariance.
    variance : float
        The variance the question sets (cm²), e.g. 1 or 10⁵, > 0.

    Raises
    ------
    CheckFailed
        For a single number, a vector, a wrong size, off-diagonal entries, standard
        deviations instead of variances, or other diagonal values.
    """
    variance = positive_number(variance, "variance", "cm²")
    problem = _p0_problem(P0, variance, "P0")
    if problem is not None:
        raise CheckFailed(problem)
    passed(f"P0 = {variance:g} · I (3 × 3, diagonal) cm²")


def _judge_covariances(P0_small: object, P0_large: object) -> None:
    """CheckFailed unless ``P0_small = diag(1, 1, 1)`` and ``P0_large = diag(10⁵, 10⁵, 10⁵)``.

    Names the matrix: the two swapped, a single number, a vector, a wrong size,
    off-diagonal entries, standard deviations instead of variances, other values.
    """
    given = {"P0_small": P0_small, "P0_large": P0_large}
    for index, (name, P0) in enumerate(given.items()):
        variance, other = QUESTION_P0[index], QUESTION_P0[1 - index]
        problem = _p0_problem(P0, variance, name)
        if problem is None:
            continue
        if _p0_problem(P0, other, name) is None:
            partner = list(given)[1 - index]
            swapped = _p0_problem(given[partner], variance, partner) is None
            raise CheckFailed(
                f"{name} is diag({other:g}, {other:g}, {other:g}), the other start"
                + (f": {name} and {partner} are swapped" if swapped else "")
                + f". {name} is the {'confident' if index == 0 else 'uncertain'} start, "
                  f"diag({variance:g}, {variance:g}, {variance:g})")
        raise CheckFailed(problem)


# ------------------------------------------------------------------------------------------
# Task 1: one trial, the student's filter from each P0
# ------------------------------------------------------------------------------------------

def _trial_estimates(p0_variance: float, *, z0: np.ndarray | None = None,
                     r_variance: float | None = None, y_divisor: float = 1.0) -> np.ndarray:
    """The engine's estimates (n, 3) of the task's trial, with one input changed or none."""
    vision = experiments.filter_model(DEFAULT, p0_variance=p0_variance)
    y = experiments.track(DEFAULT).measurements / y_divisor
    R = vision.R if r_variance is None else np.array([[r_variance]])
    start = vision.z0 if z0 is None else z0
    return experiments.FilterModel(vision.A, vision.C, vision.Q, R, start,
                                   vision.P0).filter(y).estimates


@remembered
def _trial() -> dict[str, np.ndarray]:
    """The right estimates of Task 1 and the likely mistakes, each (n, 3)."""
    right = {name: _trial_estimates(p0) for name, p0 in zip(_SMALL_LARGE, QUESTION_P0,
                                                               strict=True)}
    sigma_v = DEFAULT.sigma_v
    return {
        **right,
        **{f"true_start_{name}": _trial_estimates(p0, z0=DEFAULT.truth[0])
           for name, p0 in zip(_SMALL_LARGE, QUESTION_P0, strict=True)},
        **{f"r_sigma_{name}": _trial_estimates(p0, r_variance=sigma_v)
           for name, p0 in zip(_SMALL_LARGE, QUESTION_P0, strict=True)},
        **{f"std_{name}": _trial_estimates(np.sqrt(p0))
           for name, p0 in zip(_SMALL_LARGE, QUESTION_P0, strict=True)},
        **{f"metres_{name}": _trial_estimates(p0, y_divisor=CM_PER_M)
           for name, p0 in zip(_SMALL_LARGE, QUESTION_P0, strict=True)},
    }


def check_start_of_trial(P0_small: np.ndarray, P0_large: np.ndarray,
                         estimates_small: np.ndarray, estimates_large: np.ndarray) -> None:
    """Check Task 1: both P0, and the student's filter on one trial from each.

    First ``P0_small = diag(1, 1, 1)`` and ``P0_large = diag(10⁵, 10⁵, 10⁵)``: 3 × 3
    diagonal matrices of the question's variance (cm², cm²/s², cm²/s⁴), within
    :data:`MATRIX_RTOL` relative. Then the estimates, recomputed before looking at
    them: the scenario's trial of vision at σ_v (``experiments.track(DEFAULT)``)
    filtered by the pack's engine with the model of
    :func:`~lqe_helpers.experiments.filter_model` and each P0. Every estimate must agree
    within :data:`FUNCTION_RTOL` of the largest one, as ``check_filter`` of notebook 01
    asks of ``my_filter``.

    Parameters
    ----------
    P0_small, P0_large : array_like, shape (3, 3)
        The student's initial covariances: the confident and the uncertain start.
    estimates_small, estimates_large : array_like, shape (n, 3)
        The student's estimates (position cm, velocity cm/s, acceleration cm/s²) after
        each reading, from P0 = diag(1) and from P0 = diag(10⁵).

    Raises
    ------
    CheckFailed
        Naming the matrix or array and the likely cause: the two P0 swapped, a single
        number, a vector, off-diagonal entries, standard deviations instead of
        variances; the runs swapped or both from one P0, positions only, the filter
        started from the true state, R of σ_v instead of σ_v², a filter that no longer
        follows eq. (5).
    """
    _judge_covariances(P0_small, P0_large)
    runs = _trial()
    n = DEFAULT.n_steps
    given = {"estimates_small": estimates_small, "estimates_large": estimates_large}
    for index, (name, value) in enumerate(given.items()):
        this, other = _SMALL_LARGE[index], _SMALL_LARGE[1 - index]
        array = argument_array(value, name, f"the estimates, an array of shape ({n}, 3)")
        if array.shape == (n,):
            raise CheckFailed(
                f"{name} holds one number per reading (the positions only?). Keep all "
                f"three states, shape ({n}, 3): Figure 1 draws the velocity too")
        if array.shape == (n + 1, 3):
            raise CheckFailed(
                f"{name} has {n + 1} rows for {n} readings: row j is the estimate after "
                f"reading j, and z0 is not one of them")
        judge(name, array, runs[this], FUNCTION_RTOL,
              what=f"the pack's engine on this trial from P0 = {P0_NAMES[index]}",
              hint="if you changed my_filter since notebook 01, run its check there again",
              mistakes={
                  f"it is the run from P0_{other}, {P0_NAMES[1 - index]}: {name} starts "
                  f"from P0_{this}": runs[other],
                  "the filter started from the butterfly's true state; the question starts "
                  "from the guess z0 = [0, 0, 0] (at rest in the centre)":
                      runs[f"true_start_{this}"],
                  "R holds σ_v (cm) where its variance σ_v² (cm²) belongs":
                      runs[f"r_sigma_{this}"],
                  "P0 held standard deviations (√p0) on its diagonal, not variances":
                      runs[f"std_{this}"],
                  "the readings are in metres (y divided by 100) while R, Q and P0 are in cm: "
                  "give my_filter the readings y as they are, in cm": runs[f"metres_{this}"],
              })
    passed(f"P0_small = {QUESTION_P0[0]:g} · I and P0_large = {QUESTION_P0[1]:g} · I (3 × 3, "
           f"variances on the diagonal, to {tolerance_text(MATRIX_RTOL)} relative); "
           f"estimates_small and estimates_large match the pack's engine on this trial from "
           f"each ({n} readings × 3 states) to {tolerance_text(FUNCTION_RTOL)} of the largest "
           f"estimate")


# ------------------------------------------------------------------------------------------
# Task 2: convergence times of the Monte Carlo mean
# ------------------------------------------------------------------------------------------

def squared_against_readings(trial: bool = False) -> np.ndarray:
    """Task 2's squared position errors taken against the readings instead of the truth
    (cm²), shape (runs, 2, n): each run's own readings, or (``trial``) the one trial's y."""
    runs = question_runs()
    readings = runs.measurements[..., 0]          # (runs, 1, n): the same for both P0
    return (runs.positions - (readings[0] if trial else readings)) ** 2


@remembered
def _convergence() -> dict[str, object]:
    """The right convergence times of Task 2 (s) and their likely mistakes, by P0."""
    squared, dt = squared_errors(), DEFAULT.dt
    runs = question_runs()
    error = runs.positions - DEFAULT.truth[:, 0]
    curves = squared.mean(axis=0)
    medians = np.median(squared, axis=0)
    readings_curves = {"each run's readings": squared_against_readings().mean(axis=0),
                       "the one trial's readings y": squared_against_readings(True).mean(axis=0)}
    right = metrics.convergence_time(curves, dt)
    per_run = metrics.convergence_time(np.moveaxis(squared, 1, 0), dt)     # (2, runs)
    axes = wrong_axis_times(squared, dt)
    mistakes = []
    for index in range(len(QUESTION_P0)):
        other = 1 - index
        mistakes.append({
            f"it is the convergence time from P0_{_SMALL_LARGE[other]}, {P0_NAMES[other]}":
                float(right[other]),
            **crossing_times(curves[index], dt),
            **axes[index],
            "it is the convergence time of a single run (run 0). The definition applies to "
            "the Monte Carlo mean: average the squared errors over the runs first":
                float(per_run[index, 0]),
            "it is the mean of the runs' convergence times. The definition averages the "
            "squared errors over the runs first, then takes one convergence time":
                float(per_run[index].mean()),
            "the errors were averaged over the runs before squaring (the squared mean "
            "error): square each run's error first, then average":
                float(metrics.convergence_time(error[:, index].mean(axis=0) ** 2, dt)),
            "the curve is the mean absolute error (cm); the definition uses the mean "
            "squared error (cm²)":
                float(metrics.convergence_time(np.abs(error[:, index]).mean(axis=0), dt)),
            "the curve is the root of the mean squared error (cm); the definition uses the "
            "mean squared error itself (cm²)":
                float(metrics.convergence_time(np.sqrt(curves[index]), dt)),
            "the curve is the filter's own variance of its position, not its actual "
            "squared error": float(metrics.convergence_time(runs.position_variances[0, index],
                                                            dt)),
            **{f"the errors are taken against {which}, not the truth: an estimate's error is "
               f"estimate − true position (truth[:, 0])":
                   float(metrics.convergence_time(curve[index], dt))
               for which, curve in readings_curves.items()},
            "the curve is the median of the squared errors over the runs; the definition "
            "uses their mean (the Monte Carlo mean)":
                float(metrics.convergence_time(medians[index], dt)),
            **{f"the band is {factor:g} × the steady level; the definition's band is "
               f"{BAND_FACTOR:g} × (metrics.convergence_time's factor, left at its default)":
                   float(metrics.convergence_time(curves[index], dt, factor))
               for factor in OTHER_FACTORS},
        })
    return {"right": right, "mistakes": mistakes, "runs": squared.shape[0]}


def check_convergence_times(t_small: float, t_large: float) -> None:
    """Check Task 2: the convergence times (s) from P0 = diag(1) and diag(10⁵).

    Recomputed before looking at the student's values: ``DEFAULT.mc_runs`` runs from
    both P0 on the task's draws (:func:`~lqe_helpers.experiments.track`), the mean over
    the runs of the squared position error, and :func:`metrics.convergence_time` of
    each mean curve (the first time after which it stays within 2 × its mean over the
    second half of the trial). Each time must agree within :data:`TIME_ATOL` s (times
    are whole numbers of samples).

    Parameters
    ----------
    t_small, t_large : float
        The student's convergence times (s), from P0 = diag(1) and from diag(10⁵).

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: the two swapped, samples or milliseconds
        instead of seconds, one run or the mean of per-run times instead of the Monte
        Carlo mean, the errors averaged before squaring, the first entry into the band,
        another steady level, one time per run, ...
    """
    right = _convergence()
    given = {}
    for name, value in (("t_small", t_small), ("t_large", t_large)):
        got = argument_array(value, name, "one number of seconds", allow_nan=True)
        if got.shape == (right["runs"],):
            raise CheckFailed(
                f"{name} holds one convergence time per run ({got.size} values). The "
                f"definition applies to the Monte Carlo mean: average the squared errors "
                f"over the runs first, then take one convergence time of that mean curve")
        given[name] = got
    judge_seconds_together(given, right["right"], right["mistakes"])
    for index, (name, got) in enumerate(given.items()):
        judge_seconds(name, got, float(right["right"][index]), right["mistakes"][index],
                       f"the convergence time of the Monte Carlo mean squared error from "
                       f"P0 = {P0_NAMES[index]}")
    passed(f"t_small and t_large match the convergence times of the Monte Carlo mean squared "
           f"error over {right['runs']} runs from P0 = {P0_NAMES[0]} and {P0_NAMES[1]} (first "
           f"time after which it stays within 2 × its second-half level), recomputed with the "
           f"pack's engine, to {tolerance_text(TIME_ATOL)} s")


# ------------------------------------------------------------------------------------------
# Task 3: the start-up and the settled filter, paired
# ------------------------------------------------------------------------------------------

@remembered
def window_mses() -> dict[str, np.ndarray]:
    """Per-run position MSEs (cm²), shape (runs, 2), over the windows of Task 3 and its slips.

    Keys: ``start`` (the first second), ``after`` (after it), ``whole`` (the whole
    trial), ``one`` (the first sample only), ``start_late`` (the first second and one
    sample more), ``after_one`` (after the first sample). Read-only.
    """
    squared, burn = squared_errors(), DEFAULT.burn_in_steps
    windows = {"start": squared[..., :burn], "after": squared[..., burn:], "whole": squared,
               "one": squared[..., :1], "start_late": squared[..., :burn + 1],
               "after_one": squared[..., 1:]}
    values = {key: window.mean(axis=-1) for key, window in windows.items()}
    for array in values.values():
        array.setflags(write=False)
    return values


#: The windows of Task 3, as the messages say them.
_WINDOWS = {"start": "over the first second", "after": "after the first second"}


def _paired(mses: np.ndarray) -> metrics.Interval:
    """``metrics.mean_ci95`` of diag(1) − diag(10⁵), run by run."""
    return metrics.mean_ci95(mses[:, 0] - mses[:, 1])


def check_start_and_after(start_difference: metrics.Interval,
                          after_difference: metrics.Interval) -> None:
    """Check Task 3: diag(1) − diag(10⁵), paired, in the MSE over the first second and after.

    Recomputed before looking at the student's intervals: the runs of
    :func:`check_convergence_times`, each run's position MSE (cm²) over the samples before
    ``DEFAULT.burn_in_steps`` and over those from it on, and ``metrics.mean_ci95`` of the
    per-run differences P0 = diag(1) minus P0 = diag(10⁵). Mean and ends must agree within
    :data:`INTERVAL_RTOL` of the interval's scale.

    Parameters
    ----------
    start_difference, after_difference : metrics.Interval
        The student's paired differences (cm²) over the first second and after it.

    Raises
    ------
    CheckFailed
        Naming the interval and the likely cause: the windows swapped or the whole
        trial, the first second cut from the runs' axis or counted in seconds, the sign
        reversed, an unpaired interval, the RMSE, ...
    """
    mses, burn, squared = window_mses(), DEFAULT.burn_in_steps, squared_errors()
    runs = mses["start"].shape[0]
    readings_mses: dict[str, dict] = {window: {} for window in _WINDOWS}
    for which in (OWN_READINGS, TRIAL_READINGS):   # each run's readings, or the trial's y
        against = squared_against_readings(which == TRIAL_READINGS)
        for window, part in (("start", against[..., :burn]), ("after", against[..., burn:])):
            readings_mses[window][which] = tuple(part.mean(axis=-1).T)
    names = ("diag(1)'s MSE", "diag(1e5)'s MSE")
    cases = (
        ("start_difference", start_difference, "start", "after", {
            "it is over the whole trial: keep only the first second (the samples before "
            "burn_in)": _paired(mses["whole"]),
            "the first second ends one sample late: the samples before burn_in are "
            "0 … burn_in − 1": _paired(mses["start_late"]),
            f"it covers only the first sample: the first second is {burn} samples of "
            f"{DEFAULT.dt:g} s": _paired(mses["one"]),
            "the first second ends one sample early: the samples before burn_in are "
            "0 … burn_in − 1": _paired(squared[..., :burn - 1].mean(axis=-1)),
        }),
        ("after_difference", after_difference, "after", "start", {
            "it is over the whole trial: leave out the first second (the samples before "
            "burn_in)": _paired(mses["whole"]),
            f"it leaves out only the first sample: the first second is {burn} samples of "
            f"{DEFAULT.dt:g} s": _paired(mses["after_one"]),
            **{cause: _paired(squared[..., start:].mean(axis=-1))
               for cause, start in burn_in_slips(burn, squared.shape[-1]).items()},
        }),
    )
    for name, interval, window, other, slips in cases:
        if getattr(interval, "runs", runs) == burn and burn != runs:
            raise CheckFailed(
                f"{name} is over {burn} runs: [:burn_in] on the first axis cut the first "
                f"{burn} runs, not the first {burn} samples. Samples are the last axis of "
                f"the positions: [..., :burn_in] or [:, :, :burn_in]")
        mses_here = mses[window]
        judge_interval(name, interval, _paired(mses_here), INTERVAL_RTOL, unit="cm²",
                       what=f"the paired difference diag(1) − diag(1e5) of the MSE "
                            f"{_WINDOWS[window]}, recomputed from the task's runs",
                       mistakes={
                           f"it is the difference {_WINDOWS[other]}: start_difference is "
                           f"over the first second, after_difference after it":
                               _paired(mses[other]),
                           **slips,
                           "it is the difference of the root mean squared errors (cm); "
                           "the task compares the MSEs (cm²)": _paired(np.sqrt(mses_here)),
                           **interval_mistakes(
                               mses_here[:, 0], mses_here[:, 1], *names,
                               readings=readings_mses[window]),
                           **unit_mistakes(mses_here[:, 0], mses_here[:, 1], *names),
                       })
    passed(f"start_difference and after_difference match diag(1) − diag(1e5), paired over "
           f"{runs} runs, over the first {burn} samples and after them, recomputed with the "
           f"pack's engine: mean and 95 % interval to {tolerance_text(INTERVAL_RTOL)} "
           f"relative")
