"""Checks of notebook 03, question (c): vision fused with proprioception.

- :func:`check_fusion` (Task 1): C and R for the two senses;
- :func:`check_fusion_trial` (Task 2): the student's filter run on one trial both ways,
  its estimated positions and their MSEs, recomputed from the task's draw with the engine;
- :func:`check_fusion_difference` (Task 3): the per-run MSEs over the Monte Carlo runs and
  the paired vision-only − fused difference after the first second, recomputed with
  :func:`lqe_helpers.experiments.track`.

The checks of the Going further tasks are in :mod:`lqe_helpers.checks.fusion_further`.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from .. import experiments, metrics
from ..scenario import DEFAULT
from .initial_covariance import P0_NAMES, QUESTION_P0
from .judging import (
    CM_PER_M,
    burn_in_slips,
    judge,
    judge_interval,
    mse_mistakes,
)
from .machinery import (
    FUNCTION_RTOL,
    INTERVAL_RTOL,
    MATRIX_RTOL,
    MSE_RTOL,
    CheckFailed,
    argument_array,
    passed,
    positive_number,
    tolerance_text,
)
from .paired_mistakes import interval_mistakes, unit_mistakes
from .readings_slips import monte_carlo_readings_slips, sensor_readings
from .remembering import remembered
from .shared_runs import vision_runs

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback

#: The fused filter's sensors, in the column order of its readings, C and R.
FUSED = ("vision", "proprioception")


def judge_together(*judgements: Callable[[], object]) -> None:
    """Run every judgement; if any fails, fail once, naming each value that failed.

    A slip made in two values (column 1 of both filters' estimates) is named for both at
    once, not one at a time. Shared with :mod:`~lqe_helpers.checks.noisier_proprioception`.

    Raises
    ------
    CheckFailed
        One line: the failures' messages in the order of ``judgements``.
    """
    failures = []
    for judgement in judgements:
        try:
            judgement()
        except CheckFailed as failure:
            failures.append(str(failure).rstrip("."))
    if failures:
        raise CheckFailed(". Also, ".join(failures))


def check_fusion(C: np.ndarray, R: np.ndarray, sigma_v: float, sigma_p: float) -> None:
    """Check C and R for vision and proprioception (Tutorial eqs. (3), (6)).

    Expected: ``C = [[1, 0, 0], [1, 0, 0]]`` (both senses read the position of the state
    [p, v, a]; vision is row 0, proprioception row 1) and ``R = diag(σ_v², σ_p²)`` in
    cm², each within :data:`MATRIX_RTOL`.

    Parameters
    ----------
    C : array_like, shape (2, 3)
        The student's observation matrix.
    R : array_like, shape (2, 2)
        The student's sensor noise covariance (cm²).
    sigma_v, sigma_p : float
        The noise standard deviations (cm) the student used, > 0.

    Raises
    ------
    CheckFailed
        With the mistake named: wrong shape, transposed C, a row not reading position,
        standard deviations instead of variances, off-diagonal terms, swapped rows, ...
    """
    sigma_v = positive_number(sigma_v, "sigma_v", "cm")
    sigma_p = positive_number(sigma_p, "sigma_p", "cm")
    C = argument_array(C, "C", "the observation matrix, an array of shape (2, 3)")
    R = argument_array(R, "R", "the noise covariance (cm²), an array of shape (2, 2)")
    _check_fusion_C(C)
    judge_noise_matrix(R, sigma_v, sigma_p)
    passed(f"C (2 × 3) reads the position p for vision and for proprioception, and "
           f"R = diag(σ_v², σ_p²) = diag({sigma_v**2:g}, {sigma_p**2:g}) cm² (2 × 2)")


def _check_fusion_C(C: np.ndarray) -> None:
    position = np.array([1.0, 0.0, 0.0])
    if C.shape == (3, 2):
        raise CheckFailed(
            "C has shape (3, 2): it is transposed. C has one row per sensor (vision, "
            "proprioception) and one column per state (p, v, a): shape (2, 3)")
    if C.shape in ((3,), (1, 3)):
        raise CheckFailed(
            f"C has shape {C.shape}: one row only. With two senses C needs one row per "
            f"sensor, vision and proprioception: shape (2, 3)")
    if C.shape != (2, 3):
        raise CheckFailed(
            f"C must have shape (2, 3): one row per sensor (vision, proprioception), one "
            f"column per state (p, v, a); got shape {C.shape}")
    labels = ("vision", "proprioception")
    for row, label in enumerate(labels):
        if np.allclose(C[row], position, rtol=0, atol=MATRIX_RTOL):
            continue
        read = [s for s, c in zip(("position p", "velocity v", "acceleration a"), C[row],
                                  strict=True) if c != 0]
        reads = " and ".join(read) if read else "nothing (all zeros)"
        raise CheckFailed(
            f"C's row {row} ({label}) is {C[row].tolist()}, which reads {reads}. "
            f"{label.capitalize()} measures the position only: its row must pick out p "
            f"from the state [p, v, a], with weight 1")


def judge_noise_matrix(R: np.ndarray, sigma_v: float, sigma_p: float) -> None:
    """Judge the student's R (2, 2) (cm²) against diag(σ_v², σ_p²) (Tutorial eq. (6)).

    Within :data:`MATRIX_RTOL` relative; else CheckFailed naming the mistake: a vector,
    the wrong shape, off-diagonal entries, the σ for the σ² (both or one), the rows
    swapped, σ⁴.
    Shared with :mod:`~lqe_helpers.checks.noisier_proprioception`.
    """
    sigmas = np.array([sigma_v, sigma_p])
    variances = sigmas**2
    if R.ndim < 2 and R.size == 2:
        raise CheckFailed(
            f"R has shape {R.shape}: a vector. R is a 2 × 2 covariance matrix with the "
            f"two variances on its diagonal")
    if R.shape != (2, 2):
        raise CheckFailed(
            f"R must have shape (2, 2), one row and column per sensor, got shape {R.shape}")

    def same(a: np.ndarray, b: np.ndarray) -> bool:
        return bool(np.allclose(a, b, rtol=MATRIX_RTOL, atol=0.0))

    expected = np.diag(variances)
    if same(R, expected):
        return
    off = R[0, 1] != 0 or R[1, 0] != 0
    diag = np.diag(R)
    if off:
        raise CheckFailed(
            f"R has off-diagonal entries ({R[0, 1]:g}, {R[1, 0]:g}). Vision and "
            f"proprioception are independent (Tutorial eq. (6)): their covariances, the "
            f"off-diagonal entries, are 0")
    if same(diag, sigmas):
        raise CheckFailed(
            f"R holds the standard deviations σ_v = {sigma_v:g} and σ_p = {sigma_p:g} cm. "
            f"R is a covariance: its diagonal holds variances, in cm²")
    for entry, label in enumerate(FUSED):
        mixed = variances.copy()
        mixed[entry] = sigmas[entry]
        if same(diag, mixed):
            raise CheckFailed(
                f"R's {label} entry holds σ = {sigmas[entry]:g} cm, not its variance σ² "
                f"(cm²): R is a covariance, its diagonal holds variances")
    if same(diag, variances[::-1]):
        raise CheckFailed(
            "R's rows are swapped: row 0 must be vision's variance and row 1 "
            "proprioception's, in the same order as the rows of C")
    if same(diag, sigmas**4):
        raise CheckFailed("R's diagonal holds σ⁴: the variances σ² were squared again")
    raise CheckFailed(
        f"R's diagonal is {diag.tolist()} cm²; for σ_v = {sigma_v:g} cm and σ_p = "
        f"{sigma_p:g} cm it must hold their variances")


# ------------------------------------------------------------------------------------------
# Task 2: one trial, filtered both ways
# ------------------------------------------------------------------------------------------

#: The vision-only run given vision's readings y[:, :1] but both senses' C and R: a loop of
#: eq. (5) then compares the one reading with both rows of C A ẑ (numpy broadcasts it), which
#: is the fused filter fed vision's reading twice.
VISION_WITH_BOTH_SENSES = ("the vision-only run kept both senses' C and R: with vision's "
                           "readings y[:, :1] it needs C[:1] (1, 3) and R[:1, :1] (1, 1) too")


def engine_positions(readings: np.ndarray, sigmas: list[float], column: int = 0,
                     p0_variance: float | None = None) -> np.ndarray:
    """Column ``column`` of the engine's estimates on ``readings`` (n, m), R = diag(σ²).

    The model is the tasks' (:func:`lqe_helpers.experiments.filter_model` of the first m
    senses): DEFAULT's A, Q, z0 and P0 (or ``p0_variance`` · I), C with one position row
    per sense. Shared with :mod:`~lqe_helpers.checks.fusion_further`.
    """
    senses = FUSED[:readings.shape[-1]]
    return experiments.filter_model(DEFAULT, senses, sigmas=sigmas,
                                    p0_variance=p0_variance).filter(
        readings).estimates[..., column]


def setup_slips(y: np.ndarray, sigmas: list[float]) -> dict[str, np.ndarray]:
    """Positions (n,) (cm) of the filter on ``y`` (n, m) with a slip in the set-up's inputs.

    P0 of the tutorial's uncertain start (notebook 02's diag(1e5)) where the question's
    diag(1) belongs, and the readings in metres (divided by :data:`judging.CM_PER_M`).
    Shared with :mod:`~lqe_helpers.checks.noisier_proprioception`.
    """
    return {
        f"P0 is {P0_NAMES[1]}, notebook 02's uncertain start: this question starts from "
        f"P0 = {P0_NAMES[0]}, the set-up cell's P0":
            engine_positions(y, sigmas, p0_variance=QUESTION_P0[1]),
        "the readings are in metres (y divided by 100) while R, Q and the truth are in cm: "
        "give my_filter the readings y as they are, in cm":
            engine_positions(y / CM_PER_M, sigmas),
    }


@remembered
def _trial() -> dict[str, object]:
    """Task 2's right positions (n,) and MSEs (cm²), and the likely mistakes of each."""
    tracking = experiments.track(DEFAULT, FUSED)
    y = tracking.measurements
    truth, burn, dt = DEFAULT.truth[:, 0], DEFAULT.burn_in_steps, DEFAULT.dt
    sigma_v, sigma_p = DEFAULT.sigma_v, DEFAULT.sigma_p
    fused = tracking.positions
    vision = engine_positions(y[:, :1], [sigma_v])
    root = {"vision": [np.sqrt(sigma_v)], "fused": [np.sqrt(sigma_v), np.sqrt(sigma_p)]}
    velocity = "it is column 1 of the estimates, the velocity (cm/s): the position is column 0"
    sigma_for_variance = ("R holds σ (cm) where the variance σ² (cm²) belongs, so the filter "
                          "weighs the readings wrongly")
    positions = {"vision": vision, "fused": fused}
    mistakes = {
        "vision": {
            "it is the fused filter's estimate: vision_positions comes from the filter given "
            "vision alone (column 0 of y, row 0 of C, the top-left entry of R)": fused,
            "it is the filter run on proprioception's readings (column 1 of y): vision's "
            "readings are column 0": engine_positions(y[:, 1:], [sigma_p]),
            velocity: engine_positions(y[:, :1], [sigma_v], 1),
            sigma_for_variance: engine_positions(y[:, :1], root["vision"]),
            "these are vision's readings, not the filter's estimate": y[:, 0],
            VISION_WITH_BOTH_SENSES: engine_positions(np.repeat(y[:, :1], 2, axis=1),
                                                      [sigma_v, sigma_p]),
            **setup_slips(y[:, :1], [sigma_v]),
        },
        "fused": {
            "it is the vision-only filter's estimate: fused_positions comes from the filter "
            "given both senses (all of y, C and R)": vision,
            "the two readings were averaged and filtered as one sense with vision's R: the "
            "filter of both senses needs no averaging; give it both columns of the readings "
            "with your C and R":
                engine_positions(y.mean(axis=1, keepdims=True), [sigma_v]),
            velocity: engine_positions(y, [sigma_v, sigma_p], 1),
            sigma_for_variance: engine_positions(y, root["fused"]),
            "these are vision's readings, not the filter's estimate": y[:, 0],
            **setup_slips(y, [sigma_v, sigma_p]),
        },
    }

    def mse(x: np.ndarray) -> float:
        return float(metrics.mse(x, truth, burn))

    mse_wrong = {}
    for kind, other in (("vision", "fused"), ("fused", "vision")):
        mse_wrong[kind] = {
            f"it is the MSE of the {'fused' if kind == 'vision' else 'vision-only'} "
            f"filter's estimate": mse(positions[other]),
            "it is the MSE of vision's raw readings, not of the filter's estimate":
                mse(y[:, 0]),
            **{f"it comes from a wrong estimate: {cause}": mse(wrong)
               for cause, wrong in mistakes[kind].items() if wrong is not positions[other]},
            **mse_mistakes(positions[kind], truth, burn, dt, readings=sensor_readings(y)),
        }
    return {"positions": positions, "mistakes": mistakes,
            "mse": {kind: mse(value) for kind, value in positions.items()},
            "mse_mistakes": mse_wrong}


def position_array(value: object, name: str, n: int) -> np.ndarray:
    """The student's positions (n,) (cm) as an array, or CheckFailed naming a wrong shape.

    Shared with :mod:`~lqe_helpers.checks.noisier_proprioception`.
    """
    array = argument_array(value, name, f"the estimated positions (cm), an array of shape "
                                        f"({n},)")
    if array.ndim == 2 and array.shape[0] == n:
        raise CheckFailed(
            f"{name} has shape {array.shape}: it holds {array.shape[1]} column(s) of "
            f"estimates. Keep only column 0, the position, as a flat array of shape ({n},)")
    return array


def check_fusion_trial(vision_positions: np.ndarray, fused_positions: np.ndarray,
                       mse_vision_trial: float, mse_fused_trial: float) -> None:
    """Check Task 2: one trial filtered with vision alone and with both senses, and its MSEs.

    Recomputed from the task's own inputs before looking at the student's: the scenario's
    trial of both senses (:func:`lqe_helpers.experiments.track`, σ_v = σ_p = 1.5 cm),
    filtered by the pack's engine with both senses (C with two position rows,
    ``R = diag(σ_v², σ_p²)``) and with vision alone (column 0, ``R = [[σ_v²]]``), from
    ``DEFAULT.z0`` and ``P0 = diag(1, 1, 1)``. The positions (cm) must agree within
    :data:`FUNCTION_RTOL` of their largest value, each MSE (cm²) after the first
    ``DEFAULT.burn_in_steps`` samples within :data:`MSE_RTOL` relative.

    Parameters
    ----------
    vision_positions, fused_positions : array_like, shape (n,)
        The student's estimated positions (cm): column 0 of their filter's estimates.
    mse_vision_trial, mse_fused_trial : float
        The student's MSEs (cm²) after the burn-in.

    Raises
    ------
    CheckFailed
        Naming the value and the likely cause: the two filters swapped, proprioception's
        column for vision's, the velocity column, σ where σ² belongs, the readings
        averaged, the raw readings, the whole trial, the burn-in in seconds, the RMSE, ...
    """
    right = _trial()
    n = DEFAULT.n_steps

    def positions(kind: str, name: str, value: object) -> None:
        judge(name, position_array(value, name, n), right["positions"][kind],
              FUNCTION_RTOL, unit="cm", mistakes=right["mistakes"][kind],
              what=f"the {'vision-only' if kind == 'vision' else 'fused'} filter's positions "
                   f"recomputed from the task's trial")

    def mse(kind: str, name: str, value: object) -> None:
        judge(name, value, right["mse"][kind], MSE_RTOL, unit="cm²",
              mistakes=right["mse_mistakes"][kind],
              what=f"the {'vision-only' if kind == 'vision' else 'fused'} MSE recomputed "
                   f"from the task's trial")

    judge_together(functools.partial(positions, "vision", "vision_positions", vision_positions),
                   functools.partial(positions, "fused", "fused_positions", fused_positions))
    judge_together(functools.partial(mse, "vision", "mse_vision_trial", mse_vision_trial),
                   functools.partial(mse, "fused", "mse_fused_trial", mse_fused_trial))
    passed(f"both filters' positions match the pack's engine on the task's trial to "
           f"{tolerance_text(FUNCTION_RTOL)} of the largest, and both MSEs (after the first "
           f"{DEFAULT.burn_in_steps} samples) to {tolerance_text(MSE_RTOL)} relative")


# ------------------------------------------------------------------------------------------
# Task 3: many trials, compared pair by pair
# ------------------------------------------------------------------------------------------

@remembered
def monte_carlo_mses() -> dict[str, np.ndarray]:
    """Task 3's runs: positions (runs, n) (cm) and per-run MSEs (runs,) (cm²), read-only.

    Keys ``vision`` and ``fused`` (positions), ``<filter>_after`` (after the burn-in),
    ``<filter>_whole``, ``raw`` (vision's readings' MSE), ``<filter>_readings`` (its runs'
    readings, (runs, n, m), cm), ``y`` (Task 2's one trial, (n, 2), cm). Shared with
    :mod:`~lqe_helpers.checks.fusion_further`.
    """
    runs, truth, burn = DEFAULT.mc_runs, DEFAULT.truth[:, 0], DEFAULT.burn_in_steps
    vision = vision_runs()
    fused = experiments.track(DEFAULT, FUSED, runs=runs)
    values = {"vision": vision.positions, "fused": fused.positions,
              "raw": vision.measurement_mse("vision"),
              "vision_readings": vision.measurements, "fused_readings": fused.measurements,
              "y": experiments.readings(DEFAULT, FUSED)}
    for kind in ("vision", "fused"):
        values[f"{kind}_after"] = metrics.mse(values[kind], truth, burn)
        values[f"{kind}_whole"] = metrics.mse(values[kind], truth)
        if burn * DEFAULT.dt >= 1:  # the burn-in given in seconds: int(1 s) samples
            values[f"{kind}_seconds"] = metrics.mse(values[kind], truth,
                                                    int(burn * DEFAULT.dt))
    for array in values.values():
        array.setflags(write=False)
    return values


def _per_run(value: object, name: str, runs: int) -> np.ndarray:
    """The student's per-run MSEs as an array, or CheckFailed if it is one number."""
    array = argument_array(value, name, f"one MSE per run (cm²), an array of shape ({runs},)")
    if array.size == 1:
        raise CheckFailed(
            f"{name} is one number; the task asks for one MSE per run, shape ({runs},): "
            f"metrics.mse of positions of shape (runs, n) gives them")
    return array


def check_fusion_difference(mse_vision: np.ndarray, mse_fused: np.ndarray,
                            difference: metrics.Interval) -> None:
    """Check Task 3: per-run MSEs of both filters and their paired difference.

    Recomputed from the task's inputs before looking at the student's:
    ``DEFAULT.mc_runs`` runs of vision alone and of both senses
    (:func:`lqe_helpers.experiments.track`; run r of both on the same visual noise), the
    per-run MSEs after the first ``DEFAULT.burn_in_steps`` samples (each within
    :data:`MSE_RTOL` relative), and ``metrics.mean_ci95`` of the per-run differences
    vision only − fused (mean and ends within :data:`INTERVAL_RTOL` of the interval's
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
        Naming the value and the likely cause: the two filters swapped, the whole trial,
        the sign reversed, an unpaired interval, a ratio or a percentage, the standard
        deviation for the standard error, one run, ...
    """
    values = monte_carlo_mses()
    runs, truth, burn = DEFAULT.mc_runs, DEFAULT.truth[:, 0], DEFAULT.burn_in_steps
    against_readings = monte_carlo_readings_slips(
        {kind: values[kind] for kind in ("vision", "fused")},
        {kind: values[f"{kind}_readings"] for kind in ("vision", "fused")}, values["y"], burn)

    def per_run(kind: str, other: str, name: str, value: object) -> None:
        label = "vision-only" if kind == "vision" else "fused"
        judge(name, _per_run(value, name, runs), values[f"{kind}_after"], MSE_RTOL,
              unit="cm²", what=f"the {label} MSEs recomputed from the task's runs",
              mistakes={
                  f"these are the {'fused' if kind == 'vision' else 'vision-only'} filter's "
                  f"MSEs": values[f"{other}_after"],
                  "these are the MSEs of vision's raw readings, not of the filter's "
                  "estimates": values["raw"],
                  **mse_mistakes(values[kind], truth, burn, DEFAULT.dt),
                  **against_readings[kind]})

    judge_together(functools.partial(per_run, "vision", "fused", "mse_vision", mse_vision),
                   functools.partial(per_run, "fused", "vision", "mse_fused", mse_fused))
    vision, fused = values["vision_after"], values["fused_after"]
    mistakes = {
        **interval_mistakes(vision, fused, "the vision-only MSE", "the fused MSE",
                            readings=against_readings["pairs"]),
        "it is the difference over the whole trial; difference is the one after the first "
        "second (from burn_in on)":
            metrics.mean_ci95(values["vision_whole"] - values["fused_whole"]),
        "it is the interval of the ratio vision only / fused; the task asks for the paired "
        "difference vision only − fused (cm²)": metrics.mean_ci95(vision / fused),
        "it is the relative difference in % of the vision-only MSE; the task asks for the "
        "difference itself (cm²)": metrics.mean_ci95(100 * (vision - fused) / vision),
    }
    for cause, start in burn_in_slips(burn, truth.size).items():
        mistakes[cause] = metrics.mean_ci95(metrics.mse(values["vision"], truth, start)
                                            - metrics.mse(values["fused"], truth, start))
    if "vision_seconds" in values:
        mistakes[f"it leaves out the first {burn * DEFAULT.dt:g} sample(s): the burn-in is "
                 f"{burn * DEFAULT.dt:g} s, which is {burn} samples"] = (
            metrics.mean_ci95(values["vision_seconds"] - values["fused_seconds"]))
    mistakes.update(unit_mistakes(vision, fused, "the vision-only MSE", "the fused MSE"))
    judge_interval("difference", difference, metrics.mean_ci95(vision - fused), INTERVAL_RTOL,
                   unit="cm²", mistakes=mistakes,
                   what="the paired difference vision only − fused after the first second, "
                        "recomputed from the task's runs",
                   runs_of=(vision, fused, "Subtract mse_fused from mse_vision as they come "
                                           "(run r from run r, both from the same draws)"))
    passed(f"per-run MSEs of both filters over {runs} runs match the pack's engine to "
           f"{tolerance_text(MSE_RTOL)} relative, and the paired difference vision only − "
           f"fused after the first second (mean and 95 % interval) to "
           f"{tolerance_text(INTERVAL_RTOL)}")
