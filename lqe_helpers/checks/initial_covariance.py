"""Checks of notebook 02, question (b): the initial covariance P0 and the convergence time."""

from __future__ import annotations

import numpy as np

from .. import metrics
from .machinery import (
    MATRIX_RTOL,
    TIME_ATOL,
    CheckFailed,
    argument_array,
    passed,
    positive_number,
    tolerance_text,
)

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback


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
    P0 = argument_array(P0, "P0", "the initial covariance, a 3 × 3 matrix (cm², cm²/s², cm²/s⁴)")
    if P0.ndim == 0:
        raise CheckFailed(
            f"P0 is a single number ({float(P0):g}). The filter needs a 3 × 3 matrix, "
            f"one row and column per state (p, v, a), with the variances on its diagonal")
    if P0.shape == (3,):
        raise CheckFailed(
            "P0 is a vector of 3 numbers. It must be a 3 × 3 matrix with these variances "
            "on its diagonal and 0 elsewhere")
    if P0.shape != (3, 3):
        raise CheckFailed(
            f"P0 must be 3 × 3 (one row and column per state p, v, a), got shape {P0.shape}")
    off = P0 - np.diag(np.diag(P0))
    if np.any(off != 0):
        if np.allclose(P0, variance, rtol=MATRIX_RTOL, atol=0):
            raise CheckFailed(
                f"every entry of P0 is {variance:g}. Only the diagonal holds the "
                f"variances; the off-diagonal entries (covariances between p, v and a) "
                f"are 0")
        raise CheckFailed(
            "P0 has non-zero off-diagonal entries; diag(…) means the variances on the "
            "diagonal and 0 everywhere else")
    diagonal = np.diag(P0)

    def same(value: float) -> bool:
        return bool(np.allclose(diagonal, value, rtol=MATRIX_RTOL, atol=0))

    if same(variance):
        passed(f"P0 = {variance:g} · I (3 × 3, diagonal) cm²")
        return
    if same(np.sqrt(variance)):
        raise CheckFailed(
            f"P0's diagonal holds √{variance:g} = {np.sqrt(variance):g}, a standard "
            f"deviation. P0 is a covariance: its diagonal holds the variance, {variance:g}")
    if same(variance**2):
        raise CheckFailed(
            f"P0's diagonal holds {variance:g}² = {variance**2:g}: the variance was squared "
            f"again. The diagonal holds the variance itself, {variance:g}")
    if not np.allclose(diagonal, diagonal[0], rtol=MATRIX_RTOL, atol=0):
        raise CheckFailed(
            f"P0's diagonal entries differ ({diagonal.tolist()}); diag({variance:g}, "
            f"{variance:g}, {variance:g}) has the same variance for each state")
    raise CheckFailed(
        f"P0's diagonal holds {diagonal[0]:g}, expected the variance {variance:g}")


def check_convergence_time(value: float, squared_error: np.ndarray, dt: float,
                           factor: float = 2.0) -> None:
    """Check a convergence time against the pack's definition (:func:`metrics.convergence_time`).

    The convergence time is the first sample time after which the Monte Carlo mean of
    the squared error stays within ``factor`` × its mean over the second half of the
    trial. ``squared_error`` is either that mean curve, shape (n,), or the squared errors
    of every run, shape (runs, n), whose mean over runs is then taken here. Tolerance
    :data:`TIME_ATOL` s (the time is a whole number of samples).

    Parameters
    ----------
    value : float
        The student's convergence time (s).
    squared_error : array_like, shape (n,) or (runs, n)
        Squared position errors (cm²): the Monte Carlo mean curve, or every run.
    dt : float
        Time step (s), > 0.
    factor : float
        Width of the band around the steady level, as in :func:`metrics.convergence_time`.

    Raises
    ------
    CheckFailed
        With the mistake named: steps instead of seconds, one run or per-run times
        instead of the Monte Carlo mean, first entry into the band, ...
    """
    dt = positive_number(dt, "dt", "s")
    factor = positive_number(factor, "factor", "")
    curves = argument_array(squared_error, "squared_error",
                            "squared errors (cm²), shape (n,) or (runs, n)")
    if curves.ndim not in (1, 2):
        raise CheckFailed(
            f"squared_error must have shape (n,) (the Monte Carlo mean curve) or (runs, n) "
            f"(every run), got shape {curves.shape}")
    curve = curves if curves.ndim == 1 else curves.mean(axis=0)
    try:
        expected = float(metrics.convergence_time(curve, dt, factor))
    except ValueError as error:
        raise CheckFailed(f"check_convergence_time could not use squared_error: {error}") \
            from None
    got = argument_array(value, "your convergence time", "a number of seconds")
    mean_of = "the Monte Carlo mean squared error" if curves.ndim == 2 else "the curve"

    def same(a: object, b: float) -> bool:
        return bool(np.allclose(a, b, rtol=0.0, atol=TIME_ATOL))

    if curves.ndim == 2 and got.shape == (curves.shape[0],):
        raise CheckFailed(
            f"your value holds one convergence time per run ({got.size} values). The definition "
            f"applies to the Monte Carlo mean: average the squared errors over the runs "
            f"first, then take one convergence time of that mean curve")
    if got.size != 1:
        raise CheckFailed(f"your convergence time must be one number (s), got shape {got.shape}")
    got = float(got.reshape(()))
    if not np.isfinite(got):
        raise CheckFailed(f"your convergence time must be a finite number of seconds, got {got}")
    if same(got, expected):
        passed(f"convergence time matches the pack's definition (first time after which "
               f"{mean_of} stays within {factor:g} × its second-half level) to "
               f"{tolerance_text(TIME_ATOL)} s")
        return
    single_run = ("your convergence time is that of a single run ({}). The definition "
                  "applies to the Monte Carlo mean: average the squared errors over the "
                  "runs first")
    mistakes = [
        (expected / dt, "your convergence time is in samples (time steps): give it in "
                        f"seconds, samples × Δt (Δt = {dt:g} s)"),
        (expected * 1000.0, "your convergence time is in milliseconds: give it in seconds"),
    ]
    if curves.ndim == 2:
        per_run = metrics.convergence_time(curves, dt, factor)
        mistakes += [
            (float(per_run[0]), single_run.format("the first")),
            (float(per_run[-1]), single_run.format("the last")),
            (float(np.mean(per_run)), "your convergence time is the mean of the runs' "
                                      "convergence times. The definition averages the "
                                      "squared errors over the runs first, then takes one "
                                      "convergence time"),
        ]
    n = curve.size
    steady = np.mean(curve[n // 2:])
    inside = curve <= factor * steady
    if inside.any():
        mistakes.append((float(np.argmax(inside)) * dt,
                         "your convergence time is the first time the curve enters the "
                         "band; the definition asks for the time after which it stays "
                         "inside for good (it may leave the band again after entering it)"))
    if expected > 0:
        mistakes.append((expected - dt,
                         "your convergence time is the time of the last sample outside the "
                         "band; the convergence time is the sample just after it, the "
                         "first that stays inside"))
    for level, text in ((np.mean(curve), "the mean of the whole curve"),
                        (curve[-1], "the last sample")):
        outside = curve > factor * level
        time = (n - int(np.argmax(outside[::-1]))) * dt if outside.any() else 0.0
        mistakes.append((time, f"the steady level is taken as {text}; the definition uses "
                               f"the mean over the second half of the trial"))
    for candidate, message in mistakes:
        if same(got, candidate) and not same(candidate, expected):
            raise CheckFailed(message)
    raise CheckFailed(
        f"your convergence time, {got:g} s, is not the convergence time of {mean_of} by the pack's "
        f"definition (first sample time after which it stays <= {factor:g} × its mean "
        f"over the second half of the trial), and not by one of the usual mistakes")
