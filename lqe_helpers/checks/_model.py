"""Checks of notebooks 00 and 06: A, the covariance step of eq. (9), the bias model."""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from .. import bias_model, model
from ._common import (
    MATRIX_RTOL,
    SEED,
    CheckFailed,
    as_result_array,
    call_student,
    close,
    matrix_argument,
    passed,
    positive_number,
    require_callable,
    tolerance_text,
)

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
    answers = {}
    for dt in _TRANSITION_DTS:
        output = call_student(make_A, name, (dt,), f"dt = {dt:g} s")
        array = as_result_array(output, name, (3, 3), "the transition matrix A")
        if array.shape != (3, 3):
            raise CheckFailed(
                f"{name}({dt:g}) returned shape {array.shape}; A must be 3 × 3, one row and "
                f"one column per state (p, v, a)")
        answers[dt] = array
    wrong = [dt for dt, array in answers.items()
             if not close(array, model.transition_matrix(dt), MATRIX_RTOL)]
    if not wrong:
        passed(f"{name} gives eq. (4)'s A (constant acceleration) at {len(answers)} time "
               f"steps from {min(_TRANSITION_DTS):g} to {max(_TRANSITION_DTS):g} s, to "
               f"{tolerance_text(MATRIX_RTOL)}")
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
    wrong = []
    for P, F, G, sigma in _covariance_cases():
        inputs = (P.copy(), F.copy(), G.copy(), sigma)
        where = f"P and F of shape {P.shape}, G of shape {G.shape}, sigma = {sigma:.3g}"
        output = call_student(
            predict_covariance, name, inputs, where,
            shape_hint="P and F are (k, k), G is (k, r): write each term's shape.")
        for label, given, original in zip(("P", "F", "G"), inputs, (P, F, G), strict=False):
            if not np.array_equal(given, original):
                raise CheckFailed(f"{name} changed its input {label} in place ({where}); "
                                  f"return a new matrix instead")
        array = as_result_array(output, name, P.shape, "the new covariance P")
        if array.shape != P.shape:
            raise CheckFailed(f"{name} returned shape {array.shape} for {where}; the new "
                              f"covariance has the shape of P, {P.shape}")
        right = F @ P @ F.T + sigma**2 * G @ G.T
        if not close(array, right, MATRIX_RTOL):
            wrong.append((array, P, F, G, sigma, where))
    if not wrong:
        passed(f"{name} gives F P Fᵀ + G σ² Gᵀ (Lesson 0.5 eq. (9)) on "
               f"{len(_COVARIANCE_CASES)} random cases (1–4 states, 1–2 inputs), to "
               f"{tolerance_text(MATRIX_RTOL)}")
        return
    for key in ("sides", "no_noise", "sigma", "no_transpose", "not_moved"):
        if all(close(array, _covariance_mistakes(P, F, G, sigma)[key][0], MATRIX_RTOL)
               for array, P, F, G, sigma, _ in wrong):
            raise CheckFailed(f"{name} does not follow eq. (9): "
                              f"{_covariance_mistakes(*wrong[0][1:5])[key][1]}")
    raise CheckFailed(
        f"{name} does not give F P Fᵀ + G σ² Gᵀ on {wrong[0][5]}, and not by one of the "
        f"usual mistakes")


def check_bias_model(F: np.ndarray, G: np.ndarray, Q: np.ndarray, dt: float,
                     sigma_a: float) -> None:
    """Check F, G and Q of the biased acceleration model (Lesson 0.5 eqs. (4), (5), (9)).

    Expected, for the state [p, v, b] and the input u = a_r (cm/s²):
    ``F = [[1, Δt, −Δt²/2], [0, 1, −Δt], [0, 0, 1]]``, ``G = [Δt²/2, Δt, 0]ᵀ`` (shape
    (3, 1)) and ``Q = G σ_a² Gᵀ``, each within :data:`MATRIX_RTOL`
    (:mod:`lqe_helpers.bias_model`).

    Parameters
    ----------
    F : array_like, shape (3, 3)
    G : array_like, shape (3, 1)
    Q : array_like, shape (3, 3)
        The student's matrices.
    dt : float
        The time step they were built for (s), > 0.
    sigma_a : float
        The signal's noise they were built for (cm/s²), > 0.

    Raises
    ------
    CheckFailed
        With the mistake named: shapes, the bias added instead of removed, Δt² without
        the half, a row for the bias in G, σ_a instead of σ_a², ...
    """
    dt = positive_number(dt, "dt", "s")
    sigma_a = positive_number(sigma_a, "sigma_a", "cm/s²")
    F = matrix_argument(F, "F")
    G = matrix_argument(G, "G")
    Q = matrix_argument(Q, "Q")
    right_F = bias_model.transition_matrix(dt)
    right_G = bias_model.input_matrix(dt)
    if F.shape != (3, 3):
        raise CheckFailed(f"F must be 3 × 3 (state [p, v, b]), got shape {F.shape}")
    if G.shape == (3,):
        raise CheckFailed("G has shape (3,): make it a column, shape (3, 1), so that G σ² Gᵀ "
                          "is a 3 × 3 matrix")
    if G.shape != (3, 1):
        raise CheckFailed(f"G must have shape (3, 1): one row per state, one column for the "
                          f"single input; got shape {G.shape}")
    if not close(F, right_F, MATRIX_RTOL):
        if close(F[:, :2], right_F[:, :2], MATRIX_RTOL) and close(F[:2, 2], -right_F[:2, 2],
                                                                  MATRIX_RTOL):
            raise CheckFailed(
                "F's last column adds the bias; the reading a_r = a + b carries the bias, so "
                "the model must remove its estimate: the entries are −Δt²/2 and −Δt")
        if close(F[:, :2], right_F[:, :2], MATRIX_RTOL) and np.allclose(F[:2, 2], 0):
            raise CheckFailed(
                "F's last column does not correct for the bias (zeros above the diagonal): "
                "the bias estimate must be subtracted from the reading, −Δt²/2 and −Δt")
        if close(F[0, 2], -dt**2, MATRIX_RTOL) or close(F[0, 2], dt**2, MATRIX_RTOL):
            raise CheckFailed("F[0, 2] holds Δt²; the position integrates the acceleration "
                              "over a step with Δt²/2")
        raise CheckFailed(
            "F is not Lesson 0.5 eq. (5)'s transition matrix for [p, v, b]: p moves by Δt v "
            "and by Δt²/2 times (reading − bias), v by Δt times it, b stays")
    if not close(G, right_G, MATRIX_RTOL):
        if close(G[:2], right_G[:2], MATRIX_RTOL):
            raise CheckFailed("G's last entry must be 0: the reading does not change the bias")
        if close(G[0], np.array([dt**2]), MATRIX_RTOL):
            raise CheckFailed("G[0] holds Δt²; the position takes Δt²/2 of the reading")
        raise CheckFailed("G is not Lesson 0.5 eq. (5)'s input matrix: the reading enters the "
                          "position with Δt²/2, the velocity with Δt, the bias not at all")
    right_Q = sigma_a**2 * right_G @ right_G.T
    if Q.shape != (3, 3):
        raise CheckFailed(f"Q must be 3 × 3, got shape {Q.shape}")
    if not close(Q, right_Q, MATRIX_RTOL):
        if close(Q, sigma_a * right_G @ right_G.T, MATRIX_RTOL):
            raise CheckFailed("Q uses σ_a where its square belongs: Q = G σ_a² Gᵀ (variances, "
                              "not standard deviations)")
        if close(Q, sigma_a**2 * np.eye(3), MATRIX_RTOL) or close(
                Q, sigma_a**2 * np.diag(right_G[:, 0]), MATRIX_RTOL):
            raise CheckFailed("Q is not pushed through G: the signal's noise reaches the "
                              "state the way the signal does, Q = G σ_a² Gᵀ")
        if close(Q, sigma_a**2 * right_G.T @ right_G, MATRIX_RTOL):
            raise CheckFailed("Q is built as Gᵀ G (one number); the covariance is G σ_a² Gᵀ, "
                              "3 × 3")
        raise CheckFailed("Q is not G σ_a² Gᵀ (Lesson 0.5 eq. (9)) for the given σ_a")
    passed(f"F, G and Q = G σ_a² Gᵀ match Lesson 0.5 eqs. (5), (9) for Δt = {dt:g} s and "
           f"σ_a = {sigma_a:g} cm/s², to {tolerance_text(MATRIX_RTOL)}")
