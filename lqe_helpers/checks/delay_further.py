"""Checks of notebook 05's Going further, parts 1 and 3: the late eye and the shortest delays.

Each recomputes what its task asks from the task's own inputs (the scenario's draws, the
pack's engine) before looking at the student's values:

- :func:`check_late_eye` (part 1): a perfect but late eye against the noise-free filter,
  whose lead is fitted;
- :func:`check_short_delays` (part 3): the short-delay approximations, from the sweep and
  the theory of part 2 (:mod:`lqe_helpers.checks.delay_sweep`).
"""

from __future__ import annotations

import numpy as np

from .. import experiments, metrics
from ..scenario import DEFAULT
from ..simulation import delay_signal
from .delay import monte_carlo_mses
from .delay_sweep import prediction_theory, sweep
from .judging import judge, judge_interval, mse_mistakes
from .machinery import INTERVAL_RTOL, MSE_RTOL, passed, tolerance_text
from .paired_mistakes import interval_mistakes
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

_TRUTH = DEFAULT.truth[:, 0]
_BURN = DEFAULT.burn_in_steps
_STEPS = DEFAULT.delay_steps(DEFAULT.delay)
_SKIP = max(_BURN, _STEPS)


def _mse(x: np.ndarray, start: int = _SKIP) -> float | None:
    """MSE (cm²) of positions (n,) after ``start`` samples; None if it is not finite."""
    with np.errstate(invalid="ignore"):
        value = float(np.mean((x[start:] - _TRUTH[start:]) ** 2))
    return value if np.isfinite(value) else None


# ------------------------------------------------------------------------------------------
# Part 1: a perfect but late eye
# ------------------------------------------------------------------------------------------

@remembered
def _late_eye() -> dict[str, object]:
    """Part 1 recomputed, with each value's likely mistakes."""
    times, frequency = DEFAULT.times, DEFAULT.frequency
    clean = experiments.track(DEFAULT, noise=np.zeros((DEFAULT.n_steps, 1))).positions
    noisy = experiments.track(DEFAULT).positions              # the one trial of Task 2
    late_eye = delay_signal(_TRUTH, _STEPS, axis=-1)
    lead = float(metrics.fit_sinusoid(times[_BURN:], clean[_BURN:], frequency).lead)
    now = monte_carlo_mses()
    noise_part = float(now["now"].mean()) - _mse(clean, _BURN)
    clean_delayed = delay_signal(clean, _STEPS, axis=-1)
    return {
        "mse_late_eye": (_mse(late_eye), {
            "the eye is not late: that is the true position itself, whose error is 0":
                0.0,
            f"it leaves out only the first δ = {_STEPS} samples; leave out `skip` = "
            f"{_SKIP} as for the estimates, so that the two compare the same samples":
                _mse(late_eye, _STEPS),
            **mse_mistakes(late_eye, _TRUTH, _SKIP, DEFAULT.dt)}),
        "lead": (lead, {
            "it is in ms; give the lead in seconds (s)": 1000 * lead,
            "it is fitted to the filter run on the noisy readings; run your my_filter on "
            "readings without noise (the true position itself)":
                float(metrics.fit_sinusoid(times[_BURN:], noisy[_BURN:], frequency).lead),
            "it is fitted over the whole trial; leave out the burn-in, where the filter "
            "is still starting": float(metrics.fit_sinusoid(times, clean, frequency).lead),
            "its sign is reversed: > 0 means the estimate runs ahead of the butterfly":
                -lead}),
        "mse_clean_delayed": (_mse(clean_delayed), {
            "it is the MSE of the noisy run's delayed estimate (Task 2); delay the "
            "noise-free filter's estimate": _mse(delay_signal(noisy, _STEPS, axis=-1)),
            "it is not delayed: the noise-free estimate's own MSE": _mse(clean),
            **mse_mistakes(clean_delayed, _TRUTH, _SKIP, DEFAULT.dt)}),
        "noise_part": (noise_part, {
            "its sign is reversed: the noise part is the noisy filter's MSE minus the "
            "noise-free one's": -noise_part,
            "it is taken from the delayed MSEs, which makes the comparison circular: take "
            "the undelayed filter's Monte Carlo MSE minus the noise-free filter's":
                float(now["delayed"].mean()) - _mse(clean_delayed),
            "it uses one noisy run (Task 2's) instead of the Monte Carlo mean of mse_now":
                _mse(noisy, _BURN) - _mse(clean, _BURN),
            "the noise-free MSE is over the whole trial; leave out the burn-in as mse_now "
            "does": float(now["now"].mean()) - _mse(clean, 0)}),
    }


def check_late_eye(mse_late_eye: float, lead: float, mse_clean_delayed: float,
                   noise_part: float) -> None:
    """Check Going further part 1: the late eye, the noise-free filter's lead and its parts.

    Recomputed from the task's inputs: the true position delayed by δ samples, the pack's
    engine on readings without noise (which the student's ``my_filter`` equals) and its
    sine fit after the burn-in (:func:`lqe_helpers.metrics.fit_sinusoid`), and Task 3's
    Monte Carlo runs; each value within :data:`MSE_RTOL` relative.

    Parameters
    ----------
    mse_late_eye : float
        MSE (cm²) of the true position seen δ samples late, after ``skip`` samples.
    lead : float
        Lead (s) of the noise-free filter's position over the butterfly, > 0 ahead.
    mse_clean_delayed : float
        MSE (cm²) of the noise-free filter's position delayed by δ, after ``skip``.
    noise_part : float
        Monte Carlo MSE of the undelayed filter minus the noise-free filter's (cm²).

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: the eye not late, only δ samples left out,
        the lead in ms, fitted to the noisy run or over the burn-in, the noisy run
        delayed, a circular noise part, one run for the Monte Carlo mean, ...
    """
    right = _late_eye()
    units = {"mse_late_eye": "cm²", "lead": "s", "mse_clean_delayed": "cm²",
             "noise_part": "cm²"}
    for name, value in zip(units, (mse_late_eye, lead, mse_clean_delayed, noise_part),
                           strict=True):
        expected, mistakes = right[name]
        judge(name, value, expected, MSE_RTOL, unit=units[name], mistakes=mistakes,
              what=f"{name} recomputed from the task's inputs",
              nan_hint=f"leave out the first `skip` = {_SKIP} samples, where nothing has "
                       f"arrived yet")
    passed(f"the late eye's MSE, the noise-free filter's lead and delayed MSE, and the "
           f"noise part match the pack's engine on the scenario's draws to "
           f"{tolerance_text(MSE_RTOL)} relative")




# ------------------------------------------------------------------------------------------
# Part 3: the shortest delays
# ------------------------------------------------------------------------------------------

@remembered
def _short() -> dict[str, object]:
    """Part 3 recomputed, with each value's likely mistakes."""
    v = DEFAULT.truth[:, 1]
    mean_v2 = float(np.mean(v[_BURN:] ** 2))
    lead = _late_eye()["lead"][0]
    t = prediction_theory()

    def d0(P: np.ndarray, L: float = lead, v2: float = mean_v2) -> float:
        return float(2 * (P[0, 1] + L * v2) / (v2 - P[1, 1] - P[0, 2]))

    runs = sweep()
    now = monte_carlo_mses()["now"]
    delayed = runs["delayed"][1]
    return {
        "mean_v2": (mean_v2, {
            "it is the square of the mean velocity, near 0 as the butterfly flies back and "
            "forth; average the squared speeds instead": float(np.mean(v[_BURN:])) ** 2,
            "it is the root mean squared speed (cm/s); the mean squared speed is its square":
                np.sqrt(mean_v2),
            "it is the square of the mean absolute speed; average the squares instead":
                float(np.mean(np.abs(v[_BURN:]))) ** 2,
            "it is the mean squared position (column 0 of the truth); the speed v is "
            "column 1": float(np.mean(DEFAULT.truth[_BURN:, 0] ** 2)),
            "it is the mean squared acceleration (column 2 of the truth); the speed v is "
            "column 1": float(np.mean(DEFAULT.truth[_BURN:, 2] ** 2))}),
        "shortest": (metrics.mean_ci95(delayed - now), {
            **interval_mistakes(delayed, now, "the delayed MSE at 0.01 s",
                                "the undelayed MSE"),
            "it is the compensated estimate's; the task asks for the delayed estimate's "
            "extra MSE": metrics.mean_ci95(runs["predicted"][1] - now),
            f"it is at the question's delay, {DEFAULT.delay:g} s; take the shortest delay "
            f"of the sweep, {DEFAULT.dt:g} s (row 1)":
                metrics.mean_ci95(runs["delayed"][_STEPS] - now)}),
        "break_even": (d0(t["P_hat"]), {
            "the lead is in ms; give L in seconds": d0(t["P_hat"], 1000 * lead),
            "the lead L is left out": d0(t["P_hat"], 0.0),
            "it uses the covariance of the one-step prediction; use P̂, the estimate's":
                d0(t["P_prior"]),
            "the lead's sign is reversed: L > 0 means the estimate runs ahead":
                d0(t["P_hat"], -lead)}),
    }


def check_short_delays(mean_v2: float, shortest: metrics.Interval, break_even: float) -> None:
    """Check part 3: the mean squared speed, the extra MSE at 0.01 s and the break-even delay.

    Recomputed from the task's inputs: the true speed after the burn-in, the sweep of
    Task 3's runs (:func:`lqe_helpers.checks.delay_sweep.sweep`), the noise-free filter's
    lead and the filter's steady state; ``mean_v2`` and ``break_even`` within
    :data:`MSE_RTOL` relative, ``shortest`` within :data:`INTERVAL_RTOL` of its scale.

    Parameters
    ----------
    mean_v2 : float
        The butterfly's mean squared speed after the burn-in (cm²/s²).
    shortest : metrics.Interval
        Paired delayed (d = Δt) − undelayed MSE over the runs (cm²).
    break_even : float
        The break-even delay d0 (s) of the short-delay approximation.

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: the mean squared, the root or another
        column for v²; the sign reversed, unpaired, the compensated estimate or another
        delay for the interval; the lead in ms, left out or reversed, the prediction's
        covariance for P̂, ...
    """
    right = _short()
    expected, mistakes = right["mean_v2"]
    judge("mean_v2", mean_v2, expected, MSE_RTOL, unit="cm²/s²", mistakes=mistakes,
          what="the mean squared speed after the burn-in, recomputed")
    expected, mistakes = right["shortest"]
    judge_interval("shortest", shortest, expected, INTERVAL_RTOL, unit="cm²",
                   mistakes=mistakes, what="the paired extra MSE of the delayed estimate at "
                   f"{DEFAULT.dt:g} s, recomputed from Task 3's runs")
    expected, mistakes = right["break_even"]
    judge("break_even", break_even, expected, MSE_RTOL, unit="s", mistakes=mistakes,
          what="d0 recomputed from the lead, the mean squared speed and P̂")
    passed(f"the mean squared speed, the paired extra MSE at d = {DEFAULT.dt:g} s and the "
           f"break-even delay match the pack's engine to {tolerance_text(MSE_RTOL)} "
           f"(the interval to {tolerance_text(INTERVAL_RTOL)}) relative")
