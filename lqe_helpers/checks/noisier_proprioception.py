"""Checks of notebook 04, question (d): proprioception three times noisier than vision.

Every check recomputes what its task asks from the question's values and the task's own
draws (the scenario's seed, the pack's engine :func:`lqe_helpers.experiments.track`)
before it looks at the student's value, and names the likely cause of a wrong one:

- :func:`check_noisier_sense` (Task 1): σ_p itself and R;
- :func:`check_noisier_trial` (Task 2): one trial filtered both ways, the positions and
  the two MSEs;
- :func:`check_noisier_difference` (Task 3): the per-run MSEs and the paired vision-only
  − fused MSE over the Monte Carlo runs, after the first second;
- Going further 1 and 2 are checked in
  :mod:`lqe_helpers.checks.noisier_proprioception_further`, Going further 4 (a misjudged
  σ_p) in :mod:`lqe_helpers.checks.misjudged_noise`; both share this module's Monte
  Carlo runs.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from .. import experiments, metrics
from ..scenario import DEFAULT
from .fusion import (
    VISION_WITH_BOTH_SENSES,
    engine_positions,
    judge_noise_matrix,
    judge_together,
    position_array,
    setup_slips,
)
from .judging import judge, judge_interval, mse_mistakes
from .machinery import (
    FUNCTION_RTOL,
    INTERVAL_RTOL,
    MATRIX_RTOL,
    MSE_RTOL,
    CheckFailed,
    argument_array,
    keyed_entries,
    passed,
    tolerance_text,
)
from .paired_mistakes import interval_mistakes, unit_mistakes
from .readings_slips import monte_carlo_readings_slips, sensor_readings
from .remembering import remembered

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: σ_v and σ_p of question (d) (cm).
SIGMA_V, SIGMA_P = 1.5, 4.5
#: σ_p of question (c) (cm), a value left in by mistake.
SIGMA_P_C = 1.5
#: The benefit levels (%) whose crossing Going further 2 reads off the theory.
BENEFIT_LEVELS = (10, 1)

#: The fused filter's sensors, in the column order of its readings.
FUSED = ("vision", "proprioception")
#: True position (cm), shape (n,), and the samples every MSE leaves out.
TRUTH = DEFAULT.truth[:, 0]
BURN = DEFAULT.burn_in_steps


@remembered
def monte_carlo(sigmas: tuple[float, ...],
                assumed: tuple[float, ...] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per-run MSEs (runs,) (cm²) after the burn-in and over the whole trial, read-only.

    ``DEFAULT.mc_runs`` runs of the engine on the scenario's draws with the true
    ``sigmas`` (cm): vision alone for one σ, fused for two; the filter assumes
    ``assumed`` (default the truth). Kept, so several checks share one run.
    """
    tracking = experiments.track(DEFAULT, FUSED[:len(sigmas)], sigmas=list(sigmas),
                                 assumed_sigmas=assumed, runs=DEFAULT.mc_runs)
    pair = (tracking.mse(), metrics.mse(tracking.positions, TRUTH))
    for array in pair:
        array.flags.writeable = False
    return pair


@remembered
def readings_slips() -> dict[str, dict]:
    """Task 3's per-run MSEs taken against readings instead of the truth (cm², (runs,)):
    :func:`~lqe_helpers.checks.readings_slips.monte_carlo_readings_slips` of the
    question's runs, with Task 2's one trial y."""
    senses = {"vision": (SIGMA_V,), "fused": (SIGMA_V, SIGMA_P)}
    runs = {kind: experiments.track(DEFAULT, FUSED[:len(sigmas)], sigmas=list(sigmas),
                                    runs=DEFAULT.mc_runs) for kind, sigmas in senses.items()}
    y = experiments.readings(DEFAULT, FUSED, sigmas=list(senses["fused"]))
    return monte_carlo_readings_slips({kind: run.positions for kind, run in runs.items()},
                                      {kind: run.measurements for kind, run in runs.items()},
                                      y, BURN)


def paired(first: np.ndarray, second: np.ndarray) -> metrics.Interval:
    """The paired difference ``first − second`` (per run) with its 95 % interval."""
    return metrics.mean_ci95(first - second)


def entries(name: str, values: object, keys: tuple[object, ...], what: str) -> dict:
    """The student's dict ``name``, which must hold ``keys``."""
    return keyed_entries(values, name, keys, what, keyed_by=f"{keys[0]!r}, … (the task's keys)",
                         advice=f"; the task asks for {', '.join(repr(key) for key in keys)}")


def sigma_grid(name: str, values: object) -> np.ndarray:
    """A σ grid the student chose (cm): 1-D, > 0, increasing."""
    grid = argument_array(values, name, "a 1-D array of σ values (cm)")
    if grid.ndim != 1 or grid.size < 3 or np.any(grid <= 0) or np.any(np.diff(grid) <= 0):
        raise CheckFailed(f"{name} must be a 1-D array of at least 3 increasing σ values > 0 "
                          f"(cm), got shape {grid.shape}")
    return grid


# ------------------------------------------------------------------------------------------
# Task 1: the noisier sense
# ------------------------------------------------------------------------------------------

def check_noisier_sense(sigma_p: float, R: np.ndarray) -> None:
    """Check Task 1: the student's σ_p and their R for question (d).

    Expected: ``sigma_p`` is question (d)'s σ_p = 4.5 cm (a standard deviation), within
    :data:`MATRIX_RTOL` relative, and ``R = diag(σ_v², σ_p²) = diag(2.25, 20.25)`` cm²,
    each entry within :data:`MATRIX_RTOL` relative.

    Parameters
    ----------
    sigma_p : float
        The student's proprioceptive noise σ_p (cm).
    R : array_like, shape (2, 2)
        The student's sensor noise covariance (cm²).

    Raises
    ------
    CheckFailed
        With the likely cause: σ_p² (cm²) given for σ_p, question (c)'s σ_p, the factor
        3 alone, three times vision's variance; in R: the σ for the σ², a variance nine
        times instead of three times vision's... (see
        :func:`~lqe_helpers.checks.fusion.judge_noise_matrix`).
    """
    judge("sigma_p", sigma_p, SIGMA_P, MATRIX_RTOL, unit="cm",
          what=f"question (d)'s σ_p = {SIGMA_P:g} cm", mistakes={
              f"it is σ_p² = {SIGMA_P**2:g} cm², a variance. sigma_p is the standard deviation "
              f"σ_p in cm; R holds its square": SIGMA_P**2,
              f"it is question (c)'s σ_p; question (d) makes proprioception three times as "
              f"noisy as vision's σ_v = {SIGMA_V:g} cm": SIGMA_P_C,
              f"it is the factor 3 alone; σ_p is three times vision's σ_v = {SIGMA_V:g} cm":
                  3.0,
              f"it is three times vision's variance σ_v²; (d) makes the standard deviation "
              f"three times σ_v = {SIGMA_V:g} cm": 3 * SIGMA_V**2,
              "it is √4.5; σ_p itself is 4.5 cm (R holds its square)": np.sqrt(SIGMA_P)})
    R = argument_array(R, "R", "the noise covariance (cm²), an array of shape (2, 2)")
    if R.shape == (2, 2) and np.allclose(np.diag(R), [SIGMA_V**2, 3 * SIGMA_V**2],
                                         rtol=MATRIX_RTOL, atol=0):
        raise CheckFailed(
            f"R's proprioceptive variance is three times vision's; (d) triples the standard "
            f"deviation σ_p = 3 σ_v = {SIGMA_P:g} cm, so the variance is nine times "
            f"vision's, σ_p² = {SIGMA_P**2:g} cm²")
    judge_noise_matrix(R, SIGMA_V, SIGMA_P)
    passed(f"σ_p = {SIGMA_P:g} cm and R = diag(σ_v², σ_p²) = diag({SIGMA_V**2:g}, "
           f"{SIGMA_P**2:g}) cm² (2 × 2), each to {tolerance_text(MATRIX_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Task 2: one trial, filtered both ways
# ------------------------------------------------------------------------------------------

@remembered
def _trial() -> dict[str, dict]:
    """Task 2's right positions (n,) (cm) and MSEs (cm²) of each filter, with the likely
    mistakes of each."""
    y = experiments.track(DEFAULT, FUSED, sigmas=[SIGMA_V, SIGMA_P]).measurements
    root = {"vision": [np.sqrt(SIGMA_V)], "fused": [np.sqrt(SIGMA_V), np.sqrt(SIGMA_P)]}
    positions = {"vision": engine_positions(y[:, :1], [SIGMA_V]),
                 "fused": engine_positions(y, [SIGMA_V, SIGMA_P])}
    velocity = "it is column 1 of the estimates, the velocity (cm/s): the position is column 0"
    sigma_for_variance = "R holds σ (cm) where the variance σ² (cm²) belongs"
    raw = "these are vision's readings, not the filter's estimate"
    mistakes = {
        "vision": {
            "it is the fused filter's estimate: the vision-only filter reads column 0 of the "
            "readings only, with row 0 of C and the top-left entry of R": positions["fused"],
            "the vision-only filter was given proprioception's readings (column 1); "
            "vision's are column 0": engine_positions(y[:, 1:], [SIGMA_V]),
            "the vision-only filter's R holds proprioception's variance σ_p²; vision's σ_v² "
            "is the top-left entry of R": engine_positions(y[:, :1], [SIGMA_P]),
            velocity: engine_positions(y[:, :1], [SIGMA_V], 1),
            sigma_for_variance: engine_positions(y[:, :1], root["vision"]),
            raw: y[:, 0],
            VISION_WITH_BOTH_SENSES: engine_positions(np.repeat(y[:, :1], 2, axis=1),
                                                      [SIGMA_V, SIGMA_P]),
            **setup_slips(y[:, :1], [SIGMA_V]),
        },
        "fused": {
            "it is the vision-only filter's estimate: the fused filter reads both columns "
            "of the readings with your C and R": positions["vision"],
            velocity: engine_positions(y, [SIGMA_V, SIGMA_P], 1),
            sigma_for_variance: engine_positions(y, root["fused"]),
            f"it is the filter of question (c), σ_p = {SIGMA_P_C:g} cm; (d) sets σ_p = "
            f"{SIGMA_P:g} cm": engine_positions(y, [SIGMA_V, SIGMA_P_C]),
            raw: y[:, 0],
            **setup_slips(y, [SIGMA_V, SIGMA_P]),
        },
    }

    def mse(x: np.ndarray) -> float:
        return float(metrics.mse(x, TRUTH, BURN))

    mse_wrong = {}
    for kind, other in (("vision", "fused"), ("fused", "vision")):
        mse_wrong[kind] = {
            f"it is the {'fused' if kind == 'vision' else 'vision-only'} filter's MSE":
                mse(positions[other]),
            "it is the MSE of vision's raw readings, not of a filtered estimate": mse(y[:, 0]),
            "it is the MSE of proprioception's raw readings, not of a filtered estimate":
                mse(y[:, 1]),
            **{f"it comes from a wrong estimate: {cause}": mse(wrong)
               for cause, wrong in mistakes[kind].items() if wrong is not positions[other]},
            **mse_mistakes(positions[kind], TRUTH, BURN, DEFAULT.dt,
                           readings=sensor_readings(y)),
        }
    return {"positions": positions, "mistakes": mistakes,
            "mse": {kind: mse(value) for kind, value in positions.items()},
            "mse_mistakes": mse_wrong}


def check_noisier_trial(vision_positions: np.ndarray, fused_positions: np.ndarray,
                        mse_vision_trial: float, mse_fused_trial: float) -> None:
    """Check Task 2: one trial filtered with vision alone and with both senses, and its MSEs.

    Recomputed before looking at the student's values: the scenario's trial at σ_v =
    1.5 cm and σ_p = 4.5 cm (:func:`lqe_helpers.experiments.track`), filtered by the
    pack's engine with P0 = diag(1, 1, 1) cm², both senses and vision alone (column 0
    of the readings). The positions (cm) must agree within :data:`FUNCTION_RTOL` of their
    largest value, each MSE (cm²) after the first ``DEFAULT.burn_in_steps`` samples within
    :data:`MSE_RTOL` relative. A slip in both filters is named for both.

    Parameters
    ----------
    vision_positions, fused_positions : array_like, shape (n,)
        The student's estimated positions (cm): column 0 of their filter's estimates.
    mse_vision_trial, mse_fused_trial : float
        The student's MSEs (cm²) after the burn-in.

    Raises
    ------
    CheckFailed
        Naming each wrong value and the likely cause: the velocity column, the two
        swapped, proprioception's readings or σ_p² in the vision-only filter, σ where σ²
        belongs, question (c)'s σ_p, the raw readings, the whole trial, the burn-in in
        seconds, the RMSE, ...
    """
    right = _trial()
    n = DEFAULT.n_steps
    label = {"vision": "vision-only", "fused": "fused"}

    def positions(kind: str, name: str, value: object) -> None:
        judge(name, position_array(value, name, n), right["positions"][kind], FUNCTION_RTOL,
              unit="cm", mistakes=right["mistakes"][kind],
              what=f"the {label[kind]} filter's positions recomputed from the task's trial")

    def mse(kind: str, name: str, value: object) -> None:
        judge(name, value, right["mse"][kind], MSE_RTOL, unit="cm²",
              mistakes=right["mse_mistakes"][kind],
              what=f"the {label[kind]} filter's MSE recomputed from the task's inputs")

    judge_together(partial(positions, "vision", "vision_positions", vision_positions),
                   partial(positions, "fused", "fused_positions", fused_positions))
    judge_together(partial(mse, "vision", "mse_vision_trial", mse_vision_trial),
                   partial(mse, "fused", "mse_fused_trial", mse_fused_trial))
    passed(f"both filters' positions (σ_v = {SIGMA_V:g} cm, σ_p = {SIGMA_P:g} cm) match the "
           f"pack's engine on the task's trial to {tolerance_text(FUNCTION_RTOL)} of the "
           f"largest, and both MSEs (after the first {BURN} samples) to "
           f"{tolerance_text(MSE_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Task 3: many runs, paired
# ------------------------------------------------------------------------------------------

def check_noisier_difference(mse_vision: np.ndarray, mse_fused: np.ndarray,
                             difference: metrics.Interval) -> None:
    """Check Task 3's per-run MSEs and their paired difference vision-only − fused.

    Recomputed before looking at the student's values: ``DEFAULT.mc_runs`` runs of both
    filters on the scenario's draws (:func:`lqe_helpers.experiments.track`, σ_v = 1.5 cm,
    σ_p = 4.5 cm, run r of both on the same visual noise), their per-run MSEs after the
    first second (each within :data:`MSE_RTOL` relative) and ``metrics.mean_ci95`` of the
    per-run differences (mean and ends within :data:`INTERVAL_RTOL` of the interval's
    scale).

    Parameters
    ----------
    mse_vision, mse_fused : array_like, shape (runs,)
        The student's per-run MSEs (cm²) after the first second.
    difference : metrics.Interval
        The student's paired difference (cm²) after the first second.

    Raises
    ------
    CheckFailed
        With the likely cause: the two filters swapped, one run, the whole trial, σ_p of
        question (c), σ_p² given as the noise, the sign reversed, the runs unpaired, a
        percentage, ...
    """
    runs = DEFAULT.mc_runs
    vision = monte_carlo((SIGMA_V,))
    fused = monte_carlo((SIGMA_V, SIGMA_P))
    fused_c = monte_carlo((SIGMA_V, SIGMA_P_C))
    fused_squared = monte_carlo((SIGMA_V, SIGMA_P**2))
    both_squared = monte_carlo((SIGMA_V**2, SIGMA_P**2))
    sigma_causes = {
        f"the fused filter's σ_p is question (c)'s {SIGMA_P_C:g} cm; (d) sets σ_p = "
        f"{SIGMA_P:g} cm": fused_c,
        "σ_p² (cm²) was given where σ_p (cm) belongs: sigmas holds standard deviations":
            fused_squared,
        "the σ² (cm²) were given where the σ (cm) belong: sigmas holds standard deviations":
            both_squared,
    }

    against_readings = readings_slips()

    def per_run(name: str, right: tuple[np.ndarray, np.ndarray],
                other: tuple[np.ndarray, np.ndarray], other_name: str,
                wrong: dict[str, tuple[np.ndarray, np.ndarray]], kind: str,
                value: object) -> None:
        array = argument_array(value, name, f"one MSE per run (cm²), an array of shape "
                                            f"({runs},)")
        if array.size == 1:
            raise CheckFailed(f"{name} is one number; the task asks for one MSE per run, "
                              f"shape ({runs},): .mse() of a result of {runs} runs gives them")
        judge(name, array, right[0], MSE_RTOL, unit="cm²",
              what="the per-run MSEs after the first second recomputed from the task's runs",
              mistakes={f"these are the {other_name} filter's MSEs": other[0],
                        "these are over the whole trial; the MSEs leave out the first second "
                        "(the start-up)": right[1],
                        **{cause: pair[0] for cause, pair in wrong.items()},
                        **against_readings[kind]})

    judge_together(partial(per_run, "mse_vision", vision, fused, "fused", {}, "vision",
                           mse_vision),
                   partial(per_run, "mse_fused", fused, vision, "vision-only", sigma_causes,
                           "fused", mse_fused))
    first, second = vision[0], fused[0]
    mistakes = {
        **interval_mistakes(first, second, "the vision-only MSE", "the fused MSE",
                            readings=against_readings["pairs"]),
        "it is the difference over the whole trial; difference is the one after the first "
        "second": paired(vision[1], fused[1]),
        **{cause: paired(first, pair[0]) for cause, pair in sigma_causes.items()},
        "it is in % of the vision-only MSE; the task asks for the difference in cm²":
            metrics.mean_ci95(100 * (first - second) / first),
    }
    mistakes.update(unit_mistakes(first, second, "the vision-only MSE", "the fused MSE"))
    judge_interval("difference", difference, paired(first, second), INTERVAL_RTOL, unit="cm²",
                   mistakes=mistakes, what="the paired difference vision-only − fused MSE "
                   "after the first second recomputed from the task's inputs")
    passed(f"both filters' per-run MSEs match the pack's engine to "
           f"{tolerance_text(MSE_RTOL)} relative, and the paired difference vision-only − "
           f"fused after the first second over {runs} runs (mean and 95 % interval) to "
           f"{tolerance_text(INTERVAL_RTOL)} relative")
