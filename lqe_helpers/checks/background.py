"""Checks of notebook 00, the background: A of eq. (4) and the covariance step of eq. (9)."""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from .. import model
from .machinery import (
    MATRIX_RTOL,
    SEED,
    CheckFailed,
    call_student,
    close,
    passed,
    require_callable,
    student_result,
    time_limit_text,
    tolerance_text,
)

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


def check_transition_matrix(make_A: Callable[[float], np.ndarray]) -> None:
    """Check a student's ``make_A(dt)`` against Tutorial eq. (4) (constant acceleration).

    The function is called at several time steps (:data:`_TRANSITION_DTS`, s) and must
    return the 3 × 3 matrix ``[[1, Δt, Δt²/2], [0, 1, Δt], [0, 0, 1]]`` for the state
    [p, v, a], equal to :func:`model.transition_matrix` within :data:`MATRIX_RTOL`.

    Parameters
    ----------
    make_A : callable
        The student's function of the time step Δt (s).

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
        output = call_student(make_A, dt, name=name, where=f"dt = {dt:g} s", arg_names=("dt",))
        array = student_result(output, name=name, where=f"dt = {dt:g} s",
                               what="the transition matrix A, an array of shape (3, 3)")
        if array.shape != (3, 3):
            raise CheckFailed(
                f"{name}({dt:g}) returned shape {array.shape}; A must be 3 × 3, one row and "
                f"one column per state (p, v, a)")
        answers[dt] = array
    wrong = [dt for dt, array in answers.items() if not close(array, right[dt], MATRIX_RTOL)]
    if not wrong:
        passed(f"{name} gives eq. (4)'s A (constant acceleration) at {len(answers)} time "
               f"steps from {min(_TRANSITION_DTS):g} to {max(_TRANSITION_DTS):g} s, to "
               f"{tolerance_text(MATRIX_RTOL)}, {time_limit_text()}")
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


#: (states k, inputs r) of the random cases of :func:`check_covariance_step`.
_COVARIANCE_CASES = ((3, 1), (2, 1), (4, 2), (1, 1), (3, 2))


@functools.cache
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
        "not_moved": (P + noise, "P is not carried through the model: the old covariance "
                                 "must be moved one step by F (F P Fᵀ) before the noise is "
                                 "added"),
    }


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
        sides, no noise term, σ instead of σ², no transpose, P not moved by F).
    """
    name = require_callable(predict_covariance, "predict_covariance", "check_covariance_step")
    cases = _covariance_cases()
    right = [F @ P @ F.T + sigma**2 * G @ G.T for P, F, G, sigma in cases]
    wrong = []
    for (P, F, G, sigma), expected in zip(cases, right, strict=True):
        where = f"P and F of shape {P.shape}, G of shape {G.shape}, sigma = {sigma:.3g}"
        output = call_student(
            predict_covariance, P, F, G, sigma, name=name, where=where,
            arg_names=("P", "F", "G", "sigma"),
            shape_hint="P and F are (k, k), G is (k, r): write each term's shape.")
        array = student_result(output, name=name, where=where,
                               what=f"the new covariance P, an array of shape {P.shape}")
        if array.shape != P.shape:
            raise CheckFailed(f"{name} returned shape {array.shape} for {where}; the new "
                              f"covariance has the shape of P, {P.shape}")
        if not close(array, expected, MATRIX_RTOL):
            wrong.append((array, P, F, G, sigma, where))
    if not wrong:
        passed(f"{name} gives F P Fᵀ + G σ² Gᵀ (Lesson 0.5 eq. (9)) on "
               f"{len(_COVARIANCE_CASES)} random cases (1–4 states, 1–2 inputs), to "
               f"{tolerance_text(MATRIX_RTOL)}, {time_limit_text()}")
        return
    for key in ("sides", "no_noise", "sigma", "no_transpose", "not_moved"):
        if all(close(array, _covariance_mistakes(P, F, G, sigma)[key][0], MATRIX_RTOL)
               for array, P, F, G, sigma, _ in wrong):
            raise CheckFailed(f"{name} does not follow eq. (9): "
                              f"{_covariance_mistakes(*wrong[0][1:5])[key][1]}")
    raise CheckFailed(
        f"{name} does not give F P Fᵀ + G σ² Gᵀ on {wrong[0][5]}, and not by one of the "
        f"usual mistakes")
