"""Checks of notebook 05's Going further, part 2: compensation as the delay grows.

Each recomputes what its task asks from the task's own inputs (Task 3's Monte Carlo runs,
the filter's model) before looking at the student's values:

- :func:`check_delay_sweep`: per-run MSEs of both estimates at every delay of the sweep,
  on Task 3's runs (:func:`~lqe_helpers.checks.shared_runs.vision_runs`);
- :func:`check_prediction_theory`: the steady-state covariance of the estimate carried
  forward (Lesson 0.5 eq. (9)), and its two sources;
- :func:`check_compensation_regimes`: the delays at which compensation helps;
- :func:`check_error_sources`: where the jerks take over, and the log–log slopes.

:func:`sweep` and :func:`prediction_theory` keep what they recompute for part 3
(:mod:`lqe_helpers.checks.delay_further`).
"""

from __future__ import annotations

import numpy as np

from .. import experiments, metrics
from ..prediction import predict_ahead, propagate_covariance
from ..scenario import DEFAULT
from ..simulation import delay_signal
from .judging import judge
from .machinery import MATRIX_RTOL, MSE_RTOL, CheckFailed, argument_array, passed, tolerance_text
from .remembering import remembered
from .shared_runs import vision_runs

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: The sweep: delays 0, Δt, …, 0.5 s.
SWEEP_STEPS = 50
#: How far the theory is followed (s).
THEORY_SECONDS = 3.0

_TRUTH = DEFAULT.truth[:, 0]
_BURN = DEFAULT.burn_in_steps
_STEPS = DEFAULT.delay_steps(DEFAULT.delay)


@remembered
def sweep() -> dict[str, np.ndarray]:
    """Per-run MSEs (cm²), shape (SWEEP_STEPS + 1, runs), of both estimates at each delay.

    Recomputed on Task 3's Monte Carlo runs from the positions only (the pack's
    :func:`~lqe_helpers.simulation.delay_signal` and
    :func:`~lqe_helpers.prediction.predict_ahead`), so it takes well under a second;
    read-only.
    """
    tracking = vision_runs()
    estimates = tracking.result.estimates
    rows: dict[str, list[np.ndarray]] = {"delayed": [], "predicted": []}
    for steps in range(SWEEP_STEPS + 1):
        skip = max(_BURN, steps)
        rows["delayed"].append(metrics.mse(delay_signal(tracking.positions, steps, axis=-1),
                                           _TRUTH, skip))
        rows["predicted"].append(metrics.mse(predict_ahead(estimates, DEFAULT.A, steps)[..., 0],
                                             _TRUTH, skip))
    values = {which: np.array(found) for which, found in rows.items()}
    for array in values.values():
        array.setflags(write=False)
    return values


def _sweep_delays() -> np.ndarray:
    return np.arange(SWEEP_STEPS + 1) * DEFAULT.dt


def check_delay_sweep(delays: np.ndarray, sweep_mse: dict[str, np.ndarray]) -> None:
    """Check Going further part 2's sweep: per-run MSEs of both estimates at every delay.

    Recomputed on Task 3's Monte Carlo runs (:func:`lqe_helpers.experiments.track`, the
    same draws), delayed and compensated at d = 0, Δt, …, 0.5 s; the delays must agree
    within :data:`MSE_RTOL` relative and every per-run MSE (cm², after the burn-in or
    the delay, whichever is longer) within :data:`MSE_RTOL` of the largest.

    Parameters
    ----------
    delays : array_like, shape (51,)
        The delays (s).
    sweep_mse : dict
        ``{"delayed": ..., "predicted": ...}``, each an array (51, runs) (cm²), row i for
        ``delays[i]``.

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: delays in samples or one short, a key
        missing, one run or the mean over the runs, rows and runs swapped, the two
        estimates swapped, every row at the question's delay, ...
    """
    expected_delays = _sweep_delays()
    count = expected_delays.size
    got = argument_array(delays, "delays", f"the {count} delays (s), shape ({count},)")
    if got.shape != (count,):
        raise CheckFailed(
            f"delays must hold the {count} delays 0, {DEFAULT.dt:g}, …, "
            f"{expected_delays[-1]:g} s (both ends included), got shape {got.shape}: "
            f"np.arange(0, 0.5, 0.01) stops before 0.5")
    judge("delays", got, expected_delays, MSE_RTOL, unit="s",
          what="0, Δt, …, 0.5 s",
          mistakes={"they are in samples; give them in seconds (δ Δt)": np.arange(count)})
    if not isinstance(sweep_mse, dict) or set(sweep_mse) != {"delayed", "predicted"}:
        found = (f"keys {sorted(sweep_mse)}" if isinstance(sweep_mse, dict)
                 else f"a {type(sweep_mse).__name__}")
        raise CheckFailed(f'sweep_mse must be a dict with the keys "delayed" and "predicted", '
                          f"got {found}")
    right = sweep()
    runs = DEFAULT.mc_runs
    for which in ("delayed", "predicted"):
        name = f'sweep_mse["{which}"]'
        values = argument_array(sweep_mse[which], name, f"per-run MSEs (cm²), shape "
                                f"({count}, {runs})")
        if values.shape == (runs, count):
            raise CheckFailed(f"{name} has shape {values.shape}: rows are runs. Make row i "
                              f"the delay delays[i], shape ({count}, {runs})")
        if values.shape == (count,):
            raise CheckFailed(
                f"{name} has one number per delay, shape ({count},): keep the MSE of each "
                f"of tracking_mc's {runs} runs, shape ({count}, {runs}); the paired "
                f"intervals need them run by run")
        other = "predicted" if which == "delayed" else "delayed"
        question_row = right[which][_STEPS]
        judge(name, values, right[which], MSE_RTOL, unit="cm²",
              what="the per-run MSEs recomputed from Task 3's runs",
              mistakes={f'it holds the {other} MSEs: "predicted" is the compensated '
                        f'estimate, "delayed" the uncompensated one': right[other],
                        f"every row is the MSE at the question's delay "
                        f"{DEFAULT.delay:g} s: delay and compensate tracking_mc anew at "
                        f"each d": np.broadcast_to(question_row, right[which].shape)})
    passed(f"the delays and the per-run MSEs of the delayed and compensated estimates "
           f"({count} delays × {runs} runs) match the pack's engine on Task 3's draws to "
           f"{tolerance_text(MSE_RTOL)} relative")


@remembered
def prediction_theory() -> dict[str, np.ndarray]:
    """Part 2's theory (cm²), shape (301,) over 0–3 s, and the covariances it starts from.

    Keys: ``P_hat`` and ``P_prior`` (3, 3), the steady-state covariances of the estimate
    and of the one-step prediction; ``theory``, ``extrapolated``, ``jerks`` and three
    mistaken starts (read-only).
    """
    steady = experiments.filter_model(DEFAULT).steady_state()
    steps = DEFAULT.delay_steps(THEORY_SECONDS)
    no_noise = np.zeros_like(DEFAULT.Q)

    def pp(P: np.ndarray, Q: np.ndarray) -> np.ndarray:
        return propagate_covariance(P, DEFAULT.A, Q, steps)[:, 0, 0]

    P_hat = steady.estimate_covariance
    return {"P_hat": P_hat, "P_prior": steady.covariance,
            "theory": pp(P_hat, DEFAULT.Q), "extrapolated": pp(P_hat, no_noise),
            "jerks": pp(no_noise, DEFAULT.Q), "from_prior": pp(steady.covariance, DEFAULT.Q),
            "from_P0": pp(DEFAULT.P0, DEFAULT.Q),
            "prior_no_noise": pp(steady.covariance, no_noise)}


def check_prediction_theory(P_hat: np.ndarray, theory: np.ndarray, extrapolated: np.ndarray,
                            jerks: np.ndarray) -> None:
    """Check part 2's theory: P̂ carried forward δ steps, with and without the jerks.

    Recomputed from the filter's model (:func:`lqe_helpers.experiments.filter_model`, its
    steady state) and :func:`lqe_helpers.prediction.propagate_covariance` over 0–3 s;
    each array within :data:`MATRIX_RTOL` of its largest entry.

    Parameters
    ----------
    P_hat : array_like, shape (3, 3)
        Steady-state covariance of the estimate ẑ.
    theory, extrapolated, jerks : array_like, shape (301,)
        Position entry (cm²) of P̂ propagated with Q, without Q (Q = 0), and of 0
        propagated with Q, for δ = 0 … 300.

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: the prediction's covariance or P0 for
        the estimate's, Q and no Q swapped, the standard deviation, whole matrices, only
        up to 0.5 s, ...
    """
    right = prediction_theory()
    judge("P_hat", _matrix(P_hat), right["P_hat"], MATRIX_RTOL, unit="",
          what="the steady-state covariance of the estimate, recomputed",
          mistakes={"it is the covariance of the one-step prediction (steady_state()"
                    ".covariance); the estimate's is .estimate_covariance":
                    right["P_prior"],
                    "it is P0, the covariance the filter starts from; take the steady "
                    "state's": DEFAULT.P0})
    size = right["theory"].size
    for name, value in (("theory", theory), ("extrapolated", extrapolated), ("jerks", jerks)):
        got = argument_array(value, name, f"position variances (cm²), shape ({size},)")
        if got.shape == (size, 3, 3):
            raise CheckFailed(f"{name} holds whole covariance matrices, shape {got.shape}: "
                              f"keep the position entry [:, 0, 0], shape ({size},)")
        if got.ndim == 1 and got.size < size:
            raise CheckFailed(
                f"{name} has {got.size} entries: follow the theory over δ = 0 … {size - 1} "
                f"({THEORY_SECONDS:g} s), shape ({size},)")
        mistakes = {
            "it starts from the covariance of the one-step prediction; start from P̂, the "
            "estimate's": right["from_prior"] if name == "theory" else (
                right["prior_no_noise"] if name == "extrapolated" else None),
            "it starts from P0; start from P̂, the steady-state covariance of the estimate":
                right["from_P0"] if name == "theory" else None,
            "it is the standard deviation (cm); keep the variance (cm²), without the root":
                np.sqrt(right[name]),
            "the jerks were left out of the theory: propagate P̂ with Q": right["extrapolated"],
            "it holds the jerks alone (from P = 0 with Q)": right["jerks"],
            "it holds the extrapolated old error (from P̂ with Q = 0)": right["extrapolated"],
            "it holds the whole theory (from P̂ with Q)": right["theory"],
        }
        judge(name, got, right[name], MATRIX_RTOL, unit="cm²",
              what=f"{name} recomputed from the filter's steady state", mistakes=mistakes)
    passed(f"P̂ and the theory's position variance over 0–{THEORY_SECONDS:g} s (total, "
           f"extrapolated old error, jerks) match propagate_covariance from the filter's "
           f"steady state to {tolerance_text(MATRIX_RTOL)} relative")


def _matrix(value: object) -> np.ndarray:
    got = argument_array(value, "P_hat", "a 3 × 3 covariance matrix")
    if got.shape != (3, 3):
        raise CheckFailed(f"P_hat must be a 3 × 3 covariance matrix (p, v, a), got shape "
                          f"{got.shape}")
    return got


def _regimes(delayed: np.ndarray, predicted: np.ndarray) -> dict[str, float]:
    """First and last delay (s) where the paired interval is above 0, and the best share."""
    delays = _sweep_delays()
    paired = [metrics.mean_ci95(d - p) for d, p in zip(delayed, predicted, strict=True)]
    helps = np.array([iv.low > 0 for iv in paired])
    shares = [0.0] + [float(np.mean(1 - p / d)) for d, p in zip(delayed[1:], predicted[1:],
                                                              strict=True)]
    gains = [iv.mean for iv in paired]
    return {"help_from": delays[helps].min() if helps.any() else None,
            "help_to": delays[helps].max() if helps.any() else None,
            "best_delay": delays[int(np.argmax(shares))],
            "best_share": max(shares),
            "best_gain_delay": delays[int(np.argmax(gains))]}


def check_compensation_regimes(help_from: float, help_to: float, best_delay: float) -> None:
    """Check part 2's regimes: the delays at which compensation helps, and helps most.

    Recomputed from the sweep on Task 3's runs (:func:`sweep`): the shortest and the
    longest delay whose paired 95 % interval of delayed − compensated lies above zero,
    and the delay of the largest mean share 1 − compensated / delayed; each within
    :data:`MSE_RTOL` relative.

    Parameters
    ----------
    help_from, help_to, best_delay : float
        The delays (s).

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: samples for seconds, where it hurts for
        where it helps, the largest difference for the largest share, the share itself, ...
    """
    runs = sweep()
    right = _regimes(runs["delayed"], runs["predicted"])
    hurt = _regimes(runs["predicted"], runs["delayed"])
    dt = DEFAULT.dt
    for name, value in (("help_from", help_from), ("help_to", help_to),
                        ("best_delay", best_delay)):
        mistakes = {"it is in samples (an index into delays); give the delay in seconds":
                    round(right[name] / dt),
                    "it is where compensation hurts: the paired difference is delayed − "
                    "compensated, and it helps where that interval lies above zero":
                        hurt[name] if name != "best_delay" else None}
        if name == "best_delay":
            mistakes.update({
                "it is where the paired difference is largest, in cm²; the question is "
                "where compensation removes the largest share of the delayed MSE":
                    right["best_gain_delay"],
                "it is the largest share itself; give the delay (s) where it occurs":
                    right["best_share"]})
        judge(name, value, right[name], MSE_RTOL, unit="s", mistakes=mistakes,
              what=f"{name} recomputed from the sweep of Task 3's runs")
    passed(f"the shortest and longest delays at which compensation helps (paired 95 % "
           f"interval above zero) and the delay of its largest share match the sweep of "
           f"Task 3's runs to {tolerance_text(MSE_RTOL)} relative")


@remembered
def _sources() -> dict[str, tuple[float, dict[str, float | None]]]:
    """Where the jerks take over (s) and both log–log slopes, with their likely mistakes."""
    t = prediction_theory()
    delays = np.arange(t["theory"].size) * DEFAULT.dt
    jerks, old = t["jerks"], t["extrapolated"]
    takeover = float(delays[np.argmax(jerks > old)])
    positive = delays > 0
    simulated = positive & (delays <= SWEEP_STEPS * DEFAULT.dt + 1e-9)

    def slope(values: np.ndarray, where: np.ndarray = positive) -> float:
        return metrics.power_law_exponent(delays[where], values[where])

    right = {"slope_jerks": slope(jerks), "slope_old": slope(old)}
    short = {"slope_jerks": slope(jerks, simulated), "slope_old": slope(old, simulated)}
    swapped = {"slope_jerks": "slope_old", "slope_old": "slope_jerks"}
    found = {"takeover": (takeover, {
        "it is in samples (an index); give the delay in seconds": takeover / DEFAULT.dt,
        "it is the first delay of all, 0 s: there the extrapolated error is P̂_pp and the "
        "jerks 0, so look for the first delay at which jerks > extrapolated": 0.0})}
    for name, value in right.items():
        found[name] = (value, {
            f"it is the slope of {swapped[name].split('_')[1]}, the other part":
                right[swapped[name]],
            "it is the slope of the standard deviation (half the variance's); fit the "
            "variances (cm²) themselves": value / 2,
            f"it is fitted over the simulated delays only (to {SWEEP_STEPS * DEFAULT.dt:g} "
            f"s); fit over 0.01–{THEORY_SECONDS:g} s": short[name],
            "it is the slope of the whole theory, not of one part": slope(t["theory"])})
    return found


def check_error_sources(takeover: float, slope_jerks: float, slope_old: float) -> None:
    """Check part 2's sources: where the jerks take over, and the slope of each part.

    Recomputed from the theory (:func:`prediction_theory`): the first delay at which the
    accumulated jerks exceed the extrapolated old error, and the least-squares log–log
    slopes (:func:`lqe_helpers.metrics.power_law_exponent`) of each part over the delays
    0.01–3 s; each within :data:`MSE_RTOL` relative.

    Parameters
    ----------
    takeover : float
        The delay (s) from which the jerks exceed the extrapolated old error.
    slope_jerks, slope_old : float
        The fitted exponents of the accumulated jerks and of the extrapolated old error.

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: samples for seconds, the comparison at
        d = 0, the slopes swapped, of the standard deviation, over the simulated delays
        only, of the whole theory, ...
    """
    right = _sources()
    for name, value in (("takeover", takeover), ("slope_jerks", slope_jerks),
                        ("slope_old", slope_old)):
        expected, mistakes = right[name]
        judge(name, value, expected, MSE_RTOL, unit="s" if name == "takeover" else "",
              mistakes=mistakes, what=f"{name} recomputed from the theory")
    passed(f"the delay where the jerks take over and the log–log slopes of both parts "
           f"(0.01–{THEORY_SECONDS:g} s) match the theory to {tolerance_text(MSE_RTOL)} "
           f"relative")
