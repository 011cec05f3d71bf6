"""Checks of the numbers a task produces: P0, MSEs, convergence times, paired differences."""

from __future__ import annotations

import numpy as np

from .. import metrics
from ._common import (
    INTERVAL_RTOL,
    MATRIX_RTOL,
    MSE_RTOL,
    TIME_ATOL,
    CheckFailed,
    describe_type,
    matrix_argument,
    passed,
    positive_number,
    tolerance_text,
)


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
    P0 = matrix_argument(P0, "P0")
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


def check_mse(value: float | np.ndarray, estimate: np.ndarray, truth: np.ndarray,
              burn_in_steps: int = 0) -> None:
    """Check a mean squared error against :func:`metrics.mse` (relative tolerance 1e-6).

    Parameters
    ----------
    value : float or array_like, shape (...)
        The student's MSE (cm²): one number for one run, one per run for a batch (or
        the mean over the runs as one number).
    estimate : array_like, shape (..., n)
        Estimated positions (cm).
    truth : array_like, shape (n,)
        True positions (cm).
    burn_in_steps : int
        Samples skipped at the start.

    Raises
    ------
    CheckFailed
        With the mistake named: RMSE instead of MSE, burn-in not skipped or a different
        one, a sum instead of a mean, errors not squared, ...
    """
    try:
        expected = metrics.mse(estimate, truth, burn_in_steps)
    except ValueError as error:
        positions = ("" if "NaN" in str(error) else
                     ". It expects positions (cm): estimate of shape (n,) or (runs, n) and "
                     "truth of shape (n,), e.g. the position column of the states")
        raise CheckFailed(f"check_mse could not compute the MSE from your estimate and "
                          f"truth: {error}{positions}") from None
    got = matrix_argument(value, "value")
    if got.size == 1 and (expected.ndim == 0 or expected.size > 1):
        got = got.reshape(())   # one number: the MSE of one run, or the mean over runs
    estimate = np.asarray(estimate, dtype=float)
    truth = np.asarray(truth, dtype=float)
    runs = expected.size if expected.ndim else 0
    skipped = f"skipping the first {burn_in_steps} samples" if burn_in_steps else "whole trial"

    def same(a: np.ndarray, b: np.ndarray) -> bool:
        return bool(np.shape(a) == np.shape(b)
                    and np.allclose(a, b, rtol=MSE_RTOL, atol=0.0, equal_nan=False))

    if got.shape == expected.shape and same(got, expected):
        what = f"{runs} MSEs (one per run)" if runs else "MSE"
        passed(f"{what} match{'es' * (not runs)} metrics.mse (positions, {skipped}) to "
               f"rtol {tolerance_text(MSE_RTOL)}")
        return
    if runs and got.ndim == 0 and same(got, np.mean(expected)):
        passed(f"mean MSE over {runs} runs matches metrics.mse (positions, {skipped}) to "
               f"rtol {tolerance_text(MSE_RTOL)}")
        return
    if got.shape != expected.shape and not (runs and got.ndim == 0):
        raise CheckFailed(
            f"your MSE has shape {got.shape}, expected {expected.shape} (one MSE "
            f"{'per run' if runs else 'for the trial'}) for estimate of shape "
            f"{estimate.shape}")
    if not np.all(np.isfinite(got)):
        raise CheckFailed("your MSE contains NaN or infinite numbers")
    if got.shape != expected.shape:
        expected = np.mean(expected)
        estimate = estimate.reshape(-1, estimate.shape[-1])
    kept = estimate[..., burn_in_steps:] - truth[burn_in_steps:]

    def pooled(per_run: np.ndarray) -> np.ndarray:
        return per_run if np.ndim(per_run) == np.ndim(got) else np.mean(per_run)

    mistakes = [
        (np.sqrt(expected), "your MSE is the root mean squared error (RMSE, in cm): the MSE "
                            "is its square, in cm², without the root"),
        (expected * kept.shape[-1], "your MSE is the sum of the squared errors: the MSE is "
                                    "their mean over the samples"),
        (pooled(np.mean(kept, axis=-1)), "your MSE is the mean error (the errors are not "
                                         "squared): square each error, then average"),
        (pooled(np.mean(np.abs(kept), axis=-1)), "your MSE is the mean absolute error: square "
                                                 "each error, then average"),
        (pooled(np.var(kept, axis=-1)), "your MSE is the variance of the error (its mean is "
                                        "subtracted): the MSE averages the squared errors "
                                        "themselves, bias included"),
    ]
    for candidate, message in mistakes:
        if same(got, candidate) and not same(candidate, expected):
            raise CheckFailed(message)
    if burn_in_steps > 0 and np.all(np.isfinite(estimate)):
        whole = pooled(metrics.mse(estimate, truth, 0))
        if same(got, whole):
            raise CheckFailed(
                f"your MSE is the MSE of the whole trial: the first burn_in_steps = "
                f"{burn_in_steps} samples were not skipped")
    other = _matching_burn_in(got, estimate, truth)
    if other is not None and other != burn_in_steps:
        raise CheckFailed(
            f"your MSE is the MSE after skipping {other} sample{'s' * (other != 1)}, but "
            f"burn_in_steps = "
            f"{burn_in_steps}. Skip exactly the burn-in (in samples, not seconds) and tell "
            f"the check the same number")
    raise CheckFailed(
        f"your MSE does not match the MSE of these positions ({skipped}), and not by one of "
        f"the usual mistakes: the MSE is the mean over the samples of (estimate − truth)²")


def _matching_burn_in(got: np.ndarray, estimate: np.ndarray, truth: np.ndarray) -> int | None:
    """The burn-in (samples) whose MSE equals ``got``, if there is one.

    ``got`` has the shape of one MSE per run, or is one number for the mean over runs.
    """
    squared = (estimate - truth) ** 2
    if not np.all(np.isfinite(squared)):
        return None
    n = squared.shape[-1]
    tail_sums = np.cumsum(squared[..., ::-1], axis=-1)[..., ::-1]    # sum from b on
    per_burn_in = np.moveaxis(tail_sums / (n - np.arange(n)), -1, 0)  # (n, ...)
    if np.ndim(got) == 0 and per_burn_in.ndim > 1:
        per_burn_in = per_burn_in.reshape(n, -1).mean(axis=1)
    for b in range(n):
        if np.allclose(got, per_burn_in[b], rtol=MSE_RTOL, atol=0.0):
            return b
    return None


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
    curves = matrix_argument(squared_error, "squared_error")
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
    got = matrix_argument(value, "value")
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


def check_paired_difference(interval: metrics.Interval, mse_first: np.ndarray,
                            mse_second: np.ndarray) -> None:
    """Check a paired Monte Carlo difference against ``metrics.mean_ci95(first − second)``.

    ``mse_first`` and ``mse_second`` hold one MSE per run, computed on the same noise
    in run r; the answer to "is the first larger?" is the mean of the per-run
    differences with its 95 % Student-t interval. Tolerance :data:`INTERVAL_RTOL`
    relative to the interval's scale.

    Parameters
    ----------
    interval : metrics.Interval
        The student's interval (anything with ``mean``, ``low``, ``high``; ``runs`` is
        compared too if present).
    mse_first, mse_second : array_like, shape (runs,)
        Per-run MSEs (cm²) of the two conditions, run r of both on the same noise.

    Raises
    ------
    CheckFailed
        With the mistake named: not an Interval, reversed sign, unpaired interval, two
        intervals subtracted, standard deviation instead of standard error, 1.96 instead
        of the t value, the interval of one MSE alone, ...
    """
    first = _runs_argument(mse_first, "mse_first")
    second = _runs_argument(mse_second, "mse_second")
    if first.shape != second.shape:
        raise CheckFailed(
            f"mse_first and mse_second must hold one MSE per run for the same runs, got "
            f"shapes {first.shape} and {second.shape}")
    if not all(hasattr(interval, attribute) for attribute in ("mean", "low", "high")):
        if isinstance(interval, (tuple, list)) and len(interval) == 2:
            found = "a pair of numbers"
        elif np.isscalar(interval) or isinstance(interval, np.ndarray):
            found = "a number (or array)" if np.isscalar(interval) else "an array"
        else:
            found = describe_type(interval)
        raise CheckFailed(
            f"your interval is {found}; it must be the metrics.Interval that metrics.mean_ci95 "
            f"returns (its mean, low and high), since a difference means little without "
            f"its 95 % interval")
    runs = first.size
    if getattr(interval, "runs", runs) != runs:
        raise CheckFailed(
            f"your interval is over {interval.runs} runs, but mse_first has {runs}: use the "
            f"per-run differences of all {runs} runs")
    got = np.array([interval.mean, interval.low, interval.high], dtype=float)
    if not np.all(np.isfinite(got)):
        raise CheckFailed("your interval contains NaN or infinite numbers")
    difference = first - second
    expected = metrics.mean_ci95(difference)
    scale = max(abs(expected.mean), expected.half_width, 1e-300)

    def same(a: tuple[float, float, float]) -> bool:
        return bool(np.all(np.abs(got - np.asarray(a)) <= INTERVAL_RTOL * scale))

    def around(mean: float, half: float) -> tuple[float, float, float]:
        return (mean, mean - half, mean + half)

    if same((expected.mean, expected.low, expected.high)):
        passed(f"paired difference: mean and 95 % interval match metrics.mean_ci95 of "
               f"mse_first − mse_second over {runs} runs (to {tolerance_text(INTERVAL_RTOL)} "
               f"relative)")
        return
    t = metrics.t_critical_95(runs - 1)
    s = float(np.std(difference, ddof=1))
    one_first, one_second = metrics.mean_ci95(first), metrics.mean_ci95(second)
    reverse = metrics.mean_ci95(second - first)
    unpaired = t * np.sqrt((np.var(first, ddof=1) + np.var(second, ddof=1)) / runs)
    mistakes = [
        ((reverse.mean, reverse.low, reverse.high),
         "the sign is reversed: your interval is of mse_second − mse_first; the check "
         "(and the question) wants mse_first − mse_second"),
        (around(expected.mean, one_first.half_width + one_second.half_width),
         "your interval combines the two MSEs' separate intervals. The runs are paired "
         "(the same noise in run r), so take the interval of the per-run differences: it "
         "is much narrower because the shared noise cancels"),
        (around(expected.mean, unpaired),
         "your interval treats the two MSEs as independent samples (unpaired). The runs "
         "are paired (the same noise in run r): take the interval of the per-run "
         "differences"),
        (around(expected.mean, t * s),
         "your half-width uses the standard deviation of the differences; a 95 % interval "
         "of the mean uses its standard error, the standard deviation divided by √runs"),
        (around(expected.mean, 1.959963984540054 * s / np.sqrt(runs)),
         "your half-width uses the normal 1.96 instead of Student's t value for "
         f"{runs - 1} degrees of freedom (metrics.mean_ci95 does this for you)"),
        (around(expected.mean, t * float(np.std(difference)) / np.sqrt(runs)),
         "the standard deviation is the population one (divided by runs); a sample "
         "standard deviation divides by runs − 1"),
        ((one_first.mean, one_first.low, one_first.high),
         "your interval is that of mse_first alone, not of the differences "
         "mse_first − mse_second"),
        ((one_second.mean, one_second.low, one_second.high),
         "your interval is that of mse_second alone, not of the differences "
         "mse_first − mse_second"),
    ]
    for candidate, message in mistakes:
        if same(candidate):
            raise CheckFailed(message)
    if abs(got[0] - expected.mean) <= INTERVAL_RTOL * scale:
        raise CheckFailed(
            "the mean difference is right but the interval's ends are not those of "
            "metrics.mean_ci95 of the per-run differences")
    raise CheckFailed(
        "your interval is not the mean of mse_first − mse_second per run with its 95 % interval, "
        "and not by one of the usual mistakes")


def _runs_argument(value: object, name: str) -> np.ndarray:
    array = matrix_argument(value, name)
    if array.ndim != 1 or array.size < 2:
        raise CheckFailed(
            f"{name} must hold one MSE per Monte Carlo run, shape (runs,) with runs >= 2, "
            f"got shape {array.shape}")
    return array
