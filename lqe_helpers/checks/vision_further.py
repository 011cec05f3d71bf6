"""Checks of notebook 01, Going further parts 2–4: lead, noise, confidence, sampling rate.

- :func:`check_systematic_error` (part 2): the noise-free filter's sine fit (amplitude,
  lead) and the split of the Monte Carlo MSE into a systematic and a noise part;
- :func:`check_steady_state` (part 3): the filter's forecast of its own MSE,
  [P̂∞]pp, and how often the truth lies inside its ±2σ band;
- :func:`check_nis` (part 3): the normalised innovation squared, which needs no true
  path, and the share of runs whose mean NIS lies in its 95 % band;
- :func:`check_sampling_ratio` (part 4): raw / filtered MSE at three time steps.

Each recomputes the task's numbers from its own inputs and draws with the pack's engine
(the core path's batch, :func:`lqe_helpers.checks.vision.monte_carlo`) before looking at the
student's values.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from .. import experiments, metrics
from ..scenario import DEFAULT
from ..steady_state import SteadyState
from .judging import judge, mse_mistakes
from .machinery import MSE_RTOL, CheckFailed, passed, tolerance_text
from .remembering import remembered
from .vision import SIGMAS_V, keyed, monte_carlo

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: The time steps (s) of the sampling-rate task.
SAMPLING_DTS = (0.02, 0.01, 0.002)
#: Vision noise (cm) of the sampling-rate task.
SAMPLING_SIGMA_V = 1.5

_TRUTH = DEFAULT.truth[:, 0]


def _judge_each_sigma(values: dict[str, dict[float, object]], units: dict[str, str],
                      table: Callable[[int], dict[str, dict[str, object]]]) -> None:
    """Judge each of the student's dicts (name → values by σ_v) against ``table``.

    ``table(column)`` gives, for σ_v = SIGMAS_V[column], each name's right value and its
    likely mistakes; the value of the other σ_v is one more likely mistake.
    """
    for column, sigma in enumerate(SIGMAS_V):
        right, other = table(column), table(1 - column)
        for name, by_sigma in values.items():
            judge(f"{name}[{sigma:g}]", by_sigma[sigma], right[name]["right"], MSE_RTOL,
                  unit=units[name], what="the value recomputed from the task's inputs",
                  mistakes={**right[name]["mistakes"],
                            f"it is the value for σ_v = {SIGMAS_V[1 - column]:g} cm":
                                other[name]["right"]})


# ------------------------------------------------------------------------------------------
# Part 2: the systematic error
# ------------------------------------------------------------------------------------------

@remembered
def _noise_free(column: int) -> np.ndarray:
    """Positions (n,) (cm) of the filter fed noise-free readings at σ_v = SIGMAS_V[column]."""
    positions = experiments.track(DEFAULT, sigmas=[SIGMAS_V[column]],
                                  noise=np.zeros((DEFAULT.n_steps, 1))).positions
    positions.setflags(write=False)
    return positions


def _fit(positions: np.ndarray, start: int) -> metrics.SinusoidFit:
    return metrics.fit_sinusoid(DEFAULT.times[start:], positions[..., start:], DEFAULT.frequency)


@remembered
def _split(column: int) -> dict[str, dict[str, object]]:
    """Right values of part 2 at one σ_v and their likely mistakes, by the student's name."""
    burn = DEFAULT.burn_in_steps
    clean, noisy = _noise_free(column), monte_carlo().positions[:, column]
    fit, whole, run0 = _fit(clean, burn), _fit(clean, 0), _fit(noisy[0], burn)
    systematic = float(metrics.mse(clean, _TRUTH, burn))
    monte_carlo_mse = float(monte_carlo().mse()[:, column].mean())
    deviation = noisy[:, burn:] - clean[burn:]
    noise_part = float(np.mean(deviation**2))
    return {
        "amplitude": {"right": float(fit.amplitude), "mistakes": {
            "the sine is fitted to the whole trial: fit it after the burn-in, once the "
            "filter has settled": float(whole.amplitude),
            "the sine is fitted to a noisy run's estimate; fit the noise-free filter's":
                float(run0.amplitude)}},
        "lead_ms": {"right": 1000 * float(fit.lead), "mistakes": {
            "it is in seconds: the task asks for milliseconds (ms)": float(fit.lead),
            "its sign is reversed: the lead is > 0 when the estimate runs ahead of the "
            "butterfly, as metrics.fit_sinusoid gives it": -1000 * float(fit.lead),
            "the sine is fitted to the whole trial: fit it after the burn-in":
                1000 * float(whole.lead),
            "the sine is fitted to a noisy run's estimate; fit the noise-free filter's":
                1000 * float(run0.lead)}},
        "systematic": {"right": systematic, "mistakes": {
            "it is the Monte Carlo MSE of the noisy runs; the systematic part is the MSE of "
            "the noise-free run": monte_carlo_mse,
            **mse_mistakes(clean, _TRUTH, burn, DEFAULT.dt)}},
        "noise_part": {"right": noise_part, "mistakes": {
            "it is the Monte Carlo MSE minus the systematic part. Compute the noise part "
            "itself, from each run's estimate minus the noise-free one: only then is their "
            "sum a check": monte_carlo_mse - systematic,
            "it is the spread of the runs around their own mean; the noise part is their "
            "spread around the noise-free estimate": float(np.mean(np.var(
                noisy[:, burn:], axis=0))),
            "it is one run's (run 0's); the noise part is the mean over all runs":
                float(np.mean(deviation[0] ** 2)),
            "it includes the burn-in: leave out the first samples in the noise part too":
                float(np.mean((noisy - clean) ** 2))}},
    }


def check_systematic_error(amplitude: dict[float, float], lead_ms: dict[float, float],
                           systematic: dict[float, float],
                           noise_part: dict[float, float]) -> None:
    """Check part 2: the noise-free filter's sine fit and the split of the MSE, at both σ_v.

    Recomputed from the task's inputs before looking at the student's: the engine fed
    noise-free readings (which equals a correct ``my_filter``), the sine of the flight's
    frequency fitted after the burn-in (:func:`lqe_helpers.metrics.fit_sinusoid`), the
    noise-free run's MSE, and the Monte Carlo mean square of the core path's estimates minus the
    noise-free one after the burn-in; each within :data:`MSE_RTOL` relative.

    Parameters
    ----------
    amplitude : dict of float to float
        Amplitude (cm) of the fitted sine, keyed by σ_v (cm).
    lead_ms : dict of float to float
        Its lead (ms, > 0: ahead of the butterfly), keyed by σ_v (cm).
    systematic, noise_part : dict of float to float
        The two parts of the Monte Carlo MSE (cm²), keyed by σ_v (cm).

    Raises
    ------
    CheckFailed
        Naming the entry and the likely cause: a fit over the whole trial or to a noisy
        run, seconds for milliseconds, a reversed sign, the noise part taken as the rest
        of the MSE or around the runs' own mean, ...
    """
    given = {"amplitude": (amplitude, "amplitudes (cm)", "cm"),
             "lead_ms": (lead_ms, "leads (ms)", "ms"),
             "systematic": (systematic, "systematic parts of the MSE (cm²)", "cm²"),
             "noise_part": (noise_part, "noise parts of the MSE (cm²)", "cm²")}
    values = {name: keyed(value, name, what) for name, (value, what, _) in given.items()}
    _judge_each_sigma(values, {name: unit for name, (_, _, unit) in given.items()}, _split)
    passed(f"the noise-free filter's fitted amplitude and lead and the systematic and noise "
           f"parts of the MSE at σ_v = {' and '.join(f'{s:g}' for s in SIGMAS_V)} cm match "
           f"the pack's engine on the task's draws to {tolerance_text(MSE_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Part 3: the filter's confidence, with and without the true path
# ------------------------------------------------------------------------------------------

def _steady(r_variance: float) -> SteadyState:
    """The steady state of vision alone with R = [[r_variance]] (cm²)."""
    return experiments.filter_model(DEFAULT, sigmas=[np.sqrt(r_variance)]).steady_state()


def _coverage(errors: np.ndarray, limits: np.ndarray) -> float:
    return 100.0 * float(np.mean(np.abs(errors) <= limits))


@remembered
def _confidence(column: int) -> dict[str, dict[str, object]]:
    """Right forecast and coverage at one σ_v and their likely mistakes."""
    sigma, burn = SIGMAS_V[column], DEFAULT.burn_in_steps
    steady = _steady(sigma**2)
    batch = monte_carlo()
    errors = batch.positions[:, column] - _TRUTH
    std = np.sqrt(batch.position_variances[:, column])
    right = _coverage(errors[:, burn:], 2 * std[:, burn:])
    return {
        "forecast": {"right": float(steady.estimate_covariance[0, 0]), "mistakes": {
            "it is [P∞]pp, the covariance of the prediction before each reading; the "
            "estimate's own is P̂∞ = (I − K∞ C) P∞ (estimate_covariance)":
                float(steady.covariance[0, 0]),
            "R holds σ_v (cm) where its variance σ_v² (cm²) belongs":
                float(_steady(sigma).estimate_covariance[0, 0]),
            "it is a standard deviation (cm), the root of [P̂∞]pp; the forecast of an MSE "
            "is a variance (cm²)": float(np.sqrt(steady.estimate_covariance[0, 0])),
            "it is the Monte Carlo MSE; the forecast is the filter's own [P̂∞]pp":
                float(batch.mse()[:, column].mean())}},
        "coverage": {"right": right, "mistakes": {
            "it is a fraction; the task asks for a percentage": right / 100,
            "the band is ±1σ; the task's band is ±2σ": _coverage(errors[:, burn:],
                                                                  std[:, burn:]),
            "the band is ±2 variances; σ is the square root of the position variance":
                _coverage(errors[:, burn:], 2 * std[:, burn:] ** 2),
            "it includes the burn-in: count the samples after it only":
                _coverage(errors, 2 * std),
            "it is one run's (run 0's); count the samples of all runs":
                _coverage(errors[0, burn:], 2 * std[0, burn:])}},
    }


def check_steady_state(forecast: dict[float, float], coverage: dict[float, float]) -> None:
    """Check part 3: [P̂∞]pp, the filter's forecast of its MSE, and its ±2σ coverage.

    Recomputed from the task's inputs before looking at the student's: the steady state
    of eq. (5) with R = [[σ_v²]] (:func:`lqe_helpers.steady_state.steady_state` of
    :func:`lqe_helpers.experiments.filter_model`), and the
    percentage of samples after the burn-in, over the core path's runs, where |estimate −
    truth| <= 2 √(the filter's position variance); each within :data:`MSE_RTOL` relative.

    Parameters
    ----------
    forecast : dict of float to float
        [P̂∞]pp (cm²), keyed by σ_v (cm).
    coverage : dict of float to float
        The percentage of samples inside the ±2σ band, keyed by σ_v (cm).

    Raises
    ------
    CheckFailed
        Naming the entry and the likely cause: P∞ for P̂∞, σ_v in R, a standard
        deviation, a fraction for a percentage, ±1σ, the whole trial, one run, ...
    """
    values = {"forecast": keyed(forecast, "forecast", "variances [P̂∞]pp (cm²)"),
              "coverage": keyed(coverage, "coverage", "percentages of samples")}
    _judge_each_sigma(values, {"forecast": "cm²", "coverage": "%"}, _confidence)
    passed(f"[P̂∞]pp and the ±2σ coverage at σ_v = {' and '.join(f'{s:g}' for s in SIGMAS_V)} "
           f"cm match the pack's steady state and engine on the core path's runs to "
           f"{tolerance_text(MSE_RTOL)} relative")


@remembered
def _nis(column: int) -> dict[str, dict[str, object]]:
    """Right mean NIS and share of runs in the band at one σ_v, and likely mistakes."""
    burn, n = DEFAULT.burn_in_steps, DEFAULT.n_steps
    batch = monte_carlo()
    innovations = batch.innovations()
    e = innovations.values[:, column, :, 0]
    S = innovations.covariances[:, column, :, 0, 0]
    test = metrics.nis_test(metrics.Innovations(innovations.values[:, column],
                                                innovations.covariances[:, column]), burn)
    low, high = metrics.nis_band(1, n - burn)

    def inside(run_means: np.ndarray, band: tuple[float, float]) -> float:
        return 100.0 * float(np.mean((band[0] <= run_means) & (run_means <= band[1])))

    right = inside(test.run_means, (low, high))
    nees = (batch.positions[:, column] - _TRUTH) ** 2 / batch.position_variances[:, column]
    return {
        "nis_mean": {"right": test.mean, "mistakes": {
            "each e² is divided by R, the readings' noise alone; the innovation's variance "
            "S = C P Cᵀ + R also holds the uncertainty of the prediction":
                float(np.mean(e[:, burn:] ** 2 / SIGMAS_V[column] ** 2)),
            "the innovation is not squared: ε = e² / S": float(np.mean(e[:, burn:] / S[:, burn:])),
            "e is divided by √S and not squared: ε = e² / S":
                float(np.mean(np.abs(e[:, burn:]) / np.sqrt(S[:, burn:]))),
            "e² is not divided by S: the NIS normalises each squared innovation by its "
            "variance": float(np.mean(e[:, burn:] ** 2)),
            "it includes the burn-in: average the steps after it":
                float(np.mean(e**2 / S)),
            "it uses the true path (estimate − truth)² / variance, which no observer has; "
            "the NIS uses the innovations": float(np.mean(nees[:, burn:]))}},
        "runs_inside": {"right": right, "mistakes": {
            "it is a fraction; the task asks for a percentage": right / 100,
            "the band is that of the mean over all runs and steps; each run's mean needs "
            "the band of one run's steps, metrics.nis_band(1, DEFAULT.n_steps − burn)":
                inside(test.run_means, metrics.nis_band(1, test.samples)),
            "the band is that of a single step; each run's mean is over "
            "DEFAULT.n_steps − burn steps": inside(test.run_means, metrics.nis_band(1, 1)),
            "each run's mean includes the burn-in": inside(
                np.mean(e**2 / S, axis=-1), (low, high))}},
    }


def check_nis(nis_mean: dict[float, float], runs_inside: dict[float, float]) -> None:
    """Check part 3's NIS: its mean over runs and steps, and the share of runs in the band.

    Recomputed from the task's inputs before looking at the student's: the innovations of
    the core path's runs (:meth:`lqe_helpers.experiments.Tracking.innovations`), their NIS
    (:func:`lqe_helpers.metrics.nis_test` after the burn-in), and the percentage of runs
    whose own mean NIS lies in ``metrics.nis_band(1, n − burn)``; each within
    :data:`MSE_RTOL` relative.

    Parameters
    ----------
    nis_mean : dict of float to float
        Mean NIS over the runs and the steps after the burn-in, keyed by σ_v (cm).
    runs_inside : dict of float to float
        Percentage of runs whose mean NIS lies in the one-run band, keyed by σ_v (cm).

    Raises
    ------
    CheckFailed
        Naming the entry and the likely cause: e² / R for e² / S, e not squared, the
        burn-in included, the true path used, the band of another number of steps, a
        fraction for a percentage, ...
    """
    values = {"nis_mean": keyed(nis_mean, "nis_mean", "mean NIS values"),
              "runs_inside": keyed(runs_inside, "runs_inside", "percentages of runs")}
    _judge_each_sigma(values, {"nis_mean": "", "runs_inside": "%"}, _nis)
    passed(f"the mean NIS and the share of runs inside the 95 % band at σ_v = "
           f"{' and '.join(f'{s:g}' for s in SIGMAS_V)} cm match metrics.nis_test on the core "
           f"path's runs to {tolerance_text(MSE_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Part 4: the sampling rate
# ------------------------------------------------------------------------------------------

@remembered
def _sampling_mses(dt: float, jerk_std: float | None = None) -> dict[str, np.ndarray]:
    """Per-run MSEs (runs,) (cm²) of part 4's raw readings and estimates at Δt = ``dt``.

    ``DEFAULT.mc_runs`` runs at σ_v = :data:`SAMPLING_SIGMA_V` of
    ``dataclasses.replace(DEFAULT, dt=dt, jerk_std=jerk_std)`` (``jerk_std`` None: σ_j
    matched to Δt), keyed ``raw`` and ``filtered`` after the scenario's burn-in, and
    ``…_default`` after ``DEFAULT.burn_in_steps`` samples and ``…_whole`` over the whole
    trial (two likely mistakes). Only these are kept, not the runs (up to 60 MB each).
    """
    scenario = dataclasses.replace(DEFAULT, dt=dt, jerk_std=jerk_std)
    runs = experiments.track(scenario, sigmas=[SAMPLING_SIGMA_V], runs=DEFAULT.mc_runs)
    truth = scenario.truth[:, 0]
    found = {}
    for suffix, burn in (("", scenario.burn_in_steps), ("_default", DEFAULT.burn_in_steps),
                         ("_whole", 0)):
        found[f"raw{suffix}"] = metrics.mse(runs.measurements[..., 0], truth, burn)
        found[f"filtered{suffix}"] = metrics.mse(runs.positions, truth, burn)
    for array in found.values():
        array.setflags(write=False)
    return found


def _ratio(mses: dict[str, np.ndarray], suffix: str = "") -> float:
    """Mean raw MSE / mean filtered MSE of :func:`_sampling_mses` (after the burn-in
    ``suffix`` names)."""
    return float(mses[f"raw{suffix}"].mean() / mses[f"filtered{suffix}"].mean())


def _ratio_mistakes(dt: float) -> dict[str, float]:
    mses = _sampling_mses(dt)
    raw, filtered = mses["raw"], mses["filtered"]
    burn = dataclasses.replace(DEFAULT, dt=dt).burn_in_steps
    return {
        "it is filtered / raw; the task asks for raw / filtered": float(
            filtered.mean() / raw.mean()),
        f"σ_j is held at {DEFAULT.process_jerk_std:,.0f} cm/s³ at every Δt, so the jerk "
        f"intensity σ_j² Δt changes with Δt; leave jerk_std unset (the scenario matches σ_j "
        f"to Δt)": _ratio(_sampling_mses(dt, DEFAULT.process_jerk_std)),
        f"it leaves out {DEFAULT.burn_in_steps} samples at every Δt; the burn-in is "
        f"{DEFAULT.burn_in:g} s, which is {burn} samples at Δt = {dt:g} s":
            _ratio(mses, "_default"),
        "it is the mean of the per-run ratios; the task asks for the ratio of the mean MSEs":
            float(np.mean(raw / filtered)),
        "it is one run's ratio; use all DEFAULT.mc_runs runs": float(raw[0] / filtered[0]),
        "it is the ratio over the whole trial: leave out each scenario's burn-in":
            _ratio(mses, "_whole"),
    }


def check_sampling_ratio(ratio: dict[float, float]) -> None:
    """Check part 4: raw / filtered mean MSE at Δt = 0.02, 0.01 and 0.002 s.

    Recomputed from the task's inputs before looking at the student's:
    ``dataclasses.replace(DEFAULT, dt=Δt)`` (σ_j matched to Δt), ``DEFAULT.mc_runs``
    runs at σ_v = 1.5 cm with :func:`lqe_helpers.experiments.track`, and the ratio of
    the mean MSEs after each scenario's burn-in; each within :data:`MSE_RTOL` relative.
    The likely mistakes are computed only when a value is wrong (they need more runs).

    Parameters
    ----------
    ratio : dict of float to float
        Mean raw MSE / mean filtered MSE, keyed by Δt (s).

    Raises
    ------
    CheckFailed
        Naming the entry and the likely cause: the ratio inverted, σ_j held fixed, the
        burn-in counted in samples of 0.01 s, the mean of per-run ratios, one run, ...
    """
    values = keyed(ratio, "ratio", "ratios raw / filtered", keys=SAMPLING_DTS, key="Δt",
                   unit="s")
    for dt in SAMPLING_DTS:
        name, right = f"ratio[{dt:g}]", _ratio(_sampling_mses(dt))
        try:
            judge(name, values[dt], right, MSE_RTOL)
        except CheckFailed:
            judge(name, values[dt], right, MSE_RTOL, mistakes=_ratio_mistakes(dt),
                  what="the ratio recomputed from the task's inputs")
    passed(f"raw / filtered MSE at Δt = {', '.join(f'{dt:g}' for dt in SAMPLING_DTS)} s "
           f"({DEFAULT.mc_runs} runs at σ_v = {SAMPLING_SIGMA_V:g} cm each) matches the "
           f"pack's engine to {tolerance_text(MSE_RTOL)} relative")
