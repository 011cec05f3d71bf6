"""Judging a student's number against an independent recomputation, naming likely mistakes.

A number check recomputes what the task asks from the task's own inputs and draws (the
same seed, the pack's engine), before looking at the student's value, and hands both to
:func:`judge` (a number or an array) or :func:`judge_interval` (a mean with its 95 %
interval), with a catalogue of likely mistakes, each computed from the same inputs::

    judge("mse_filtered[4.5]", value, expected, MSE_RTOL, unit="cm²",
          what="the filtered estimate's MSE",
          mistakes={"R holds σ_v where the variance σ_v² belongs ...": mse_with_r_sigma,
                    **mse_mistakes(positions, truth, burn, dt)})

The first mistake that matches the student's value (and not the right one) names the
cause in the message, in words, without code. :func:`mse_mistakes` and
:func:`interval_mistakes` give the mistakes every MSE and every paired difference can have;
:func:`burn_in_slips` the burn-in off by one sample, for a check that makes its own MSEs.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from .. import metrics
from .machinery import TIME_ATOL, CheckFailed, argument_array, tolerance_text

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: Centimetres in a metre: readings a student converts to metres are the cm ones divided by it.
CM_PER_M = 100.0

#: The normal distribution's two-sided 95 % point, the usual wrong stand-in for Student's t.
NORMAL_95 = 1.959963984540054


def _shown(value: np.ndarray, unit: str) -> str:
    if value.ndim == 0:
        return f" = {float(value):.6g}{f' {unit}' if unit else ''}"
    return ""


def judge(name: str, value: object, expected: object, rtol: float, *,
          mistakes: Mapping[str, object] | None = None, unit: str = "",
          what: str = "the value recomputed from the task's inputs", nan_hint: str = "",
          hint: str = "") -> np.ndarray:
    """Judge a student's number (or array) against an independent recomputation.

    Parameters
    ----------
    name : str
        The student's variable as they wrote it ("mse_filtered[4.5]").
    value : object
        The student's value: one real number (a size-1 array counts as one), or an array
        of ``expected``'s shape.
    expected : float or array_like
        The right value, recomputed from the task's inputs before looking at ``value``.
    rtol : float
        Tolerance, relative to the largest entry of ``expected`` (stated by the caller in
        its ✓ line).
    mistakes : mapping of str to value, optional
        Likely mistakes, in the order they are tried: the cause, in words for the
        student, → the value that mistake gives on the task's inputs (None: cannot occur
        here). A mistake that agrees with ``expected`` cannot explain a wrong value and
        is skipped.
    unit : str
        Unit of the value, for messages ("cm²").
    what : str
        What the value is compared with, for the message when no mistake matches ("the
        filtered MSE recomputed from the task's inputs").
    nan_hint : str
        Said when the value is NaN (e.g. "the first δ samples have no estimate yet").
    hint : str
        Added to the message when no mistake matches.

    Returns
    -------
    ndarray
        The student's value as a float array, if it agrees.

    Raises
    ------
    CheckFailed
        Naming ``name``: not a real number (array) of the right shape, NaN or infinite,
        a matching mistake's cause, or that it does not match and not by a usual mistake.
    """
    expected = np.asarray(expected, dtype=float)
    due = ("one number" if expected.ndim == 0 else f"an array of shape {expected.shape}") + (
        f" ({unit})" if unit else "")
    got = argument_array(value, name, due, allow_nan=True)
    if expected.ndim == 0 and got.size == 1:
        got = got.reshape(())
    if got.shape != expected.shape:
        raise CheckFailed(f"{name} must be {due}, got an array of shape {got.shape}")
    if np.any(np.isnan(got)):
        raise CheckFailed(f"{name} is NaN (not a number){f': {nan_hint}' if nan_hint else ''}")
    scale = float(np.max(np.abs(expected))) if expected.size else 1.0

    def near(a: np.ndarray, b: np.ndarray) -> bool:
        size = max(scale, float(np.max(np.abs(b))) if b.size else 0.0) or 1.0
        return bool(np.all(np.abs(a - b) <= rtol * size))

    if near(got, expected):
        return got
    for cause, candidate in (mistakes or {}).items():
        if candidate is None:
            continue
        wrong = np.asarray(candidate, dtype=float)
        if wrong.shape != expected.shape or not np.all(np.isfinite(wrong)) or near(
                wrong, expected):
            continue
        if near(got, wrong):
            raise CheckFailed(f"{name}{_shown(got, unit)} is not right: {cause}")
    raise CheckFailed(
        f"{name}{_shown(got, unit)} does not match {what} (to {tolerance_text(rtol)} "
        f"relative), and not by one of the usual mistakes{f': {hint}' if hint else ''}")


def _matching_causes(got: np.ndarray, expected: np.ndarray,
                     mistakes: dict[str, float | np.ndarray | None],
                     near: Callable[[np.ndarray, np.ndarray], bool]) -> list[str]:
    """Every cause whose value explains ``got`` (and not ``expected``), in order.

    Times are whole samples, so two slips can give the same time: each is then named.
    """
    causes = []
    for cause, wrong in mistakes.items():
        if wrong is None:
            continue
        wrong = np.asarray(wrong, dtype=float)
        if wrong.shape == expected.shape and not near(wrong, expected) and near(got, wrong):
            causes.append(cause)
    return causes


def _either(causes: list[str]) -> str:
    """One cause as it is; several that give the same time, each named ("either … or …")."""
    if len(causes) == 1:
        return causes[0]
    return ("two or more slips give this same time; it is one of these: "
            + "; or ".join(causes))


def judge_seconds(name: str, value: object, expected: float | np.ndarray,
                  mistakes: dict[str, float | np.ndarray | None], what: str) -> np.ndarray:
    """CheckFailed unless ``value`` equals ``expected`` (s) within :data:`TIME_ATOL`.

    ``expected`` is one time or an array of times; ``mistakes`` maps a cause, in words,
    to the value(s) that mistake gives (None: cannot occur). Returns the student's value.
    """
    expected = np.asarray(expected, dtype=float)
    due = ("one number of seconds" if expected.ndim == 0
           else f"an array of shape {expected.shape} (s)")
    got = argument_array(value, name, due, allow_nan=True)
    if expected.ndim == 0 and got.size == 1:
        got = got.reshape(())
    if got.shape != expected.shape:
        raise CheckFailed(f"{name} must be {due}, got an array of shape {got.shape}")
    if not np.all(np.isfinite(got)):
        raise CheckFailed(f"{name} must hold finite numbers of seconds, got NaN or inf")

    def near(a: np.ndarray, b: np.ndarray) -> bool:
        return bool(np.all(np.abs(a - b) <= TIME_ATOL))

    if near(got, expected):
        return got
    shown = f" = {float(got):g} s" if got.ndim == 0 else ""
    causes = _matching_causes(got, expected, mistakes, near)
    if causes:
        raise CheckFailed(f"{name}{shown} is not right: {_either(causes)}")
    raise CheckFailed(f"{name}{shown} does not match {what} (to {tolerance_text(TIME_ATOL)} "
                      f"s), and not by one of the usual mistakes")


def judge_seconds_together(given: Mapping[str, object], expected: object,
                           mistakes: Sequence[Mapping[str, float | None]]) -> None:
    """Times all wrong by one slip (one piece of code made them all): name it for all.

    A cause is named if it explains every time, even where another slip explains one of
    them too (for one P0 a band of 3 × the level and the mean absolute error give the same
    time); every cause that explains them all is named. Otherwise nothing is raised, and
    each time is judged alone (:func:`judge_seconds`).

    Parameters
    ----------
    given : mapping of str to object
        The student's times (s) by name, in the order of ``expected``.
    expected : array_like, shape (len(given),)
        The right times (s).
    mistakes : sequence of mappings of str to float or None
        For each time, cause → the time that slip gives; a cause is tried when every
        mapping has it.
    """
    got = [float(value) for value in given.values() if np.size(value) == 1]
    right = [float(value) for value in np.ravel(expected)]
    if len(got) != len(right) or any(abs(g - r) <= TIME_ATOL
                                     for g, r in zip(got, right, strict=True)):
        return
    causes = [cause for cause in mistakes[0]
              if all(each.get(cause) is not None for each in mistakes)
              and all(abs(g - each[cause]) <= TIME_ATOL < abs(each[cause] - r)
                      for g, each, r in zip(got, mistakes, right, strict=True))]
    if causes:
        shown = " and ".join(f"{name} = {g:g} s" for name, g in zip(given, got, strict=True))
        raise CheckFailed(f"{shown} are not right: {_either(causes)}")


def _interval_parts(interval: object, name: str) -> tuple[object, object, object]:
    if all(hasattr(interval, part) for part in ("mean", "low", "high")):
        return interval.mean, interval.low, interval.high
    if isinstance(interval, (tuple, list)) and len(interval) == 2:
        found = "a pair of numbers"
    elif isinstance(interval, (int, float, np.number)) and not isinstance(interval, bool):
        found = "a number"
    elif isinstance(interval, np.ndarray):
        found = f"an array of shape {interval.shape}"
    else:
        found = "None" if interval is None else f"a {type(interval).__name__}"
    raise CheckFailed(
        f"{name} is {found}; it must be the metrics.Interval that metrics.mean_ci95 returns "
        f"(its mean, low and high), since a Monte Carlo mean means little without its 95 % "
        f"interval")


def judge_interval(name: str, interval: object, expected: metrics.Interval, rtol: float, *,
                   mistakes: Mapping[str, metrics.Interval | None] | None = None,
                   unit: str = "",
                   what: str = "the paired difference recomputed from the task's inputs",
                   nan_hint: str = "",
                   runs_of: tuple[np.ndarray, np.ndarray, str] | None = None) -> None:
    """Judge a student's mean with its 95 % interval against a recomputed one.

    Parameters
    ----------
    name : str
        The student's variable ("improvement[4.5]").
    interval : object
        The student's interval: anything with ``mean``, ``low`` and ``high`` (and, if it
        has one, ``runs``, which must equal ``expected.runs``).
    expected : metrics.Interval
        The right interval, recomputed from the task's inputs.
    rtol : float
        Tolerance relative to the interval's scale: the larger of ``|mean|`` and the
        half-width.
    mistakes : mapping of str to Interval, optional
        Likely mistakes (cause → the interval it gives), tried in order; see :func:`judge`.
    unit, what, nan_hint
        See :func:`judge`.
    runs_of : (ndarray, ndarray, str), optional
        The per-run values (runs,) of the two conditions and how to pair them, in words
        ("Make vision_only with experiments.track(DEFAULT, runs=DEFAULT.mc_runs)"). Given,
        an interval of runs that are not paired is named: the right mean, or a mean as
        far from the right one as another noise draw puts it, with the width of two
        independent samples (:data:`UNPAIRED_SPREAD`); see :func:`_unpaired`.

    Raises
    ------
    CheckFailed
        Naming ``name``: not an interval, a part that is not a finite number, another
        number of runs, a matching mistake's cause, a right mean with wrong ends, or no
        match at all.
    """
    parts = _interval_parts(interval, name)
    got = np.array([float(argument_array(part, f"{name}.{label}", "one number",
                                         shape=(), allow_nan=True))
                    for part, label in zip(parts, ("mean", "low", "high"), strict=True)])
    if np.any(np.isnan(got)):
        raise CheckFailed(f"{name} holds NaN (not a number){f': {nan_hint}' if nan_hint else ''}")
    runs = getattr(interval, "runs", expected.runs)
    if runs != expected.runs:
        raise CheckFailed(
            f"{name} is over {runs} runs, but the task has {expected.runs}: use the per-run "
            f"values of all {expected.runs} runs")
    right = np.array([expected.mean, expected.low, expected.high])
    scale = max(abs(expected.mean), expected.half_width, 1e-300)

    def near(a: np.ndarray, b: np.ndarray) -> bool:
        return bool(np.all(np.abs(a - b) <= rtol * scale))

    if near(got, right):
        return
    for cause, candidate in (mistakes or {}).items():
        if candidate is None:
            continue
        wrong = np.array([candidate.mean, candidate.low, candidate.high], dtype=float)
        if np.all(np.isfinite(wrong)) and not near(wrong, right) and near(got, wrong):
            raise CheckFailed(f"{name} is not right: {cause}")
    unit_text = f" {unit}" if unit else ""
    cause, hint = _unpaired(got, right, near(got[:1], right[:1]), runs_of)
    if cause:
        raise CheckFailed(f"{name} (mean {got[0]:.6g}{unit_text}) is not right: {cause}")
    if near(got[:1], right[:1]):
        wider = (got[2] - got[1]) > 1.5 * (right[2] - right[1])
        raise CheckFailed(
            f"{name}: the mean ({got[0]:.6g}{unit_text}) is right, but the interval's ends "
            f"are not those of metrics.mean_ci95 of the per-run values"
            + (": it is much wider than the paired interval. Are the runs paired, run r "
               "with run r (the same noise draw), in their order, before taking the interval "
               "of the differences?" if wider else
               ": give mean_ci95 the per-run values themselves (for a difference, run r − run "
               "r of the other, on the same noise draw), not values combined with a mean "
               "first"))
    raise CheckFailed(
        f"{name} (mean {got[0]:.6g}{unit_text}) does not match {what} (to "
        f"{tolerance_text(rtol)} relative), and not by one of the usual mistakes"
        f"{f': {hint}' if hint else ''}")


#: How far (relative) the half-width of an interval may be from that of two independent
#: samples, t √((s₁² + s₂²) / runs), to be taken for runs that are not paired.
UNPAIRED_SPREAD = 0.25


def _unpaired(got: np.ndarray, right: np.ndarray, mean_right: bool,
              runs_of: tuple[np.ndarray, np.ndarray, str] | None) -> tuple[str, str]:
    """(cause, hint) for an interval (mean, low, high) of runs that look not paired.

    Its half-width is within :data:`UNPAIRED_SPREAD` of that of two independent samples
    and its mean within their 95 % half-width of the right mean (where another draw puts
    it). That is a cause if the mean is right (the runs out of their pairs) or the paired
    interval is clearly narrower (the width tells pairing apart); else only a hint, a
    question, since a slip that moves the mean a little looks the same.
    """
    if runs_of is None:
        return "", ""
    first, second, advice = runs_of
    runs = first.size
    half = metrics.t_critical_95(runs - 1) * float(
        np.sqrt((np.var(first, ddof=1) + np.var(second, ddof=1)) / runs))
    got_half, right_half = (got[2] - got[1]) / 2, (right[2] - right[1]) / 2
    if not (half > 0 and abs(got_half / half - 1) <= UNPAIRED_SPREAD
            and abs(got[0] - right[0]) <= half):
        return "", ""
    if mean_right or right_half < (1 - UNPAIRED_SPREAD) * half:
        how = ("the mean is right, but" if mean_right
               else "its mean is within the spread of another noise draw, and")
        return (f"its runs are not paired: {how} its width is that of two independent "
                f"samples (within "
                f"{UNPAIRED_SPREAD:.0%}). Run r of both must be on the same noise draw, in "
                f"the same order. {advice}"), ""
    return "", (f"its mean and width are what another noise draw would give (the mean "
                f"within ±{half:.3g}, the width that of two independent samples): are the "
                f"runs paired, run r of both on the same noise draw, in the same order? "
                f"{advice}")


def burn_in_slips(burn_in_steps: int, n: int) -> dict[str, int]:
    """The burn-in off by one sample: cause → the first sample such an MSE keeps.

    Parameters
    ----------
    burn_in_steps : int
        Samples the task leaves out at the start (0: no burn-in, no slips).
    n : int
        Samples in the trial.
    """
    slips = {}
    for shift, which in ((1, "one sample too many"), (-1, "one sample too few")):
        start = burn_in_steps + shift
        if burn_in_steps and 0 <= start < n:
            slips[f"it leaves out {which} ({start} instead of {burn_in_steps}): the burn-in "
                  f"is the first {burn_in_steps} samples, so keep the samples from index "
                  f"{burn_in_steps} on"] = start
    return slips


def mse_mistakes(estimate: np.ndarray, truth: np.ndarray, burn_in_steps: int,
                 dt: float | None = None,
                 readings: Mapping[str, np.ndarray] | None = None,
                 ) -> dict[str, np.ndarray | None]:
    """The usual mistakes of a mean squared error after a burn-in.

    Parameters
    ----------
    estimate : ndarray, shape (..., n)
        Positions (cm) whose MSE against ``truth`` is due; NaN allowed before the burn-in.
    truth : ndarray, shape (n,)
        True positions (cm).
    burn_in_steps : int
        Samples to leave out at the start.
    dt : float, optional
        Time step (s): adds the burn-in counted in seconds instead of samples.
    readings : mapping of str to ndarray, shape (..., n), optional
        Readings (cm) a student may compare with instead of ``truth``, by what they are
        ("vision's readings"): adds the MSE against each.

    Returns
    -------
    dict of str to ndarray or None
        Cause → the MSE (shape (...)) that mistake gives: the root of the MSE, the sum
        instead of the mean, errors not squared, absolute errors, the variance of the
        error, the whole trial, the burn-in one sample too long or too short, the burn-in
        in seconds, the readings for the truth. None where the mistake gives no finite
        number (NaN samples it would include).
    """
    with np.errstate(all="ignore"):
        error = estimate - truth
        kept = error[..., burn_in_steps:]
        right = np.mean(kept**2, axis=-1)
        mistakes: dict[str, np.ndarray | None] = {
            "it is the root mean squared error (RMSE, in cm): the MSE is its square, in cm², "
            "without the root": np.sqrt(right),
            "it is the sum of the squared errors: the MSE is their mean over the samples":
                np.sum(kept**2, axis=-1),
            "the errors are not squared (the mean error): square each error, then average":
                np.mean(kept, axis=-1),
            "it is the mean absolute error: square each error, then average":
                np.mean(np.abs(kept), axis=-1),
            "it is the variance of the error (its mean is subtracted): the MSE averages the "
            "squared errors themselves, bias included": np.var(kept, axis=-1),
        }
        if burn_in_steps:
            mistakes[f"it is the MSE of the whole trial: the first {burn_in_steps} samples "
                     f"(the burn-in) must be left out"] = np.mean(error**2, axis=-1)
        for cause, start in burn_in_slips(burn_in_steps, error.shape[-1]).items():
            mistakes[cause] = np.mean(error[..., start:] ** 2, axis=-1)
        mistakes.update(readings_mistakes(estimate, burn_in_steps, readings or {}))
        if dt is not None and burn_in_steps:
            seconds = burn_in_steps * dt
            if float(seconds).is_integer() and int(seconds) != burn_in_steps:
                mistakes[f"it leaves out the first {seconds:g} sample(s): the burn-in is "
                         f"{seconds:g} s, which is {burn_in_steps} samples of {dt:g} s; "
                         f"count it in samples"] = np.mean(error[..., int(seconds):] ** 2,
                                                           axis=-1)
        if burn_in_steps:
            mistakes.update(other_burn_ins(error, burn_in_steps, dt))
    return {cause: (value if np.all(np.isfinite(value)) else None)
            for cause, value in mistakes.items()}


def other_burn_ins(error: np.ndarray, burn_in_steps: int,
                   dt: float | None = None) -> dict[str, np.ndarray]:
    """The MSE of ``error`` (cm, shape (..., n)) after any other burn-in: cause → MSE (cm²,
    shape (...)), for every first sample kept from 1 to n − 1 but the right one and its
    neighbours (named by :func:`burn_in_slips`). Tried after the named slips."""
    n = error.shape[-1]
    tails = np.cumsum((error**2)[..., ::-1], axis=-1)[..., ::-1]  # sum from each sample on
    named = {burn_in_steps, *burn_in_slips(burn_in_steps, n).values()}
    found = {}
    for start in range(1, n):
        if start not in named:
            seconds = f" ({start * dt:g} s)" if dt is not None else ""
            found[f"it leaves out the first {start} samples{seconds}, not the burn-in's "
                  f"{burn_in_steps}: keep the samples from index {burn_in_steps} on"] = (
                tails[..., start] / (n - start))
    return found


def readings_mistakes(estimate: np.ndarray, burn_in_steps: int,
                      readings: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """MSEs after the burn-in taken against readings instead of the truth (cm²), shape (...).

    ``estimate`` (..., n) are positions (cm); ``readings`` maps what they are ("vision's
    readings") to readings (cm) that broadcast with it: each run's own, shape (..., n),
    or one trial's, shape (n,), the same for every run. Keys name the mistake.
    """
    with np.errstate(all="ignore"):
        return {f"it compares the estimate with {what}, not with the true position: the MSE "
                f"measures how far the estimate is from the truth":
                    np.mean((estimate - values)[..., burn_in_steps:] ** 2, axis=-1)
                for what, values in readings.items()}
