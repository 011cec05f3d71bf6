"""Checks of notebook 03's Going further tasks: what the settled fused filter is.

- :func:`check_noise_free_fits` (part 1): the sinusoids fitted to both filters' estimates
  on readings without noise, recomputed with the engine;
- :func:`check_settled_variances` (part 2): the settled position variances of both
  filters, from :func:`lqe_helpers.steady_state.steady_state`;
- :func:`check_equivalent_sensor` (part 3): σ/√2 and the single-sensor filter run on the
  averaged readings of Task 2's trial;
- :func:`check_settled_filter` (part 4): the settled vision-only filter's time constants
  and its response to the 0.5 Hz flight, from :mod:`lqe_helpers.lowpass`;
- :func:`check_halving` (part 4): what halving R does to the settled variance;
- :func:`check_gain_shares` (part 5): vision's share of the settled position gain.

Each recomputes from the task's inputs with the pack's engine, before looking at the
student's numbers; everything here is deterministic, so only round-off separates a right
answer from the recomputation (:data:`THEORY_RTOL`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .. import experiments, lowpass, metrics
from ..scenario import DEFAULT
from ..steady_state import steady_state
from .fusion import FUSED, engine_positions, monte_carlo_mses
from .judging import judge
from .machinery import CheckFailed, argument_array, passed, tolerance_text
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: Relative tolerance of a number computed from the settled filter, a fit or a filter run
#: (variances, time constants, gains, positions), of the expected value's largest entry.
THEORY_RTOL = 1e-6

#: The filters of the Going further parts, by the names the tasks use as keys.
FILTERS = {"vision only": ("vision",), "fused": FUSED}


def _model(sensors: tuple[str, ...], sigmas: list[float] | np.ndarray | None = None
           ) -> experiments.FilterModel:
    """The tasks' model of ``sensors`` (DEFAULT's σ unless ``sigmas`` (cm) are given)."""
    return experiments.filter_model(DEFAULT, sensors, sigmas=sigmas)


def _sigmas(sensors: tuple[str, ...]) -> np.ndarray:
    """The tasks' σ (cm) of ``sensors``: σ_v = σ_p = 1.5 cm."""
    return np.array([DEFAULT.sigma_v, DEFAULT.sigma_p][:len(sensors)])


def _position_variance(sensors: tuple[str, ...], sigmas: np.ndarray | None = None,
                       prediction: bool = False) -> float:
    """[P̂∞]pp (cm²), or [P∞]pp of the one-step prediction, of the tasks' settled filter."""
    steady = _model(sensors, sigmas).steady_state()
    return float((steady.covariance if prediction else steady.estimate_covariance)[0, 0])


# ------------------------------------------------------------------------------------------
# Part 1: the systematic error, without noise
# ------------------------------------------------------------------------------------------

@remembered
def _fits() -> dict[str, dict[str, metrics.SinusoidFit]]:
    """The right fit of each filter and the fits its likely mistakes give."""
    times, truth = DEFAULT.times, DEFAULT.truth[:, 0]
    burn, frequency = DEFAULT.burn_in_steps, DEFAULT.frequency
    trial = experiments.track(DEFAULT, FUSED).measurements
    found = {}
    for name, sensors in FILTERS.items():
        clean = experiments.track(DEFAULT, sensors,
                                  noise=np.zeros((DEFAULT.n_steps, len(sensors))))
        noisy = engine_positions(trial[:, :len(sensors)], list(_sigmas(sensors)))

        def fit(signal: np.ndarray, start: int = burn, at: float = frequency
                ) -> metrics.SinusoidFit:
            return metrics.fit_sinusoid(times[start:], signal[start:], at)

        found[name] = {
            "right": fit(clean.positions),
            "the fit includes the start-up: fit only the samples after the burn-in, times and "
            "positions alike": fit(clean.positions, 0),
            "it is the fit of the noisy trial's estimate (Task 2): feed the filter the true "
            "position itself, without noise": fit(noisy),
            "it is the fit of the readings (the true path itself), not of the filter's "
            "estimate": fit(truth),
            "it is the fit of the error (estimate − true position), not of the estimate":
                fit(clean.positions - truth),
            "the frequency was given in rad/s (2π f): fit_sinusoid takes it in Hz, "
            "DEFAULT.frequency": fit(clean.positions, at=2 * np.pi * frequency),
        }
    for name, other in (("vision only", "fused"), ("fused", "vision only")):
        found[name][f"it is the fit of the {other} filter: the keys are swapped"] = (
            found[other]["right"])
    return found


def check_noise_free_fits(fits: Mapping[str, metrics.SinusoidFit]) -> None:
    """Check part 1: sinusoids fitted to both filters' estimates on readings without noise.

    Recomputed from the task's inputs: the engine run on readings equal to the true
    position (:func:`lqe_helpers.experiments.track` with zero noise), vision alone and
    both senses, and :func:`lqe_helpers.metrics.fit_sinusoid` at ``DEFAULT.frequency``
    over the samples after the burn-in. Each amplitude (cm) and lead (s) must agree within
    :data:`THEORY_RTOL` relative.

    Parameters
    ----------
    fits : dict
        Keys ``"vision only"`` and ``"fused"``, each a fit with ``amplitude`` (cm) and
        ``lead`` (s), as :func:`~lqe_helpers.metrics.fit_sinusoid` returns it.

    Raises
    ------
    CheckFailed
        Naming the entry and the likely cause: the start-up included, the noisy trial's
        estimate, the readings or the error fitted, the frequency in rad/s, the keys
        swapped, ...
    """
    if not isinstance(fits, Mapping) or set(fits) != set(FILTERS):
        found = (f"keys {sorted(map(str, fits))}" if isinstance(fits, Mapping)
                 else "None" if fits is None else f"a {type(fits).__name__}")
        raise CheckFailed(f"fits must be a dict with the keys 'vision only' and 'fused', "
                          f"each a fit from metrics.fit_sinusoid; got {found}")
    right = _fits()
    for name, fit in fits.items():
        if not all(hasattr(fit, part) for part in ("amplitude", "lead")):
            raise CheckFailed(f"fits[{name!r}] must be what metrics.fit_sinusoid returns "
                              f"(with .amplitude and .lead), got a {type(fit).__name__}")
        for part, unit in (("amplitude", "cm"), ("lead", "s")):
            judge(f"fits[{name!r}].{part}", getattr(fit, part),
                  getattr(right[name]["right"], part), THEORY_RTOL, unit=unit,
                  what=f"the {part} fitted to the {name} filter's noise-free estimate",
                  mistakes={cause: getattr(wrong, part)
                            for cause, wrong in right[name].items() if cause != "right"})
    passed(f"the amplitude and lead fitted to both filters' noise-free estimates (after "
           f"the first {DEFAULT.burn_in_steps} samples, at {DEFAULT.frequency:g} Hz) match "
           f"the pack's engine to {tolerance_text(THEORY_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Part 2: theory beside simulation
# ------------------------------------------------------------------------------------------

def check_settled_variances(theory_vision: float, theory_fused: float) -> None:
    """Check part 2: the settled position variance [P̂∞]pp (cm²) of each filter.

    Recomputed with :func:`lqe_helpers.steady_state.steady_state` of the tasks' models
    (vision alone with ``R = [[σ_v²]]``; both senses with ``R = diag(σ_v², σ_p²)``): the
    position entry of ``estimate_covariance``, within :data:`THEORY_RTOL` relative.

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: the prediction's covariance P∞, a standard
        deviation, σ where σ² belongs in R, the two swapped, the settled gain, the Monte
        Carlo MSE, ...
    """
    mses = monte_carlo_mses()
    for name, value, kind, other in (("theory_vision", theory_vision, "vision only", "fused"),
                                     ("theory_fused", theory_fused, "fused", "vision only")):
        sensors = FILTERS[kind]
        right = _position_variance(sensors)
        key = "vision_after" if kind == "vision only" else "fused_after"
        mistakes = {
            "it is [P∞]pp, the variance of the one-step prediction (the steady state's "
            "covariance): the estimate's own variance is its estimate_covariance":
                _position_variance(sensors, prediction=True),
            "it is a standard deviation (cm): the variance is its square (cm²)": np.sqrt(right),
            "R holds σ (cm) where the variance σ² (cm²) belongs":
                _position_variance(sensors, np.sqrt(_sigmas(sensors))),
            f"it is the {other} filter's variance": _position_variance(FILTERS[other]),
            "it is the settled gain K∞[p], not a variance":
                float(_model(sensors).steady_state().gain[0].sum()),
            "it is the Monte Carlo mean MSE of Task 3, not the theory": float(
                np.mean(mses[key])),
        }
        judge(name, value, right, THEORY_RTOL, unit="cm²", mistakes=mistakes,
              what=f"[P̂∞]pp of the settled {kind} filter")
    passed(f"both settled position variances [P̂∞]pp match steady_state to "
           f"{tolerance_text(THEORY_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Part 3: two equal senses behave like one better sense
# ------------------------------------------------------------------------------------------

def check_equivalent_sensor(sigma_eq: float, averaged_positions: np.ndarray) -> None:
    """Check part 3: σ_eq = σ/√2 and the single sensor run on Task 2's averaged readings.

    ``sigma_eq`` (cm) must be σ_v/√2 (σ_v = σ_p = 1.5 cm) and ``averaged_positions`` (cm,
    shape (n,)) the engine's vision-only filter with ``R = [[σ_eq²]]`` run on the mean of
    Task 2's two readings, each within :data:`THEORY_RTOL` of its largest value.

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: σ halved, the variance for the standard
        deviation, R without the halving, σ_eq unsquared in R, the sum of the readings,
        vision's readings alone, ...
    """
    sigma = DEFAULT.sigma_v
    right = sigma / np.sqrt(2.0)
    judge("sigma_eq", sigma_eq, right, THEORY_RTOL, unit="cm",
          what="the noise σ/√2 of one sensor as good as both together",
          mistakes={
              "σ was halved: fusion halves the variance σ², so σ is divided by √2": sigma / 2,
              "it is the variance σ²/2 (cm²): sigma_eq is a standard deviation (cm)":
                  sigma**2 / 2,
              "σ was multiplied by √2: two senses make the reading less noisy, not more":
                  sigma * np.sqrt(2.0),
              "it is σ itself: two senses together are less noisy than either": sigma,
          })
    y = experiments.track(DEFAULT, FUSED).measurements
    average = y.mean(axis=1, keepdims=True)
    n = DEFAULT.n_steps
    value = argument_array(averaged_positions, "averaged_positions",
                           f"the estimated positions (cm), an array of shape ({n},)")
    if value.ndim == 2 and value.shape[0] == n:
        raise CheckFailed(f"averaged_positions has shape {value.shape}: keep only column 0 "
                          f"of the estimates, the position, shape ({n},)")
    judge("averaged_positions", value, engine_positions(average, [right]), THEORY_RTOL,
          unit="cm", what="the single-sensor filter's positions on the averaged readings",
          mistakes={
              "R is σ² of one sense: the average of two readings has the variance σ²/2, "
              "so R = [[sigma_eq²]]": engine_positions(average, [sigma]),
              "R holds sigma_eq (cm) where its square belongs":
                  engine_positions(average, [np.sqrt(right)]),
              "the filter read the sum of the two readings, not their average":
                  engine_positions(y.sum(axis=1, keepdims=True), [right]),
              "the filter read vision's readings alone (column 0), not the average":
                  engine_positions(y[:, :1], [right]),
              "it is column 1 of the estimates, the velocity (cm/s): the position is "
              "column 0": engine_positions(average, [right], 1),
              "these are the averaged readings, not the filter's estimate": average[:, 0],
          })
    passed(f"sigma_eq = σ/√2 and the single sensor's positions on the averaged readings "
           f"match the pack's engine to {tolerance_text(THEORY_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Part 4: the settled filter is a fixed low-pass filter
# ------------------------------------------------------------------------------------------

def _settled(sensors: tuple[str, ...]) -> lowpass.LowPass:
    m = _model(sensors)
    return lowpass.steady_lowpass(m.A, m.C, m.Q, m.R, DEFAULT.dt)


def _taus(closed_loop: np.ndarray, scale: float = DEFAULT.dt,
          log: object = np.log) -> np.ndarray:
    """Time constants ``−scale / log|λ|`` of the poles of ``closed_loop``, largest first."""
    return np.sort(-scale / log(np.abs(np.linalg.eigvals(closed_loop))))[::-1]


def check_settled_filter(time_constants: np.ndarray, predicted_amplitude: float,
                         predicted_lead: float) -> None:
    """Check part 4: the settled vision-only filter's time constants and 0.5 Hz response.

    Recomputed with :mod:`lqe_helpers.lowpass` from the tasks' vision-only model: the time
    constants ``−Δt / ln|λ|`` (s) of the poles of ``M = (I − K∞ C) A`` (compared in
    descending order), and the position response at ``DEFAULT.frequency``: the amplitude
    ``DEFAULT.amplitude · |H|`` (cm) and the lead (s), each within :data:`THEORY_RTOL`.

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: time constants in samples or ms, log10 for
        ln, complex or infinite time constants, M without A in the correction, the fused
        filter, the gain for the amplitude, the phase for the lead, the frequency in
        rad/s, ...
    """
    settled, fused = _settled(("vision",)), _settled(FUSED)
    if np.iscomplexobj(time_constants):
        raise CheckFailed(
            "time_constants holds complex numbers: the log of a complex pole is complex. "
            "Take the modulus |λ| of each pole before the log")
    try:
        raw = np.asarray(time_constants, dtype=float)
    except (TypeError, ValueError):
        raw = None
    if raw is not None and raw.shape == (3,) and np.any(np.isinf(raw)):
        raise CheckFailed(
            "time_constants holds an infinite time: a pole with |λ| = 1 never fades. Is M "
            "the bare A? M = (I − K∞ C) A includes the correction")
    values = argument_array(time_constants, "time_constants",
                            "three times (s), an array of shape (3,)", shape=(3,))
    m = _model(("vision",))
    gain = settled.gain
    judge("time_constants", np.sort(values)[::-1],
          _taus(settled.closed_loop), THEORY_RTOL, unit="s",
          what="the time constants −Δt / ln|λ| of the poles of M = (I − K∞ C) A",
          mistakes={
              "they are in samples: multiply −1 / ln|λ| by Δt to get seconds":
                  _taus(settled.closed_loop, 1.0),
              "they are in ms: the task asks for seconds": 1000 * _taus(settled.closed_loop),
              "log10 was used where the natural log ln belongs":
                  _taus(settled.closed_loop, log=np.log10),
              "M is A − K∞ C: the correction acts on the prediction A ẑ, so M = (I − K∞ C) A":
                  _taus(m.A - gain @ m.C),
              "they are the fused filter's: the task asks for the vision-only filter (row 0 "
              "of C, the top-left entry of R)": _taus(fused.closed_loop),
              "they are the approximation Δt / (1 − |λ|): use −Δt / ln|λ|": np.sort(
                  DEFAULT.dt / (1 - np.abs(settled.poles)))[::-1],
          })
    frequency = DEFAULT.frequency
    response = lowpass.position_response(settled, frequency)
    radians = lowpass.position_response(settled, 2 * np.pi * frequency)
    other = lowpass.position_response(fused, frequency)
    amplitude = DEFAULT.amplitude
    judge("predicted_amplitude", predicted_amplitude, amplitude * response.gain[0],
          THEORY_RTOL, unit="cm", what="the amplitude |H| · 10 cm of the settled response",
          mistakes={
              "it is the gain |H|, a ratio: multiply it by the flight's amplitude (cm)":
                  response.gain[0],
              "it is the fused filter's: the task asks for the vision-only filter":
                  amplitude * other.gain[0],
              "the frequency was given in rad/s (2π f): position_response takes Hz":
                  amplitude * radians.gain[0],
          })
    judge("predicted_lead", predicted_lead, response.lead[0], THEORY_RTOL, unit="s",
          what="the lead of the settled response",
          mistakes={
              "it is the phase arg H (rad): the lead in s is the phase divided by 2π f":
                  response.phase[0],
              "it is in ms: the task asks for seconds": 1000 * response.lead[0],
              "the sign is reversed: a positive lead means the estimate runs ahead":
                  -response.lead[0],
              "it is the fused filter's: the task asks for the vision-only filter":
                  other.lead[0],
              "the frequency was given in rad/s (2π f): position_response takes Hz":
                  radians.lead[0],
          })
    passed(f"the settled vision-only filter's time constants and its amplitude and lead at "
           f"{frequency:g} Hz match lqe_helpers.lowpass to {tolerance_text(THEORY_RTOL)} "
           f"relative")


def _variances(sigmas: np.ndarray, factor: float = 1.0, prediction: bool = False,
               variance: bool = True) -> np.ndarray:
    """Settled position variances (cm²) of vision alone at R = factor · σ² (σ if not
    ``variance``), shape (s,)."""
    m = _model(("vision",))
    noise = (sigmas**2 if variance else sigmas) * factor
    steady = steady_state(m.A, m.C, m.Q, noise[:, None, None])
    return (steady.covariance if prediction else steady.estimate_covariance)[:, 0, 0]


def check_halving(sigma_sweep: np.ndarray, halving: np.ndarray) -> None:
    """Check part 4: how much halving R shrinks the settled position variance.

    For each σ of ``sigma_sweep`` (cm) the vision-only filter's [P̂∞]pp at R = σ²/2
    divided by that at R = σ² (:func:`lqe_helpers.steady_state.steady_state`), within
    :data:`THEORY_RTOL` relative.

    Raises
    ------
    CheckFailed
        Naming the likely cause: σ halved instead of R, the ratio upside down, the
        prediction's covariance, R from σ, standard deviations, a difference, ...
    """
    sigmas = argument_array(sigma_sweep, "sigma_sweep", "noise levels σ (cm), shape (s,)")
    if sigmas.ndim != 1 or sigmas.size < 1 or np.any(sigmas <= 0):
        raise CheckFailed(f"sigma_sweep must be noise levels σ > 0 cm, shape (s,), got "
                          f"{sigmas.tolist()}")
    full = _variances(sigmas)
    judge("halving", halving, _variances(sigmas, 0.5) / full, THEORY_RTOL,
          what="[P̂∞]pp at R = σ²/2 over [P̂∞]pp at R = σ², recomputed with steady_state",
          mistakes={
              "σ was halved, which divides R by 4: halve R = σ² itself":
                  _variances(sigmas, 0.25) / full,
              "the ratio is upside down: the variance at R/2 over the variance at R":
                  full / _variances(sigmas, 0.5),
              "it is the ratio of [P∞]pp, the one-step prediction's variance: use "
              "estimate_covariance": _variances(sigmas, 0.5, prediction=True)
              / _variances(sigmas, prediction=True),
              "R was built from σ (cm) where σ² (cm²) belongs":
                  _variances(sigmas, 0.5, variance=False) / _variances(sigmas, variance=False),
              "it is the ratio of standard deviations: compare the variances themselves":
                  np.sqrt(_variances(sigmas, 0.5) / full),
              "it is the difference of the variances, not their ratio":
                  _variances(sigmas, 0.5) - full,
          })
    passed(f"the effect of halving R on the settled variance at {sigmas.size} values of σ "
           f"matches steady_state to {tolerance_text(THEORY_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Part 5: reliability-weighted cue combination
# ------------------------------------------------------------------------------------------

def check_gain_shares(sigma_p_values: np.ndarray, share_vision: np.ndarray) -> None:
    """Check part 5: vision's share of the settled position gain for each σ_p (vision 1.5 cm).

    Recomputed from :func:`lqe_helpers.experiments.filter_model` of both senses at
    ``σ_v = DEFAULT.sigma_v`` and each σ_p: ``K∞[p, vision] / (K∞[p, vision] +
    K∞[p, proprioception])``, within :data:`THEORY_RTOL` relative.

    Raises
    ------
    CheckFailed
        Naming the likely cause: proprioception's share, the gain not normalised, weights
        from σ instead of σ², the sum over the states instead of the senses, ...
    """
    sigma_p = argument_array(sigma_p_values, "sigma_p_values",
                             "noise levels σ_p (cm), shape (s,)")
    if sigma_p.ndim != 1 or sigma_p.size < 1 or np.any(sigma_p <= 0):
        raise CheckFailed(f"sigma_p_values must be noise levels σ_p > 0 cm, shape (s,), "
                          f"got {sigma_p.tolist()}")
    sigma_v = DEFAULT.sigma_v
    sigmas = np.stack([np.full_like(sigma_p, sigma_v), sigma_p], axis=-1)
    gain = _model(FUSED, sigmas).steady_state().gain       # (s, 3, 2)
    right = gain[:, 0, 0] / gain[:, 0].sum(axis=-1)
    judge("share_vision", share_vision, right, THEORY_RTOL,
          what="vision's share of the settled position gain K∞[p]",
          mistakes={
              "it is proprioception's share: vision's is K∞[p, vision] / (K∞[p, vision] + "
              "K∞[p, proprioception])": 1 - right,
              "it is the gain K∞[p, vision] itself: divide it by the sum of both senses' "
              "position gains": gain[:, 0, 0],
              "the weights come from 1/σ: reliability is 1/σ², the inverse variance":
                  (1 / sigma_v) / (1 / sigma_v + 1 / sigma_p),
              "the sum runs over the states (p, v, a) of vision's column, not over the two "
              "senses of the position row": gain[:, 0, 0] / gain[:, :, 0].sum(axis=-1),
          })
    passed(f"vision's share of the settled position gain at {sigma_p.size} values of σ_p "
           f"matches steady_state to {tolerance_text(THEORY_RTOL)} relative")
