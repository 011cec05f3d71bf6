"""Checks of notebook 06, the bonus: the core tasks.

- :func:`check_bias_model` (Task 1): F, G and Q of the biased acceleration model;
- :func:`check_signal_worth` (Task 2): the paired MSE difference vision only − with the
  signal (positive: the signal helps), recomputed with :mod:`lqe_helpers.bias_model` and
  the engine.

The Going further tasks are checked in :mod:`lqe_helpers.checks.bias_further`.
"""

from __future__ import annotations

import numpy as np

from .. import bias_model, experiments, metrics
from ..scenario import DEFAULT
from .judging import burn_in_slips, judge_interval
from .machinery import (
    INTERVAL_RTOL,
    MATRIX_RTOL,
    CheckFailed,
    argument_array,
    close,
    passed,
    positive_number,
    tolerance_text,
)
from .paired_mistakes import interval_mistakes
from .remembering import remembered
from .shared_runs import vision_runs

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback


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
    F = argument_array(F, "F", "the transition matrix, an array of shape (3, 3)")
    G = argument_array(G, "G", "the input matrix, an array of shape (3, 1)")
    Q = argument_array(Q, "Q", "the process noise covariance, an array of shape (3, 3)")
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
        if close(F, right_F.T, MATRIX_RTOL):
            raise CheckFailed(
                "F is transposed: the state [p, v, b] is a column, so row 0 says how the new "
                "position is made from p, v and b; the entries above the diagonal belong in "
                "the first rows")
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
    if Q.shape == (1, 1):
        raise CheckFailed(
            "Q has shape (1, 1), one number: it is built as Gᵀ G. G is a column (3, 1), so "
            "the covariance G σ_a² Gᵀ puts G first and its transpose last, 3 × 3")
    if Q.shape != (3, 3):
        raise CheckFailed(f"Q must be 3 × 3 (G σ_a² Gᵀ with G of shape (3, 1)), got shape "
                          f"{Q.shape}")
    if not close(Q, right_Q, MATRIX_RTOL):
        if close(Q, sigma_a * right_G @ right_G.T, MATRIX_RTOL):
            raise CheckFailed("Q uses σ_a where its square belongs: Q = G σ_a² Gᵀ (variances, "
                              "not standard deviations)")
        if close(Q, sigma_a**2 * np.eye(3), MATRIX_RTOL) or close(
                Q, sigma_a**2 * np.diag(right_G[:, 0]), MATRIX_RTOL):
            raise CheckFailed("Q is not pushed through G: the signal's noise reaches the "
                              "state the way the signal does, Q = G σ_a² Gᵀ")
        if close(Q, np.diag(np.diag(right_Q)), MATRIX_RTOL):
            raise CheckFailed("Q holds only the diagonal of G σ_a² Gᵀ; one noisy reading moves "
                              "p and v together, so the off-diagonal entries belong too")
        if close(Q, DEFAULT.Q, MATRIX_RTOL):
            raise CheckFailed("Q is notebook 00's jerk noise (DEFAULT.Q, for the state [p, v, "
                              "a]); here the noise is the signal's, reaching the state "
                              "through G: G σ_a² Gᵀ")
        raise CheckFailed("Q is not G σ_a² Gᵀ (Lesson 0.5 eq. (9)) for the given σ_a")
    passed(f"F, G and Q = G σ_a² Gᵀ match Lesson 0.5 eqs. (5), (9) for Δt = {dt:g} s and "
           f"σ_a = {sigma_a:g} cm/s², to {tolerance_text(MATRIX_RTOL)}")


@remembered
def _signal_worth() -> dict[str, object]:
    """Task 2's paired interval vision only − with the signal (cm²), with the usual wrong ones."""
    truth = DEFAULT.truth[:, 0]
    with_signal = bias_model.track_with_input(DEFAULT, runs=DEFAULT.mc_runs)
    vision = vision_runs()
    alone, helped = vision.mse(), with_signal.mse()
    right = metrics.mean_ci95(alone - helped)
    return {
        "right": right,
        "mistakes": {
            **interval_mistakes(alone, helped, "the vision-only MSE",
                                "the MSE with the signal"),
            "it is in % of the vision-only MSE; the task asks for the difference in cm²":
                metrics.mean_ci95(100 * (alone - helped) / alone.mean()),
            "it is in % of the vision-only MSE and the wrong way round; the task asks for "
            "the difference vision only − with the signal, in cm²":
                metrics.mean_ci95(100 * (helped - alone) / alone.mean()),
            "it is a fraction of the vision-only MSE; the task asks for the difference in cm²":
                metrics.mean_ci95((alone - helped) / alone.mean()),
            "it is in % of each run's vision-only MSE; the task asks for the difference "
            "itself, in cm²": metrics.mean_ci95(100 * (alone - helped) / alone),
            "it is in % of each run's MSE with the signal; the task asks for the difference "
            "itself, in cm²": metrics.mean_ci95(100 * (alone - helped) / helped),
            "it is in % of the MSE with the signal; the task asks for the difference in cm²":
                metrics.mean_ci95(100 * (alone - helped) / helped.mean()),
            "it is the difference of the root mean squared errors (√MSE, in cm), run by run; "
            "the task asks for the difference of the MSEs themselves, in cm²":
                metrics.mean_ci95(np.sqrt(alone) - np.sqrt(helped)),
            "it is the square root of the interval of the MSE difference (√ cm²); the task "
            "asks for the difference of the MSEs itself, in cm²": _rooted(right),
            "each run's difference is divided by that run's vision-only MSE; the task asks "
            "for the difference itself, in cm²": metrics.mean_ci95((alone - helped) / alone),
            "it is a ratio of the MSEs; the task asks for their difference, in cm²":
                metrics.mean_ci95(alone / helped),
            "the MSEs are those of the whole trial: leave out the burn-in in both":
                metrics.mean_ci95(metrics.mse(vision.positions, truth)
                                  - metrics.mse(with_signal.positions, truth)),
            "it uses dead reckoning's MSE (the signal integrated without vision), not the "
            "filter's (mc.mse())": metrics.mean_ci95(alone - with_signal.dead_reckoning_mse()),
            f"the vision-only runs are a single run, not {DEFAULT.mc_runs} runs paired with "
            f"the signal's": metrics.mean_ci95(float(experiments.track(DEFAULT).mse()) - helped),
            "one side is the mean MSE over the runs, the other the per-run MSEs; pair the "
            "per-run MSEs run by run (vision_only.mse() − mc.mse())":
                metrics.mean_ci95(alone.mean() - helped),
            "one side is the per-run MSEs, the other the mean MSE over the runs; pair the "
            "per-run MSEs run by run (vision_only.mse() − mc.mse())":
                metrics.mean_ci95(alone - helped.mean()),
            **{cause: metrics.mean_ci95(metrics.mse(vision.positions, truth, start)
                                        - metrics.mse(with_signal.positions, truth, start))
               for cause, start in burn_in_slips(DEFAULT.burn_in_steps, truth.size).items()},
        },
        "runs_of": (alone, helped, "Make vision_only with experiments.track(DEFAULT, "
                                   "runs=DEFAULT.mc_runs), which uses mc's camera noise, and "
                                   "subtract mc.mse() from vision_only.mse() as they come"),
    }


def _rooted(interval: metrics.Interval) -> metrics.Interval:
    """The interval with the square root taken of its mean and ends (NaN where < 0)."""
    with np.errstate(invalid="ignore"):
        parts = np.sqrt([interval.mean, interval.low, interval.high])
    return metrics.Interval(*(float(part) for part in parts), interval.runs)


def check_signal_worth(improvement: metrics.Interval) -> None:
    """Check Task 2: the paired MSE difference vision only − with the signal (cm²).

    Positive means the signal helps, as in notebooks 01, 03–05 (baseline − improved).
    Recomputed from the task's inputs before looking at the student's: the
    ``DEFAULT.mc_runs`` runs of :func:`lqe_helpers.bias_model.track_with_input` at the
    default bias and σ_a, and as many runs of the vision-only filter
    (:func:`lqe_helpers.experiments.track`) on the same camera noise; ``metrics.mean_ci95``
    of the per-run MSE differences after the burn-in, within :data:`INTERVAL_RTOL` of the
    interval's scale.

    Parameters
    ----------
    improvement : metrics.Interval
        Mean of MSE(vision only) − MSE(with the signal) over the runs, with its 95 %
        interval (cm²).

    Raises
    ------
    CheckFailed
        With the likely cause: the difference the wrong way round, unpaired (another noise
        draw, runs out of order), in % of either MSE, the RMSE or its root, over the whole
        trial or the burn-in a sample off, dead reckoning's MSE for the filter's, one
        vision-only run, ...
    """
    right = _signal_worth()
    judge_interval("improvement", improvement, right["right"], INTERVAL_RTOL,
                   unit="cm²", what="the paired difference vision only − with the signal, "
                                    "recomputed from the task's inputs",
                   mistakes=right["mistakes"], runs_of=right["runs_of"])
    passed(f"vision only − with the signal, paired over {DEFAULT.mc_runs} runs: mean and 95 % "
           f"interval match the pack's engine on the task's draws to "
           f"{tolerance_text(INTERVAL_RTOL)} relative")
