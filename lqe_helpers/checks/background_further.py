"""Checks of notebook 00's Going further tasks A, B and D, each recomputed from its inputs.

- :func:`check_one_step_error` (A): A's one-step miss on the true path, the Taylor terms
  it drops and the spread Q allows;
- :func:`check_uncertainty_growth` (B): 2σ of the position with no measurement, from a
  known start and from the settled filter;
- :func:`check_white_jerk` (D): the white-jerk Q and what it changes in the MSE.

Tasks C and E, about choosing σ_j, are checked in
:mod:`lqe_helpers.checks.background_jerk_choice`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np

from .. import experiments, metrics, model
from ..prediction import propagate_covariance
from ..scenario import DEFAULT
from .judging import judge, judge_interval
from .machinery import (
    INTERVAL_RTOL,
    MATRIX_RTOL,
    CheckFailed,
    keyed_entries,
    passed,
    shaped_argument,
    tolerance_text,
)
from .paired_mistakes import interval_mistakes
from .remembering import remembered
from .shared_runs import vision_runs

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: Steps of 0.01 s over which Task B grows the covariance (1 s).
GROWTH_STEPS = 100
#: Task B's factors of σ_j, from a perfectly known start.
GROWTH_FACTORS = (0.1, 1.0, 10.0)
#: Task D's number of sub-steps per step.
SUB_STEPS = 1000


def _sigma_j() -> float:
    return DEFAULT.process_jerk_std


# ------------------------------------------------------------------------------------------
# A · A's error on the true path
# ------------------------------------------------------------------------------------------

def check_one_step_error(max_error: object, dropped: object, allowed: object) -> None:
    """Check Task A: A's largest one-step miss, the Taylor terms it drops, Q's spread.

    Recomputed from the task's inputs: ``DEFAULT.truth[1:] − DEFAULT.truth[:-1] Aᵀ``
    (its largest magnitude per component), ``A ω³ · [Δt³/6, Δt²/2, Δt]`` and
    ``√diag(DEFAULT.Q)``, each within :data:`MATRIX_RTOL` relative.

    Parameters
    ----------
    max_error, dropped, allowed : array_like, shape (3,)
        For p, v and a (cm, cm/s, cm/s²).

    Raises
    ------
    CheckFailed
        With the likely cause: A applied transposed, the step compared with the same
        sample, the mean instead of the largest, the acceleration's peak for the jerk's,
        Δt³ without the 1/6, Q's variances for its standard deviations, ...
    """
    truth, dt, A = DEFAULT.truth, DEFAULT.dt, DEFAULT.A
    omega = 2 * np.pi * DEFAULT.frequency
    residual = truth[1:] - truth[:-1] @ A.T
    judge("max_error", shaped_argument(max_error, "max_error", (3,), "the largest miss of p, v, a"),
          np.abs(residual).max(axis=0), MATRIX_RTOL, unit="cm, cm/s, cm/s²",
          what="the largest |truth[j + 1] − A truth[j]| recomputed",
          mistakes={
              "A is applied transposed: a state stored as a row z is moved by z Aᵀ "
              "(truth[:-1] @ A.T)": np.abs(truth[1:] - truth[:-1] @ A).max(axis=0),
              "it compares A truth[j] with truth[j] itself: compare with the next true "
              "state, truth[j + 1]": np.abs(truth[:-1] - truth[:-1] @ A.T).max(axis=0),
              "it is the largest step of the true path itself (truth[j + 1] − truth[j]), "
              "not what A misses of it": np.abs(truth[1:] - truth[:-1]).max(axis=0),
              "it is the mean absolute error; the task asks for the largest":
                  np.abs(residual).mean(axis=0),
          })
    jerk = DEFAULT.amplitude * omega**3
    terms = np.array([dt**3 / 6, dt**2 / 2, dt])
    judge("dropped", shaped_argument(dropped, "dropped", (3,), "the dropped Taylor terms"),
          jerk * terms, MATRIX_RTOL, unit="cm, cm/s, cm/s²",
          what="A ω³ · [Δt³/6, Δt²/2, Δt] recomputed",
          mistakes={
              "it uses the largest acceleration A ω²; the dropped term is the jerk's, A ω³":
                  DEFAULT.amplitude * omega**2 * terms,
              "ω is f (Hz) where ω = 2πf (rad/s) belongs":
                  DEFAULT.amplitude * DEFAULT.frequency**3 * terms,
              "the factorials are missing: Δt³/6 (3!) and Δt²/2 (2!)":
                  jerk * np.array([dt**3, dt**2, dt]),
              "the position's term is Δt³/3; the Taylor series has Δt³/3! = Δt³/6":
                  jerk * np.array([dt**3 / 3, dt**2 / 2, dt]),
          })
    Q = DEFAULT.Q
    judge("allowed", shaped_argument(allowed, "allowed", (3,), "the σ per step of Q"),
          np.sqrt(np.diag(Q)), MATRIX_RTOL, unit="cm, cm/s, cm/s²",
          what="√diag(DEFAULT.Q) recomputed",
          mistakes={
              "it is Q's diagonal, the variances; the standard deviation is its square root":
                  np.diag(Q),
              "it is 2σ; the task asks for σ, the square root of Q's diagonal":
                  2 * np.sqrt(np.diag(Q)),
          })
    passed(f"max_error, dropped and allowed match truth[j + 1] − A truth[j], A ω³ "
           f"[Δt³/6, Δt²/2, Δt] and √diag(Q) recomputed on the scenario's path, to "
           f"{tolerance_text(MATRIX_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# B · the law of growth
# ------------------------------------------------------------------------------------------

def _grown(start: np.ndarray, jerk_std: float) -> np.ndarray:
    """2σ of the position (cm) after 1 … 100 steps from ``start`` with Q of ``jerk_std``."""
    Q = model.process_noise_covariance(DEFAULT.dt, jerk_std)
    return 2 * np.sqrt(propagate_covariance(start, DEFAULT.A, Q, GROWTH_STEPS)[1:, 0, 0])


def _band_mistakes(start: np.ndarray, jerk_std: float, factor: float = 1.0) -> dict:
    """Wrong 2σ curves of Task B for one start, each with its cause."""
    right = _grown(start, jerk_std)
    Q = model.process_noise_covariance(DEFAULT.dt, _sigma_j())
    return {
        "it is σ, not 2σ": right / 2,
        "it is the variance (or twice it), not 2σ: take the square root of P[0, 0]":
            (right / 2) ** 2,
        "it is twice the variance: 2σ is twice the square root of P[0, 0]": right**2 / 2,
        "the factor multiplies Q, not σ_j: Q grows with σ_j², so ten times σ_j is a hundred "
        "times Q": 2 * np.sqrt(propagate_covariance(start, DEFAULT.A, factor * Q,
                                                    GROWTH_STEPS)[1:, 0, 0]),
    }


def check_uncertainty_growth(from_zero: Mapping[float, np.ndarray],
                             from_settled: np.ndarray) -> None:
    """Check Task B: 2σ of the position over 1 s with no measurement.

    Recomputed with :func:`lqe_helpers.prediction.propagate_covariance`, ``DEFAULT.A``
    and :func:`lqe_helpers.model.process_noise_covariance`: from P = 0 with σ_j times
    0.1, 1 and 10, and from the settled vision-only filter's estimate covariance
    (``experiments.filter_model(DEFAULT).steady_state()``) with the pack's σ_j; 2σ at
    0.01 … 1 s (100 values), each within :data:`MATRIX_RTOL` relative.

    Parameters
    ----------
    from_zero : dict of float to ndarray, shape (100,)
        2σ (cm) from P = 0, keyed by the factor of σ_j (0.1, 1, 10).
    from_settled : ndarray, shape (100,)
        2σ (cm) from the settled filter's covariance.

    Raises
    ------
    CheckFailed
        With the likely cause: σ or the variance instead of 2σ, the factor applied to Q
        instead of σ_j, the start kept (101 values), the prediction covariance of the
        settled filter instead of its estimate covariance, ...
    """
    curves = keyed_entries(from_zero, "from_zero", GROWTH_FACTORS, "2σ curves (cm, shape (100,))")
    zero = np.zeros((3, 3))
    for factor in GROWTH_FACTORS:
        _judge_curve(f"from_zero[{factor:g}]", curves[factor], zero, factor * _sigma_j(),
                     factor)
    settled = experiments.filter_model(DEFAULT).steady_state()
    _judge_curve("from_settled", from_settled, settled.estimate_covariance, _sigma_j(), 1.0,
                 extra={"it starts from the settled filter's prediction covariance (.covariance, "
                        "before a reading); start from its estimate covariance "
                        "(.estimate_covariance)": _grown(settled.covariance, _sigma_j()),
                        "it starts from P = 0; this curve starts from the settled filter's "
                        "covariance": _grown(zero, _sigma_j())})
    passed(f"the four 2σ curves match Lesson 0.5 eq. (9) carried {GROWTH_STEPS} steps by the "
           f"pack's engine from P = 0 (σ_j × 0.1, 1, 10) and from the settled filter, to "
           f"{tolerance_text(MATRIX_RTOL)} relative")


def _judge_curve(name: str, value: object, start: np.ndarray, jerk_std: float, factor: float,
                 extra: dict | None = None) -> None:
    try:
        shape = np.shape(value)
    except ValueError:
        shape = None
    if shape == (GROWTH_STEPS + 1,):
        raise CheckFailed(f"{name} has {GROWTH_STEPS + 1} values: leave out the start "
                          f"(t = 0), keep 2σ at 0.01 … 1 s, {GROWTH_STEPS} values")
    judge(name, value, _grown(start, jerk_std), MATRIX_RTOL, unit="cm",
          what="2σ of the position recomputed with eq. (9)",
          mistakes={**_band_mistakes(start, jerk_std, factor), **(extra or {})})


# ------------------------------------------------------------------------------------------
# D · white jerk
# ------------------------------------------------------------------------------------------

def white_jerk_q(jerk_std: float, dt: float, sub_steps: int) -> np.ndarray:
    """Q (3, 3) of a jerk held over ``sub_steps`` sub-steps of Δt/M each, summed directly.

    Each sub-step i (of h = Δt/M) adds its own jerk of variance σ_j² M (the same strength
    per unit time σ_j² Δt), moved to the end of the step by ``A((M − 1 − i) h)``:
    ``Q = σ_j² M Σ_i b_i b_iᵀ`` with ``b_i = A(i h) g(h)``, A of a longer time being the
    product of the shorter ones (constant acceleration).
    """
    h = dt / sub_steps
    g = model.jerk_input_matrix(h)[:, 0]
    t = np.arange(sub_steps) * h
    moved = np.stack([g[0] + t * g[1] + t**2 / 2 * g[2], g[1] + t * g[2],
                      np.full_like(t, g[2])], axis=-1)
    return jerk_std**2 * sub_steps * moved.T @ moved


@remembered
def _white() -> dict[str, object]:
    """Task D's Q_white and the paired % interval, recomputed, with wrong variants."""
    sigma_j, dt, M = _sigma_j(), DEFAULT.dt, SUB_STEPS
    right = white_jerk_q(sigma_j, dt, M)
    runs = vision_runs()
    truth, burn = DEFAULT.truth[:, 0], DEFAULT.burn_in_steps

    def mse_with(Q: np.ndarray, whole: bool = False) -> np.ndarray:
        estimates = dataclasses.replace(runs.model, Q=Q).filter(runs.measurements).estimates
        return metrics.mse(estimates[..., 0], truth, 0 if whole else burn)

    held, white = runs.mse(), mse_with(right)
    scale = 100 / held.mean()
    return {
        "Q": right,
        "Q_mistakes": {
            "each sub-step's jerk has σ_j; to keep the strength per unit time σ_j² Δt, a "
            "sub-step of Δt/M needs σ_j √M": white_jerk_q(sigma_j / np.sqrt(M), dt, M),
            "each sub-step's jerk has σ_j M; the variance σ_j² Δt is kept with σ_j √M":
                white_jerk_q(sigma_j * np.sqrt(M), dt, M),
        },
        "interval": metrics.mean_ci95(scale * (white - held)),
        "interval_mistakes": {
            **interval_mistakes(scale * white, scale * held, "the white-jerk MSE",
                                "the held-jerk MSE"),
            "it is in cm²; the task asks for the difference in % of the held-jerk MSE":
                metrics.mean_ci95(white - held),
            "each run is divided by its own held-jerk MSE; divide by the mean held-jerk MSE":
                metrics.mean_ci95(100 * (white - held) / held),
            "the MSEs are those of the whole trial: leave out the burn-in":
                metrics.mean_ci95(100 * (mse_with(right, True) - mse_with(DEFAULT.Q, True))
                                  / mse_with(DEFAULT.Q, True).mean()),
        },
    }


def check_white_jerk(Q_white: np.ndarray, white_vs_held: metrics.Interval) -> None:
    """Check Task D: the white-jerk Q and the paired MSE change white − held in %.

    ``Q_white`` is recomputed by a direct sum over the M = 1000 sub-steps
    (:func:`white_jerk_q`, another route than the task's step-by-step propagation) and
    must agree within :data:`MATRIX_RTOL` of its largest entry; ``white_vs_held``, the
    mean of 100 (MSE_white − MSE_held) / mean(MSE_held) over the ``DEFAULT.mc_runs`` runs
    with its 95 % interval, is recomputed with the pack's engine on the same runs and
    must agree within :data:`INTERVAL_RTOL` of the interval's scale.

    Raises
    ------
    CheckFailed
        With the likely cause: the sub-steps' σ not scaled by √M, the difference in cm²
        or the wrong way round, each run divided by its own MSE, the whole trial, ...
    """
    right = _white()
    Q = right["Q"]
    judge("Q_white", shaped_argument(Q_white, "Q_white", (3, 3), "the white-jerk Q"), Q,
          MATRIX_RTOL, what="the sum over the sub-steps recomputed",
          mistakes=right["Q_mistakes"])
    judge_interval("white_vs_held", white_vs_held, right["interval"], INTERVAL_RTOL, unit="%",
                   what="the paired change white − held recomputed with the engine",
                   mistakes=right["interval_mistakes"])
    passed(f"Q_white matches a direct sum over the {SUB_STEPS} sub-steps (to "
           f"{tolerance_text(MATRIX_RTOL)} relative) and white_vs_held the engine's paired "
           f"change over {DEFAULT.mc_runs} runs (to {tolerance_text(INTERVAL_RTOL)})")
