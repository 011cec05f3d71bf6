"""Checks of notebook 00, the background: the core tasks.

- :func:`check_transition_matrix` (Task 1): the student's ``A(dt)`` of eq. (4);
- :func:`check_eyes_closed` (Task 2): the student's covariance step of Lesson 0.5 eq. (9),
  then the 2σ band it grows from the filter's covariance at t = 2 s and when it first
  exceeds the flight's amplitude, recomputed with the engine;
- :func:`check_jerk_stds` (Task 3): σ_j matched over four time scales.

The Going further tasks are checked in :mod:`lqe_helpers.checks.background_further`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from .. import experiments, model
from ..prediction import propagate_covariance
from ..scenario import DEFAULT, matched_jerk_std
from .judging import judge
from .machinery import (
    MATRIX_RTOL,
    SEED,
    TIME_ATOL,
    CheckFailed,
    argument_array,
    call_student,
    close,
    keyed_entries,
    passed,
    require_callable,
    student_result,
    time_limit_text,
    tolerance_text,
)
from .own_work import FUNCTION_TASKS
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: Time steps (s) at which :func:`check_transition_matrix` calls the student's function:
#: the pack's own, and others (some > 1 s, where Δt, Δt² and Δt²/2 all differ clearly).
_TRANSITION_DTS = (0.01, 0.037, 0.25, 1.3, 2.5)


def _transition_mistakes(dt: float) -> dict[str, tuple[np.ndarray, str]]:
    """Typical wrong transition matrices for step ``dt`` and what to say about each."""
    right = model.transition_matrix(dt)
    no_half = right.copy()
    no_half[0, 2] = dt**2
    no_corner = right.copy()
    no_corner[0, 2] = 0.0
    half_dt = right.copy()
    half_dt[0, 2] = dt / 2
    return {
        "transposed": (right.T, "A is transposed: the state [p, v, a] is a column, so the "
                                "first row says how the new position is made from p, v and "
                                "a; the entries above the diagonal belong in the first rows"),
        "no_half": (no_half, "the corner entry (row 0, column 2) is Δt², but the Taylor "
                             "term of the position is Δt²/2 times the acceleration"),
        "no_corner": (no_corner, "the new position ignores the acceleration: with constant "
                                 "acceleration the position also moves by Δt²/2 · a (row 0, "
                                 "column 2)"),
        "half_dt": (half_dt, "the corner entry is Δt/2; the Taylor term is Δt²/2 (Δt "
                             "squared, then halved)"),
        "identity": (np.eye(3), "A is the identity: nothing moves. The position must grow "
                                "by Δt · v and the velocity by Δt · a"),
    }


def check_transition_matrix(make_A: Callable[[float], np.ndarray], A: object = None) -> None:
    """Check a student's ``make_A(dt)`` against Tutorial eq. (4) (constant acceleration).

    The function is called at several time steps (:data:`_TRANSITION_DTS`, s) and must
    return the 3 × 3 matrix ``[[1, Δt, Δt²/2], [0, 1, Δt], [0, 0, 1]]`` for the state
    [p, v, a], equal to :func:`model.transition_matrix` within :data:`MATRIX_RTOL`. The
    task's ``A`` (which later tasks use), if given, must be that matrix at the
    scenario's Δt.

    Parameters
    ----------
    make_A : callable
        The student's function of the time step Δt (s).
    A : array_like, shape (3, 3), optional
        The student's ``A = make_A(DEFAULT.dt)``.

    Raises
    ------
    CheckFailed
        If the function is not written yet, raises, returns the wrong shape, or another
        matrix; the message names the typical mistakes (transposed, Δt² without the
        half, no acceleration term, an answer that ignores Δt, ...).
    """
    name = require_callable(make_A, "make_A", "check_transition_matrix")
    right = {dt: model.transition_matrix(dt) for dt in _TRANSITION_DTS}
    answers = {}
    for dt in _TRANSITION_DTS:
        output = call_student(make_A, dt, name=name, where=f"dt = {dt:g} s", arg_names=("dt",),
                              allow=FUNCTION_TASKS["my_transition_matrix"])
        array = student_result(output, name=name, where=f"dt = {dt:g} s",
                               what="the transition matrix A, an array of shape (3, 3)")
        if array.shape != (3, 3):
            raise CheckFailed(
                f"{name}({dt:g}) returned shape {array.shape}; A must be 3 × 3, one row and "
                f"one column per state (p, v, a)")
        answers[dt] = array
    wrong = [dt for dt, array in answers.items() if not close(array, right[dt], MATRIX_RTOL)]
    if not wrong:
        if A is not None:
            _check_task_A(A)
        passed(f"{name} gives eq. (4)'s A (constant acceleration) at {len(answers)} time "
               f"steps from {min(_TRANSITION_DTS):g} to {max(_TRANSITION_DTS):g} s, to "
               f"{tolerance_text(MATRIX_RTOL)}, {time_limit_text()}"
               + (f", and A is its value at Δt = {DEFAULT.dt:g} s" if A is not None else ""))
        return
    first, last = answers[_TRANSITION_DTS[0]], answers[_TRANSITION_DTS[-1]]
    if len(wrong) < len(answers) and np.allclose(first, last) and not np.allclose(
            model.transition_matrix(_TRANSITION_DTS[0]),
            model.transition_matrix(_TRANSITION_DTS[-1])):
        raise CheckFailed(
            f"{name} returns the same matrix for every time step: it must use its argument "
            f"dt (the pack's Δt is only one of the steps tried)")
    for key in ("transposed", "no_half", "no_corner", "half_dt", "identity"):
        if all(close(answers[dt], _transition_mistakes(dt)[key][0], MATRIX_RTOL)
               for dt in wrong):
            raise CheckFailed(f"{name}: {_transition_mistakes(wrong[0])[key][1]}")
    dt = wrong[0]
    raise CheckFailed(
        f"{name}({dt:g}) is not eq. (4)'s A: row 0 must turn [p, v, a] into the Taylor step "
        f"of the position, row 1 that of the velocity, row 2 keeps the acceleration")


def _check_task_A(A: object) -> None:
    """``A`` must be eq. (4)'s A at the scenario's Δt (the matrix later tasks use)."""
    A = argument_array(A, "A", "the transition matrix at DEFAULT.dt, an array of shape (3, 3)",
                       shape=(3, 3))
    if close(A, model.transition_matrix(DEFAULT.dt), MATRIX_RTOL):
        return
    for dt in (0.1, 0.001, 1.0, 0.02, 0.005):
        if close(A, model.transition_matrix(dt), MATRIX_RTOL):
            raise CheckFailed(
                f"A is eq. (4)'s A at Δt = {dt:g} s; the task's A is my_transition_matrix("
                f"DEFAULT.dt), the scenario's Δt = {DEFAULT.dt:g} s (later tasks use it)")
    raise CheckFailed(
        f"A is not my_transition_matrix(DEFAULT.dt), eq. (4)'s A at Δt = {DEFAULT.dt:g} s: "
        f"set A = my_transition_matrix(DEFAULT.dt) (later tasks use it)")


#: (states k, inputs r) of the random cases of :func:`check_covariance_step`.
_COVARIANCE_CASES = ((3, 1), (2, 1), (4, 2), (1, 1), (3, 2))


@remembered
def _covariance_cases() -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray, float], ...]:
    """(P, F, G, σ) for each case, drawn from ``SEED + 2`` (read-only arrays)."""
    rng = np.random.default_rng(SEED + 2)
    cases = []
    for k, r in _COVARIANCE_CASES:
        X = rng.normal(size=(k, k))
        P = X @ X.T + 0.3 * np.eye(k)
        F = np.eye(k) + 0.5 * rng.normal(size=(k, k))
        G = rng.normal(size=(k, r))
        sigma = float(rng.uniform(1.5, 4.0))
        for array in (P, F, G):
            array.setflags(write=False)
        cases.append((P, F, G, sigma))
    return tuple(cases)


def _covariance_mistakes(P, F, G, sigma) -> dict[str, tuple[np.ndarray, str]]:
    noise = sigma**2 * G @ G.T
    return {
        "sides": (F.T @ P @ F + noise, "F and Fᵀ are on the wrong sides: the state moves as "
                                       "F z, so its covariance becomes F P Fᵀ (F on the left)"),
        "no_noise": (F @ P @ F.T, "the random input's covariance G σ² Gᵀ is not added: "
                                  "without it the uncertainty never grows by the noise"),
        "sigma": (F @ P @ F.T + sigma * G @ G.T, "σ is used where its square belongs: a "
                                                 "covariance adds variances, G σ² Gᵀ"),
        "no_transpose": (F @ P @ F + noise, "the second F is not transposed: F P Fᵀ"),
        "no_second_F": (F @ P + noise, "Fᵀ is missing on the right: F P moves the covariance "
                                       "only once; the state moves as F z, so its covariance "
                                       "becomes F P Fᵀ (F on the left and Fᵀ on the right)"),
        "no_first_F": (P @ F.T + noise, "F is missing on the left: P Fᵀ moves the covariance "
                                        "only once; the state moves as F z, so its covariance "
                                        "becomes F P Fᵀ (F on the left and Fᵀ on the right)"),
        "not_moved": (P + noise, "P is not carried through the model: the old covariance "
                                 "must be moved one step by F (F P Fᵀ) before the noise is "
                                 "added"),
    }


#: The mistakes of :func:`_covariance_mistakes`, in the order they are tried.
_COVARIANCE_MISTAKE_ORDER = ("sides", "no_noise", "sigma", "no_transpose", "no_second_F",
                             "no_first_F", "not_moved")


def check_covariance_step(predict_covariance: Callable[..., np.ndarray]) -> None:
    """Check ``predict_covariance(P, F, G, sigma)`` against Lesson 0.5 eq. (9).

    The function must return ``F P Fᵀ + G σ² Gᵀ``, the covariance one step later with
    no measurement, when the state moves as ``z(k+1) = F z(k) + G u(k)`` and the input u
    has standard deviation σ. It is called on five random cases (1–4 states, 1–2 inputs,
    from ``SEED + 2``) and must agree within :data:`MATRIX_RTOL`.

    Parameters
    ----------
    predict_covariance : callable
        The student's function of (P (k, k), F (k, k), G (k, r), sigma).

    Raises
    ------
    CheckFailed
        If the function is not written yet, raises, changes its inputs, returns the
        wrong shape, or another matrix; typical mistakes are named (F on the wrong
        sides, no noise term, σ instead of σ², no transpose, Fᵀ or F missing, P not moved
        by F).
    """
    name = _judge_covariance_step(predict_covariance, "check_covariance_step")
    passed(f"{name} gives F P Fᵀ + G σ² Gᵀ (Lesson 0.5 eq. (9)) on "
           f"{len(_COVARIANCE_CASES)} random cases (1–4 states, 1–2 inputs), to "
           f"{tolerance_text(MATRIX_RTOL)}, {time_limit_text()}")


def _judge_covariance_step(predict_covariance: Callable[..., np.ndarray], check: str) -> str:
    """The student's function's name if it follows eq. (9) on every case, else CheckFailed."""
    name = require_callable(predict_covariance, "predict_covariance", check)
    cases = _covariance_cases()
    right = [F @ P @ F.T + sigma**2 * G @ G.T for P, F, G, sigma in cases]
    wrong = []
    for (P, F, G, sigma), expected in zip(cases, right, strict=True):
        where = f"P and F of shape {P.shape}, G of shape {G.shape}, sigma = {sigma:.3g}"
        output = call_student(
            predict_covariance, P, F, G, sigma, name=name, where=where,
            arg_names=("P", "F", "G", "sigma"), allow=FUNCTION_TASKS["predict_covariance"],
            shape_hint="P and F are (k, k), G is (k, r): write each term's shape.")
        array = student_result(output, name=name, where=where,
                               what=f"the new covariance P, an array of shape {P.shape}")
        if array.shape != P.shape:
            raise CheckFailed(f"{name} returned shape {array.shape} for {where}; the new "
                              f"covariance has the shape of P, {P.shape}")
        if not close(array, expected, MATRIX_RTOL):
            wrong.append((array, P, F, G, sigma, where))
    if not wrong:
        return name
    for key in _COVARIANCE_MISTAKE_ORDER:
        if all(close(array, _covariance_mistakes(P, F, G, sigma)[key][0], MATRIX_RTOL)
               for array, P, F, G, sigma, _ in wrong):
            raise CheckFailed(f"{name} does not follow eq. (9): "
                              f"{_covariance_mistakes(*wrong[0][1:5])[key][1]}")
    raise CheckFailed(
        f"{name} does not give F P Fᵀ + G σ² Gᵀ on {wrong[0][5]}, and not by one of the "
        f"usual mistakes")


# ------------------------------------------------------------------------------------------
# Task 2: eyes closed
# ------------------------------------------------------------------------------------------

#: When the eyes close in Task 2 (s), and how many steps of 0.01 s they stay closed.
EYES_CLOSE_TIME = 2.0
EYES_CLOSED_STEPS = 100


@remembered
def _eyes_closed() -> dict[str, object]:
    """Task 2's right band (101,) (cm) and crossing (s), and the likely wrong bands."""
    result = experiments.track(DEFAULT).result
    close_at = round(EYES_CLOSE_TIME / DEFAULT.dt)
    P_close = result.estimate_covariances[close_at]
    g = model.jerk_input_matrix(DEFAULT.dt)
    sigma_j = DEFAULT.process_jerk_std

    def variance(start: np.ndarray, jerk_variance: float, entry: int = 0) -> np.ndarray:
        Q = jerk_variance * g @ g.T
        return propagate_covariance(start, DEFAULT.A, Q, EYES_CLOSED_STEPS)[:, entry, entry]

    right = variance(P_close, sigma_j**2)
    # Every step taken from P_close again instead of from the last P: one step, repeated.
    restarted = np.concatenate([right[:1], np.full(EYES_CLOSED_STEPS, right[1])])
    bands = {
        "it is σ, not 2σ: double the standard deviation": np.sqrt(right),
        "it is twice the variance: take the square root of P[0, 0] (the standard deviation, "
        "cm), then double it": 2 * right,
        "it is the variance P[0, 0] itself (cm²): 2σ is twice its square root (cm)": right,
        "the 2 is inside the square root (√(2 P[0, 0])): 2σ is 2 √(P[0, 0])":
            np.sqrt(2 * right),
        "sigma was given the jerk's variance σ_j² where its standard deviation σ_j belongs "
        "(predict_covariance squares it)": 2 * np.sqrt(variance(P_close, sigma_j**4)),
        "it starts from P = 0, a perfectly known state; the band starts from P_close, the "
        "filter's own covariance when the eyes close":
            2 * np.sqrt(variance(np.zeros((3, 3)), sigma_j**2)),
        "it starts from the filter's prediction covariance at t = 2 s (before the reading "
        "of that sample); start from P_close, the covariance of its estimate":
            2 * np.sqrt(variance(result.covariances[close_at], sigma_j**2)),
        "every step starts again from P_close, so the band stops growing after one step: "
        "feed each step the P the step before returned": 2 * np.sqrt(restarted),
        "sigma is vision's noise σ_v; the random input here is the jerk, of standard "
        "deviation σ_j (sigma_j)": 2 * np.sqrt(variance(P_close, DEFAULT.sigma_v**2)),
        **{f"it is 2 √P[{entry}, {entry}], the {state}'s variance ({unit}): the position's "
           f"is the first diagonal entry, P[0, 0] (cm²)":
               2 * np.sqrt(variance(P_close, sigma_j**2, entry))
           for entry, state, unit in ((1, "velocity", "cm²/s²"), (2, "acceleration", "cm²/s⁴"))},
    }
    two_sigma = 2 * np.sqrt(right)
    above = int(np.argmax(two_sigma > DEFAULT.amplitude))
    # The first time another quantity than 2σ passes the amplitude (s after the eyes close).
    other_crossings = {
        "it is when the variance P[0, 0] (cm²) exceeds the amplitude; compare 2σ, "
        "2 √P[0, 0] in cm, with it": int(np.argmax(right > DEFAULT.amplitude)) * DEFAULT.dt,
        "it is when σ exceeds the amplitude; the task asks when 2σ does":
            int(np.argmax(np.sqrt(right) > DEFAULT.amplitude)) * DEFAULT.dt,
    }
    return {"two_sigma": two_sigma, "bands": bands, "crossing": above * DEFAULT.dt,
            "steps": above, "other_crossings": other_crossings}


def check_eyes_closed(predict_covariance: Callable[..., np.ndarray], two_sigma: object,
                      crossing: object = None) -> None:
    """Check Task 2: the covariance step, the 2σ band it grows and when the band passes A.

    First ``predict_covariance`` is checked as by :func:`check_covariance_step` (five
    random cases, :data:`MATRIX_RTOL`). Then, recomputed from the task's inputs before
    looking at the student's: the vision-only filter's estimate covariance at t = 2 s of
    the scenario's draw (``P_close``), carried 100 steps by
    :func:`lqe_helpers.prediction.propagate_covariance` with ``DEFAULT.A`` and
    ``DEFAULT.Q``; ``two_sigma`` (101 values, cm) must agree within :data:`MATRIX_RTOL`
    relative, and ``crossing``, the first time after the eyes close at which 2σ exceeds
    the amplitude (s), within :data:`TIME_ATOL`.

    Parameters
    ----------
    predict_covariance : callable
        The student's ``predict_covariance(P, F, G, sigma)``.
    two_sigma : array_like, shape (101,)
        Twice the standard deviation of the position (cm) at 0, 0.01, …, 1 s after the
        eyes close.
    crossing : float, optional
        The first time (s after the eyes close) at which it exceeds the amplitude; not
        judged when left out (notebook 00 computes it in a given cell).

    Raises
    ------
    CheckFailed
        With the likely cause: the function's mistake, σ instead of 2σ, the variance,
        σ_j² or σ_v given as sigma, every step from P_close, the band started from P = 0,
        100 values instead of 101; the crossing in samples, a step early, counted from the
        start of the trial, of the variance or of σ instead of 2σ, ...
    """
    name = _judge_covariance_step(predict_covariance, "check_eyes_closed")
    right = _eyes_closed()
    expected = right["two_sigma"]
    try:
        shape = np.shape(two_sigma)
    except ValueError:  # a ragged list: judge names it
        shape = None
    if shape == (EYES_CLOSED_STEPS,):
        raise CheckFailed(
            f"two_sigma has {EYES_CLOSED_STEPS} values; keep the moment the eyes close too "
            f"(two_sigma[0], from P_close itself), then one value per step: "
            f"{EYES_CLOSED_STEPS + 1} in all")
    judge("two_sigma", two_sigma, expected, MATRIX_RTOL, unit="cm",
          what="2σ of the position recomputed from P_close with the engine",
          mistakes=right["bands"])
    if crossing is None:
        passed(f"{name} follows eq. (9) on {len(_COVARIANCE_CASES)} random cases, and "
               f"two_sigma matches the band grown from P_close by the pack's engine (to "
               f"{tolerance_text(MATRIX_RTOL)} relative)")
        return
    dt, steps = DEFAULT.dt, right["steps"]
    judge("crossing", crossing, right["crossing"], TIME_ATOL,
          unit="s", what="the first time 2σ exceeds the amplitude, recomputed",
          mistakes={
              "it is in samples; multiply by Δt to get seconds": steps,
              "it is one step early: the last time 2σ is still below the amplitude; the task "
              "asks for the first time it is above": (steps - 1) * dt,
              "it is one step late: take the first sample above the amplitude":
                  (steps + 1) * dt,
              f"it counts from the start of the trial; count from the moment the eyes close "
              f"(t = {EYES_CLOSE_TIME:g} s)": steps * dt + EYES_CLOSE_TIME,
              **right["other_crossings"],
          })
    passed(f"{name} follows eq. (9) on {len(_COVARIANCE_CASES)} random cases, and two_sigma "
           f"and crossing match the band grown from P_close by the pack's engine (to "
           f"{tolerance_text(MATRIX_RTOL)} relative and {tolerance_text(TIME_ATOL)} s)")


# ------------------------------------------------------------------------------------------
# Task 3: which time scale for σ_j?
# ------------------------------------------------------------------------------------------

#: Task 3's matching times T, as fractions of the flight's period, by the names the
#: notebook's ``periods`` dict uses.
PERIODS = {"an eighth": 1 / 8, "a quarter": 1 / 4, "a half": 1 / 2, "a whole": 1.0}


def _named(values: object, name: str, what: str) -> dict[str, object]:
    """The student's dict with one entry per name of :data:`PERIODS`."""
    return keyed_entries(
        values, name, tuple(PERIODS), what,
        keyed_by=f"the names of periods ({', '.join(repr(key) for key in PERIODS)})",
        advice="; use the names of periods as keys")


def _sigma_mistakes(fraction: float) -> dict[str, float]:
    """σ_j (cm/s³) with the usual slips of A ω² / √(Δt T), T = fraction / f."""
    a, f, dt = DEFAULT.amplitude, DEFAULT.frequency, DEFAULT.dt
    omega, T = 2 * np.pi * f, fraction / f
    return {
        "T is in periods, not seconds: T = (fraction of a period) / f": a * omega**2
        / np.sqrt(dt * fraction),
        "the period was taken as f; it is 1/f (2 s), so T = (fraction of a period) / f":
            a * omega**2 / np.sqrt(dt * fraction * f),
        "ω is f (Hz) where the angular frequency ω = 2πf (rad/s) belongs":
            a * f**2 / np.sqrt(dt * T),
        "ω is not squared: A ω is the peak speed; the peak acceleration is A ω²":
            a * omega / np.sqrt(dt * T),
        "it uses A ω³, the peak jerk; the acceleration's swing is A ω²":
            a * omega**3 / np.sqrt(dt * T),
        "the square root is missing: the spread of the random walk is σ_j √(Δt T)":
            a * omega**2 / (dt * T),
        "Δt is missing under the root: the random walk's spread after T is σ_j √(Δt T)":
            a * omega**2 / np.sqrt(T),
        "the root covers Δt only (√Δt · T); it covers the product, √(Δt T)":
            a * omega**2 / (np.sqrt(dt) * T),
        "it multiplies by T; T belongs under the root, in the denominator: A ω² / √(Δt T)":
            a * omega**2 / np.sqrt(dt) * T,
        "it is σ_j², a variance (cm²/s⁶); jerk_stds holds the standard deviation σ_j":
            (a * omega**2 / np.sqrt(dt * T)) ** 2,
        "it multiplies by √(Δt T); divide by it: σ_j = A ω² / √(Δt T)":
            a * omega**2 * np.sqrt(dt * T),
        "ω is 2π/f; the angular frequency is ω = 2πf (rad/s)":
            a * (2 * np.pi / f) ** 2 / np.sqrt(dt * T),
    }


def check_jerk_stds(jerk_stds: Mapping[str, float]) -> None:
    """Check Task 3: σ_j = A ω² / √(Δt T) for the four matching times of :data:`PERIODS`.

    Recomputed from the task's inputs (:func:`lqe_helpers.scenario.matched_jerk_std` for
    T = 1/8, 1/4, 1/2 and 1 period of the flight, in s), each within :data:`MATRIX_RTOL`
    relative. The Monte Carlo runs with these values are the notebook's given cell.

    Parameters
    ----------
    jerk_stds : dict of str to float
        σ_j (cm/s³) keyed "an eighth", "a quarter", "a half", "a whole".

    Raises
    ------
    CheckFailed
        Naming the entry and the likely cause: T in periods instead of seconds, the
        period taken as f, ω = f or 2π/f, ω not squared or cubed, no square root, the
        root over Δt only, Δt left out, ...
    """
    sigmas = _named(jerk_stds, "jerk_stds", "σ_j values (cm/s³)")
    values = {key: argument_array(sigmas[key], f"jerk_stds[{key!r}]", "one number (cm/s³)",
                                  shape=()) for key in PERIODS}
    right = {key: matched_jerk_std(DEFAULT.amplitude, DEFAULT.frequency, DEFAULT.dt, fraction)
             for key, fraction in PERIODS.items()}
    mistakes = {key: _sigma_mistakes(fraction) for key, fraction in PERIODS.items()}
    wrong = [key for key in PERIODS if not close(values[key], right[key], MATRIX_RTOL)]
    # A slip made in the loop shows in every entry: name the one that explains them all
    # (one entry alone can fit two slips, e.g. the eighth's √(Δt T f) = √Δt T).
    for cause in mistakes[wrong[0]] if wrong else ():
        if all(close(values[key], mistakes[key][cause], MATRIX_RTOL) for key in wrong):
            raise CheckFailed(f"jerk_stds[{wrong[0]!r}] = {float(values[wrong[0]]):.6g} cm/s³ "
                              f"is not right: {cause}")
    for key in wrong:
        judge(f"jerk_stds[{key!r}]", values[key], right[key], MATRIX_RTOL, unit="cm/s³",
              what="A ω² / √(Δt T) recomputed for this T", mistakes=mistakes[key])
    passed(f"σ_j = A ω² / √(Δt T) for T = 1/8, 1/4, 1/2 and 1 period of the flight, to "
           f"{tolerance_text(MATRIX_RTOL)} relative")
