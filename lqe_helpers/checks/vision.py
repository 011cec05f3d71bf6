"""Checks of notebook 01, question (a): the filter of eq. (5), and vision alone at two noises.

- :func:`check_filter` (Task 1): the student's ``my_filter`` on small random models,
  against the pack's engine (:func:`lqe_helpers.filter.kalman_filter`);
- :func:`check_vision_trial` (Task 2): the student's ``vision_trial(sigma_v)``, the readings
  and the estimates of one trial at σ_v = 1.5 and 4.5 cm, against the engine on the
  scenario's draw.

:func:`monte_carlo` (the core path's Monte Carlo runs) and :func:`keyed` (a student's dict
keyed by σ_v or Δt) serve the Going further checks (:mod:`~lqe_helpers.checks.vision_smoothers`,
:mod:`~lqe_helpers.checks.vision_further`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from .. import experiments, simulation
from ..scenario import DEFAULT
from . import filter_models
from .filter_models import FILTER_ARGS, FILTER_MISTAKES, FILTER_STEPS, FilterCase
from .judging import CM_PER_M, judge
from .machinery import (
    FUNCTION_RTOL,
    CheckFailed,
    answers_on_cases,
    call_student,
    close,
    keyed_entries,
    match_mistake,
    passed,
    require_callable,
    student_result,
    time_limit_text,
    tolerance_text,
)
from .own_work import FUNCTION_TASKS, not_driven, outputs_of
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: The question's two noise levels of vision (cm).
SIGMAS_V = (1.5, 4.5)

_FILTER_SHAPE_HINT = (
    "The shapes in one product or sum do not fit: write the shape beside each term (y_j is "
    "(m,), ẑ is (k,), C is (m, k), P and A are (k, k), R is (m, m), K is (k, m)).")


# ------------------------------------------------------------------------------------------
# Task 1: the filter
# ------------------------------------------------------------------------------------------

def check_filter(my_filter: Callable[..., np.ndarray]) -> None:
    """Check a student's filter ``my_filter(y, A, C, Q, R, z0, P0)`` against Tutorial eq. (5).

    The function is called on six small random models (1–4 states, 1–3 sensors, 15
    steps, from the fixed seed :data:`SEED`) and on the butterfly's whole trial (the
    tasks' vision-only model on the scenario's readings, all its steps), each call given at
    most
    :data:`lqe_helpers.student_code.TIME_LIMIT` s, and must return the estimates, an
    array of shape (n, k) whose row j is ẑ after y_j, equal to the pack's engine
    (:func:`lqe_helpers.filter.kalman_filter`, computed before the student's function
    runs) within :data:`FUNCTION_RTOL` of the largest estimate.

    Parameters
    ----------
    my_filter : callable
        The student's function.

    Raises
    ------
    CheckFailed
        If the function is not written yet, raises an error, does not return in time,
        returns something of the wrong type or shape, changes its inputs, or computes
        other numbers; the message names the mistake when it is a typical one.
    """
    name = require_callable(my_filter, "my_filter", "check_filter")
    models = filter_models.models()
    correct = {index: filter_models.right_estimates(index) for index in range(len(models))}
    answers, errors = answers_on_cases(
        models,
        lambda m: call_student(my_filter, *m.args, name=name, where=m.describe(),
                               arg_names=FILTER_ARGS, shape_hint=_FILTER_SHAPE_HINT,
                               allow=FUNCTION_TASKS["my_filter"]),
        lambda output, m: _filter_output(output, name, m))
    wrong = [i for i in answers if not close(answers[i], correct[i], FUNCTION_RTOL)]
    if not wrong and not errors:
        passed(f"{name} matches eq. (5) on {len(models) - 1} random models (1–4 states, 1–3 "
               f"sensors, {FILTER_STEPS} steps) and on the butterfly's whole trial "
               f"({models[-1].n} steps) to {tolerance_text(FUNCTION_RTOL)}, "
               f"{time_limit_text()}")
        return
    mistake = match_mistake(list(FILTER_MISTAKES), filter_models.mistaken_estimates, answers,
                            correct)
    if mistake is not None:
        also = " (On some models it also raises an error.)" if errors else ""
        raise CheckFailed(f"{name} does not follow eq. (5): {FILTER_MISTAKES[mistake]}.{also}")
    if errors:
        raise errors[min(errors)]
    _explain_wrong_rows(name, models[wrong[0]], answers[wrong[0]], correct[wrong[0]])

def _explain_wrong_rows(name: str, m: FilterCase, answer: np.ndarray,
                        right: np.ndarray) -> None:
    """CheckFailed for a filter whose numbers differ in no typical way."""
    if answer.shape[0] > 1 and np.allclose(answer, answer[-1], rtol=0, atol=0) and \
            close(answer[-1], right[-1], FUNCTION_RTOL):
        raise CheckFailed(
            f"every row of {name}'s result is the last estimate (on {m.describe()}): the "
            f"same array was stored at every step and then changed in place. Store a "
            f"separate copy of ẑ at each step")
    scale = max(1.0, float(np.max(np.abs(right))))
    bad_rows = np.any(np.abs(answer - right) > FUNCTION_RTOL * scale, axis=1)
    row = int(np.argmax(bad_rows))
    if row == 0:
        where = ("Already the first estimate (after y_0, starting from ẑ = z0 and P = P0) "
                 "differs: check the gain K and the ẑ line of eq. (5)")
    elif row >= FILTER_STEPS:
        where = (f"The first {row} estimates are right, then row {row} differs: each line "
                 f"of eq. (5) works, but something changes after {row} steps. Look for what "
                 f"depends on the step number or on a fixed count: a loop bound, an array of "
                 f"a fixed length, a gain or a P kept fixed after a while")
    else:
        first = "The first estimate is" if row == 1 else f"The first {row} estimates are"
        where = (f"{first} right, then row {row} differs: K and ẑ are right at the "
                 f"start, so check how P is carried to the next step (third line of "
                 f"eq. (5))")
    raise CheckFailed(
        f"{name} does not match eq. (5) on {m.describe()}. {where}. (Largest difference "
        f"{float(np.max(np.abs(answer - right))):.3g} where the estimates are of size "
        f"{scale:.3g}.)")


def _filter_output(output: object, name: str, m: FilterCase) -> np.ndarray:
    """The filter's output as an (n, k) array, or a CheckFailed naming what came back."""
    n, k = m.n, m.k
    what = f"the estimates ẑ, an array of shape (n, k) = {(n, k)}"
    where = f"on {m.describe()}"
    array = student_result(output, name=name, what=what, where=m.describe())
    shape = array.shape
    if shape == (n, k):
        return array
    if shape == (n + 1, k):
        first = "its first row is z0" if np.allclose(array[0], m.z0) else "one row too many"
        message = (f"returned {n + 1} rows for {n} measurements ({first}) {where}. Row j "
                   f"must be the estimate after y_j, so there are exactly n = {n} rows: z0 "
                   f"is the starting point, not an estimate")
    elif shape == (n, k, k):
        message = (f"returned an array of shape {shape}, the shape of the covariances P, "
                   f"{where}; it must return the estimates ẑ, shape (n, k) = {(n, k)}")
    elif shape == (n, k, 1):
        message = (f"returned shape {shape} {where}: each estimate is a column (k, 1). "
                   f"Each row of the result must be a flat vector of k = {k} numbers, so "
                   f"the result has shape (n, k) = {(n, k)}")
    elif shape == (n, k, m.m):
        message = (f"returned an array of shape {shape}, the shape of the gains K, "
                   f"{where}; it must return the estimates ẑ, shape (n, k) = {(n, k)}")
    elif shape == (k, n):
        message = (f"returned shape {shape} {where}: the result is transposed. Rows are "
                   f"time steps, columns are states: shape (n, k) = {(n, k)}")
    elif shape == (k, k):
        message = (f"returned one {k} × {k} matrix {where} (the last covariance P?); it "
                   f"must return all n = {n} estimates ẑ, shape (n, k) = {(n, k)}")
    elif shape == (k,):
        message = (f"returned a single estimate of shape {shape} {where} (the last one?); "
                   f"it must return one estimate per measurement, shape (n, k) = {(n, k)}")
    elif shape == (n, m.m) and m.m != k:
        message = (f"returned shape {shape} {where}: one column per sensor. It must return "
                   f"the state estimates ẑ, one column per state: shape (n, k) = {(n, k)}")
    else:
        message = (f"returned an array of shape {shape} {where}; expected the estimates, "
                   f"shape (n, k) = {(n, k)} (n = {n} measurements, k = {k} states)")
    raise CheckFailed(f"{name} {message}")


# ------------------------------------------------------------------------------------------
# A student's dict keyed by σ_v (the Going further checks)
# ------------------------------------------------------------------------------------------

def keyed(values: object, name: str, what: str, keys: tuple[float, ...] = SIGMAS_V,
          key: str = "σ_v", unit: str = "cm") -> dict[float, object]:
    """The student's dict keyed by numbers (σ_v in cm, Δt in s), with every key due in it.

    Parameters
    ----------
    values : object
        What the student passed, e.g. ``mse_filtered``.
    name : str
        Its name, for messages.
    what : str
        What its values are ("MSEs (cm²) of the readings").
    keys : tuple of float
        The keys the task asks for, in order.
    key, unit : str
        What the keys are and their unit, for messages.

    Returns
    -------
    dict of float to object
        The student's values by float key (numpy numbers and ints count as floats).

    Raises
    ------
    CheckFailed
        If ``values`` is not a dict, or a key due is missing.
    """
    return keyed_entries(
        values, name, keys, what, keyed_by=f"{key} ({unit}), e.g. {name}[{keys[-1]:g}]",
        entry=lambda missing: f"for {key} = {missing:g} {unit}",
        advice=f"; the task asks for {key} = {', '.join(f'{value:g}' for value in keys)} "
               f"{unit}, keyed by the number {key} itself")


# ------------------------------------------------------------------------------------------
# Task 2: one trial at both noise levels
# ------------------------------------------------------------------------------------------

#: Task 2's function: its parameter, and what a shape error in it (or in my_filter, which
#: it calls) most likely is.
_TRIAL_ARGS = ("sigma_v",)
_TRIAL_SHAPE_HINT = (
    "Check the shapes of what vision_trial gives my_filter: truth is (n,) and noise is "
    "(n, 1), so truth + σ_v · noise broadcasts to (n, n); the readings are "
    "truth[:, None] + σ_v · noise, shape (n, 1). R is 1 × 1: [[σ_v²]].")


def _readings(sigma_v: float, scale: float | None = None) -> np.ndarray:
    """Vision's readings (n, 1) (cm): truth + scale · the scenario's draw (scale = σ_v)."""
    noise = DEFAULT.unit_noise(sensors=("vision",))
    return simulation.measure(DEFAULT.truth[:, 0], noise, [sigma_v if scale is None else scale])


def _estimates(readings: np.ndarray, r_variance: float) -> np.ndarray:
    """The engine's estimates (n, 3) of ``readings`` with R = [[r_variance]] (cm²).

    The tasks' vision-only model (:func:`lqe_helpers.experiments.filter_model`) with its
    R replaced, so that a slip in R (σ for σ², σ⁴) is filtered exactly as written.
    """
    vision = experiments.filter_model(DEFAULT)
    return dataclasses.replace(vision, R=np.array([[r_variance]])).filter(readings).estimates


@remembered
def _trial(sigma_v: float) -> dict[str, object]:
    """Task 2's readings (n, 1) and estimates (n, 3) at ``sigma_v``, and the likely mistakes."""
    other = SIGMAS_V[1] if sigma_v == SIGMAS_V[0] else SIGMAS_V[0]
    y = _readings(sigma_v)
    return {
        "y": y,
        "estimates": _estimates(y, sigma_v**2),
        "y_mistakes": {
            "the readings were made with σ_v² instead of σ_v (truth + σ_v² · noise)":
                _readings(sigma_v, sigma_v**2),
            "the readings were made without σ_v (truth + noise): scale the unit noise by σ_v":
                _readings(sigma_v, 1.0),
            f"they are the readings of σ_v = {other:g} cm: scale the noise by the σ_v "
            f"vision_trial is given": _readings(other),
            "they are the noise alone (σ_v · noise): add the true position":
                _readings(sigma_v) - DEFAULT.truth[:, :1],
            "they are in metres (divided by 100): the truth, σ_v, R and Q are in cm, so the "
            "readings are too": _readings(sigma_v) / CM_PER_M,
        },
        "estimate_mistakes": {
            "R holds σ_v (cm) where its variance σ_v² (cm²) belongs, so the filter weighs "
            "vision wrongly": _estimates(y, sigma_v),
            "R holds σ_v⁴: the variance σ_v² was squared again": _estimates(y, sigma_v**4),
            f"R is that of σ_v = {other:g} cm: make R from the σ_v vision_trial is given":
                _estimates(y, other**2),
        },
    }


#: Readings whose noise (y − truth) / σ_v has a spread within 1 ± the first, a mean within
#: ± the second and a correlation with the given draw within ± the third are "noise of the
#: right size, another draw". Measured on 20 000 draws of 1000 unit normal samples: spread
#: within 1 ± 0.095, mean within ± 0.147, correlation of two draws within ± 0.124.
_OWN_NOISE_SPREAD, _OWN_NOISE_MEAN, _OWN_NOISE_CORRELATION = 0.15, 0.2, 0.3


def _own_noise(y: np.ndarray, sigma_v: float) -> bool:
    """Whether readings ``y`` (n, 1) (cm) are the truth plus noise of spread σ_v that is
    not the scenario's draw (the student's own random numbers)."""
    given = DEFAULT.unit_noise(sensors=("vision",))[:, 0]
    scaled = (y[:, 0] - DEFAULT.truth[:, 0]) / sigma_v
    return bool(abs(float(np.std(scaled)) - 1.0) <= _OWN_NOISE_SPREAD
                and abs(float(np.mean(scaled))) <= _OWN_NOISE_MEAN
                and abs(float(np.corrcoef(scaled, given)[0, 1])) <= _OWN_NOISE_CORRELATION)


def _trial_output(output: object, name: str, sigma_v: float) -> tuple[object, object]:
    """The two values ``vision_trial`` returned, or CheckFailed saying what came back."""
    if isinstance(output, (tuple, list)) and len(output) == 2:
        return output[0], output[1]
    found = ("None (nothing): does it end with `return y, estimates`?" if output is None
             else f"a tuple of {len(output)} items" if isinstance(output, (tuple, list))
             else f"a {type(output).__name__}")
    raise CheckFailed(f"{name}({sigma_v:g}) must return two things, the readings y and the "
                      f"estimates of my_filter (return y, estimates), got {found}")


def check_vision_trial(vision_trial: Callable[[float], tuple[np.ndarray, np.ndarray]]) -> None:
    """Check Task 2's ``vision_trial(sigma_v)``: one trial of vision alone, filtered.

    The function is called at σ_v = 1.5 and 4.5 cm (each call given at most
    :data:`lqe_helpers.student_code.TIME_LIMIT` s) and must return the readings
    ``truth + σ_v · noise`` of the scenario's draw, shape (n, 1), and the estimates of
    eq. (5) with ``R = [[σ_v²]]``, ``C = [[1, 0, 0]]``, ``DEFAULT.A``, ``DEFAULT.Q``, z0
    and ``DEFAULT.P0``, shape (n, 3): both recomputed with the pack's engine before the
    student's function runs, and equal within :data:`FUNCTION_RTOL` of the largest value.

    Parameters
    ----------
    vision_trial : callable
        The student's function of σ_v (cm), returning ``(y, estimates)``.

    Raises
    ------
    CheckFailed
        If the function is not written yet, fails (a shape error names the (n, n) readings
        of ``truth + σ_v · noise``), does not return two arrays of the right shapes, runs
        the pack's engine, or computes other numbers; the message names the likely cause:
        σ_v² or no σ_v in the readings, σ_v or σ_v⁴ in R, the other noise level's R. Right
        estimates must also be what the student's ``my_filter`` returned inside the call
        (:func:`~lqe_helpers.checks.own_work.outputs_of`): results kept from elsewhere fail.
    """
    name = require_callable(vision_trial, "vision_trial", "check_vision_trial")
    n = DEFAULT.n_steps
    for sigma in SIGMAS_V:
        right = _trial(sigma)
        with outputs_of(vision_trial, "my_filter") as filtered:
            output = call_student(vision_trial, sigma, name=name, where=f"σ_v = {sigma:g} cm",
                                  arg_names=_TRIAL_ARGS, shape_hint=_TRIAL_SHAPE_HINT,
                                  allow=FUNCTION_TASKS["vision_trial"])
        y, estimates = _trial_output(output, name, sigma)
        if np.shape(y) == (n, 3) and np.shape(estimates) == (n, 1):
            raise CheckFailed(f"{name}({sigma:g}) returns the estimates first and the readings "
                              f"second; return y, then the estimates, as the task says")
        label = f"the first array {name}({sigma:g}) returns (the readings y)"
        y = student_result(y, name=label, what=f"the readings, an array of shape ({n}, 1)")
        if y.shape == (n, n):
            raise CheckFailed(f"{label} has shape ({n}, {n}): {_TRIAL_SHAPE_HINT}")
        if y.shape == (n,):
            raise CheckFailed(f"{label} is flat, shape ({n},); keep one column per sensor, "
                              f"shape ({n}, 1), as my_filter reads one row per time step")
        if y.shape == (n, 1) and not close(y, right["y"], FUNCTION_RTOL) and \
                _own_noise(y, sigma):
            raise CheckFailed(
                f"{label} has noise of the right size, σ_v, but not the given draw: it "
                f"looks like random numbers of your own. Make the readings from the set-up "
                f"cell's noise (the scenario's seeded draw), truth[:, None] + σ_v · noise, so "
                f"that every task and check works on the same trial")
        judge(label, y, right["y"], FUNCTION_RTOL, unit="cm", mistakes=right["y_mistakes"],
              what="truth + σ_v · noise on the scenario's draw")
        label = f"the second array {name}({sigma:g}) returns (the estimates)"
        estimates = student_result(estimates, name=label,
                                   what=f"the estimates of my_filter, shape ({n}, 3)")
        if estimates.shape == (n,):
            raise CheckFailed(f"{label} holds one number per reading (the positions only?); "
                              f"return all the estimates my_filter gives, shape ({n}, 3)")
        judge(label, estimates, right["estimates"], FUNCTION_RTOL,
              mistakes=right["estimate_mistakes"],
              what="the pack's engine on these readings with R = [[σ_v²]]",
              hint="if my_filter passed its check (Task 1), look at what vision_trial gives "
                   "it: y, A, C = [[1, 0, 0]], Q, R = [[σ_v²]], z0 and P0; if not, make it "
                   "pass first")
        problem = not_driven(estimates, filtered, "my_filter", f"{name}({sigma:g})")
        if problem is not None:
            raise CheckFailed(problem)
    passed(f"{name} at σ_v = {' and '.join(f'{s:g}' for s in SIGMAS_V)} cm: the readings "
           f"truth + σ_v · noise and the estimates with R = [[σ_v²]] match the pack's engine "
           f"on the scenario's draw to {tolerance_text(FUNCTION_RTOL)} of the largest value, "
           f"{time_limit_text()}")


# ------------------------------------------------------------------------------------------
# The core path's Monte Carlo runs (the notebook's given batch)
# ------------------------------------------------------------------------------------------

@remembered
def monte_carlo() -> experiments.Tracking:
    """The core path's runs: ``DEFAULT.mc_runs`` runs at σ_v = 1.5 and 4.5 cm, shape (runs, 2, ...).

    The engine's batch of the scenario's draws, the same as the notebook's ``batch``;
    computed once and shared by the checks of notebook 01 (none hands it to a student's
    function).
    """
    return experiments.track(DEFAULT, sigmas=[[s] for s in SIGMAS_V], runs=DEFAULT.mc_runs)
