"""Checks of notebook 05's Going further: the worked answers pass, realistic wrong ones fail.

Each task is written here as a student writes it (the notebook's worked code, with
``reference_loops.lqe_filter`` as the student's ``my_filter``), with one slip at a time;
the checks must name the slip. The wrong answers are made the student's way, not by the
mistakes the checks compute to recognise them.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import reference_loops as reference
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, experiments, metrics, prediction, simulation
from lqe_helpers.scenario import DEFAULT

TRUTH = DEFAULT.truth[:, 0]
TIMES = DEFAULT.times
BURN = DEFAULT.burn_in_steps
STEPS = DEFAULT.delay_steps(DEFAULT.delay)
SKIP = max(BURN, STEPS)
VISION = experiments.filter_model(DEFAULT)
MODEL = tuple(getattr(VISION, name) for name in ("A", "C", "Q", "R", "z0", "P0"))


def my_filter(y: np.ndarray) -> np.ndarray:
    """The student's filter of notebook 01 on readings y (n, 1) with the model `vision`."""
    return reference.lqe_filter(y, *MODEL)


@functools.cache
def core() -> dict[str, object]:
    """What the core path left in the notebook: Task 3's runs and their MSEs."""
    tracking_mc = experiments.track(DEFAULT, runs=DEFAULT.mc_runs)
    batch = experiments.delay_and_compensate(tracking_mc, DEFAULT.delay)
    return {"tracking_mc": tracking_mc, "mse_delayed": batch.mse("delayed"),
            "mse_now": tracking_mc.mse()}


# ------------------------------------------------------------------------------------------
# Part 1: check_late_eye
# ------------------------------------------------------------------------------------------

def late_eye_task(slip: str = "") -> tuple[float, float, float, float]:
    """Part 1 as a student writes it, with one ``slip``."""
    c = core()
    late_eye = TRUTH if slip == "eye not late" else simulation.delay_signal(TRUTH, STEPS,
                                                                            axis=-1)
    mse_late_eye = float(metrics.mse(late_eye, TRUTH, STEPS if slip == "skip only δ" else SKIP))
    readings = TRUTH[:, None]
    if slip == "noisy readings":
        readings = simulation.measure(TRUTH, DEFAULT.unit_noise(sensors=("vision",)),
                                      [DEFAULT.sigma_v])
    clean = my_filter(readings)[:, 0]
    start = 0 if slip == "lead over the whole trial" else BURN
    lead = float(metrics.fit_sinusoid(TIMES[start:], clean[start:], DEFAULT.frequency).lead)
    if slip == "lead in ms":
        lead *= 1000
    mse_clean_delayed = float(metrics.mse(simulation.delay_signal(clean, STEPS, axis=-1), TRUTH,
                                          SKIP))
    noise_part = float(c["mse_now"].mean() - metrics.mse(clean, TRUTH, BURN))
    if slip == "noise part reversed":
        noise_part = -noise_part
    elif slip == "circular noise part":
        noise_part = float(c["mse_delayed"].mean()) - mse_clean_delayed
    return mse_late_eye, lead, mse_clean_delayed, noise_part


def test_check_late_eye_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_late_eye, *late_eye_task())
    assert "noise-free filter's lead" in line and "1e-6 relative" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("eye not late", "mse_late_eye = 0 cm² is not right: the eye is not late"),
    ("skip only δ", "it leaves out only the first δ = 10 samples; leave out `skip` = 100"),
    ("noisy readings", "lead = 0.0"),
    ("noisy readings", "it is fitted to the filter run on the noisy readings"),
    ("lead over the whole trial", "it is fitted over the whole trial; leave out the burn-in"),
    ("lead in ms", "lead = 7.4"),
    ("lead in ms", "it is in ms; give the lead in seconds"),
    ("noise part reversed", "noise_part = -0.33"),
    ("noise part reversed", "its sign is reversed"),
    ("circular noise part", "it is taken from the delayed MSEs, which makes the comparison "
                            "circular"),
])
@pytest.mark.slow
def test_check_late_eye_names_the_cause(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_late_eye, *late_eye_task(slip))


# ------------------------------------------------------------------------------------------
# Part 2: check_delay_sweep
# ------------------------------------------------------------------------------------------

def sweep_task(slip: str = "") -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Part 2's sweep as a student writes it, with one ``slip``."""
    tracking_mc = core()["tracking_mc"]
    if slip == "one run":
        tracking_mc = experiments.track(DEFAULT)
    delays = np.arange(51) * DEFAULT.dt
    if slip == "arange stops early":
        delays = np.arange(0, 0.5, 0.01)
    sweep_mse = {"delayed": [], "predicted": []}
    for d in delays:
        shifted = experiments.delay_and_compensate(
            tracking_mc, DEFAULT.delay if slip == "same delay" else d)
        for which, values in sweep_mse.items():
            per_run = shifted.mse(which)
            values.append(per_run.mean() if slip == "mean over runs" else per_run)
    sweep_mse = {which: np.array(values) for which, values in sweep_mse.items()}
    if slip == "in samples":
        delays = np.arange(51)
    elif slip == "transposed":
        sweep_mse = {which: values.T for which, values in sweep_mse.items()}
    elif slip == "swapped keys":
        sweep_mse = {"delayed": sweep_mse["predicted"], "predicted": sweep_mse["delayed"]}
    elif slip == "other keys":
        sweep_mse = {"delayed": sweep_mse["delayed"], "compensated": sweep_mse["predicted"]}
    return delays, sweep_mse


@functools.cache
def worked_sweep() -> tuple[np.ndarray, dict[str, np.ndarray]]:
    return sweep_task()


@pytest.mark.slow
def test_check_delay_sweep_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_delay_sweep, *worked_sweep())
    assert "(51 delays × 300 runs)" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("arange stops early", "delays must hold the 51 delays 0, 0.01, …, 0.5 s (both ends "
                           "included), got shape (50,)"),
    ("in samples", "delays is not right: they are in samples"),
    ("one run", 'sweep_mse["delayed"] has one number per delay, shape (51,)'),
    ("mean over runs", "keep the MSE of each of tracking_mc's 300 runs"),
    ("transposed", 'sweep_mse["delayed"] has shape (300, 51): rows are runs'),
    ("swapped keys", 'sweep_mse["delayed"] is not right: it holds the predicted MSEs'),
    ("same delay", "every row is the MSE at the question's delay 0.1 s"),
    ("other keys", "sweep_mse must be a dict with the keys \"delayed\" and \"predicted\", got "
                   "keys ['compensated', 'delayed']"),
])
@pytest.mark.slow
def test_check_delay_sweep_names_the_cause(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_delay_sweep, *sweep_task(slip))


# ------------------------------------------------------------------------------------------
# Part 2: check_prediction_theory
# ------------------------------------------------------------------------------------------

def theory_task(slip: str = "") -> tuple[np.ndarray, ...]:
    """Part 2's theory as a student writes it, with one ``slip``."""
    steady = core()["tracking_mc"].model.steady_state()
    P_hat = {"prediction covariance": steady.covariance,
             "P0": DEFAULT.P0}.get(slip, steady.estimate_covariance)
    theory_steps = DEFAULT.delay_steps(0.5 if slip == "only 0.5 s" else 3.0)
    no_noise = np.zeros((3, 3))
    extrapolated_q = DEFAULT.Q if slip == "forgot Q = 0" else no_noise

    def pp(P, Q):
        full = prediction.propagate_covariance(P, DEFAULT.A, Q, theory_steps)
        return full if slip == "whole matrices" else full[:, 0, 0]

    theory, extrapolated, jerks = (pp(P_hat, DEFAULT.Q), pp(P_hat, extrapolated_q),
                                   pp(no_noise, DEFAULT.Q))
    if slip == "standard deviation":
        theory, extrapolated, jerks = np.sqrt(theory), np.sqrt(extrapolated), np.sqrt(jerks)
    return P_hat, theory, extrapolated, jerks


def test_check_prediction_theory_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_prediction_theory, *theory_task())
    assert "over 0–3 s" in line and "1e-9 relative" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("prediction covariance", "it is the covariance of the one-step prediction"),
    ("P0", "it is P0, the covariance the filter starts from"),
    ("only 0.5 s", "theory has 51 entries: follow the theory over δ = 0 … 300 (3 s)"),
    ("forgot Q = 0", "extrapolated is not right: it holds the whole theory (from P̂ with Q)"),
    ("whole matrices", "theory holds whole covariance matrices, shape (301, 3, 3)"),
    ("standard deviation", "theory is not right: it is the standard deviation (cm)"),
])
def test_check_prediction_theory_names_the_cause(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_prediction_theory, *theory_task(slip))


# ------------------------------------------------------------------------------------------
# Part 2: check_compensation_regimes
# ------------------------------------------------------------------------------------------

def regimes_task(slip: str = "") -> tuple[float, float, float]:
    """Part 2's regimes as a student writes it, with one ``slip``."""
    delays, sweep_mse = worked_sweep()
    paired = [metrics.mean_ci95(q - p) for p, q in zip(sweep_mse["predicted"],
                                                        sweep_mse["delayed"], strict=True)]
    share = [metrics.Interval(0.0, 0.0, 0.0, DEFAULT.mc_runs)]
    share += [metrics.mean_ci95(1 - p / q) for p, q in zip(sweep_mse["predicted"][1:],
                                                           sweep_mse["delayed"][1:], strict=True)]
    helps = np.array([iv.low > 0 for iv in paired])
    if slip == "hurts for helps":
        helps = np.array([iv.high < 0 for iv in paired])
    help_from, help_to = delays[helps].min(), delays[helps].max()
    scores = [iv.mean for iv in (paired if slip == "largest difference" else share)]
    best = int(np.argmax(scores))
    best_delay = delays[best]
    if slip == "indices":
        help_from, help_to, best_delay = (int(np.argmax(helps)),
                                          int(len(helps) - 1 - np.argmax(helps[::-1])), best)
    elif slip == "the share itself":
        best_delay = share[best].mean
    return help_from, help_to, best_delay


@pytest.mark.slow
def test_check_compensation_regimes_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_compensation_regimes, *regimes_task())
    assert "paired 95 % interval above zero" in line
    assert "0.04" not in line and "0.14" not in line          # the ✓ line gives nothing away


@pytest.mark.parametrize(("slip", "phrase"), [
    ("hurts for helps", "help_from = 0.01 s is not right: it is where compensation hurts"),
    ("indices", "help_from = 4 s is not right: it is in samples"),
    ("largest difference", "best_delay = 0.27 s is not right: it is where the paired "
                           "difference is largest"),
    ("the share itself", "it is the largest share itself; give the delay (s)"),
])
def test_check_compensation_regimes_names_the_cause(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_compensation_regimes, *regimes_task(slip))


# ------------------------------------------------------------------------------------------
# Part 2: check_error_sources
# ------------------------------------------------------------------------------------------

def sources_task(slip: str = "") -> tuple[float, float, float]:
    """Part 2's sources as a student writes it, with one ``slip``."""
    _, theory, extrapolated, jerks = theory_task()
    theory_delays = np.arange(theory.size) * DEFAULT.dt
    positive = theory_delays > 0
    if slip == "only the simulated delays":
        positive &= theory_delays <= 0.5 + 1e-9
    crossing = extrapolated > jerks if slip == "comparison reversed" else jerks > extrapolated
    takeover = theory_delays[np.argmax(crossing)]
    if slip == "index":
        takeover = int(np.argmax(jerks > extrapolated))
    if slip == "standard deviations":
        jerks, extrapolated = np.sqrt(jerks), np.sqrt(extrapolated)
    slope_jerks = metrics.power_law_exponent(theory_delays[positive], jerks[positive])
    slope_old = metrics.power_law_exponent(theory_delays[positive], extrapolated[positive])
    if slip == "swapped":
        slope_jerks, slope_old = slope_old, slope_jerks
    return takeover, slope_jerks, slope_old


def test_check_error_sources_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_error_sources, *sources_task())
    assert "log–log slopes of both parts (0.01–3 s)" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("index", "takeover = 135 s is not right: it is in samples"),
    ("comparison reversed", "takeover = 0 s is not right: it is the first delay of all"),
    ("swapped", "slope_jerks = 3.00"),
    ("swapped", "it is the slope of old, the other part"),
    ("standard deviations", "it is the slope of the standard deviation"),
    ("only the simulated delays", "it is fitted over the simulated delays only"),
])
def test_check_error_sources_names_the_cause(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_error_sources, *sources_task(slip))


# ------------------------------------------------------------------------------------------
# Part 3: check_short_delays
# ------------------------------------------------------------------------------------------

def short_task(slip: str = "") -> tuple[float, metrics.Interval, float]:
    """Part 3 as a student writes it, with one ``slip``."""
    _, sweep_mse = worked_sweep()
    mse_now = core()["mse_now"]
    P_hat = theory_task()[0]
    lead = late_eye_task()[1]
    column = 0 if slip == "position column" else 1
    mean_v2 = float(np.mean(DEFAULT.truth[BURN:, column] ** 2))
    if slip == "mean, then squared":
        mean_v2 = float(np.mean(DEFAULT.truth[BURN:, 1])) ** 2
    elif slip == "rms speed":
        mean_v2 = float(np.sqrt(mean_v2))
    row = STEPS if slip == "at the question's delay" else 1
    which = "predicted" if slip == "compensated" else "delayed"
    difference = sweep_mse[which][row] - mse_now
    shortest = metrics.mean_ci95(-difference if slip == "reversed" else difference)
    L = {"lead in ms": 1000 * lead, "no lead": 0.0}.get(slip, lead)
    v2 = float(np.mean(DEFAULT.truth[BURN:, 1] ** 2))
    break_even = 2 * (P_hat[0, 1] + L * v2) / (v2 - P_hat[1, 1] - P_hat[0, 2])
    return mean_v2, shortest, break_even


def test_check_short_delays_passes_the_worked_answer(capsys) -> None:
    line = assert_passes(capsys, checks.check_short_delays, *short_task())
    assert "break-even delay match" in line


@pytest.mark.parametrize(("slip", "phrase"), [
    ("mean, then squared", "mean_v2 = "),
    ("mean, then squared", "it is the square of the mean velocity, near 0"),
    ("position column", "it is the mean squared position (column 0 of the truth)"),
    ("rms speed", "it is the root mean squared speed (cm/s)"),
    ("reversed", "shortest is not right: the sign is reversed"),
    ("compensated", "it is the compensated estimate's"),
    ("at the question's delay", "it is at the question's delay, 0.1 s"),
    ("lead in ms", "break_even = "),
    ("lead in ms", "the lead is in ms; give L in seconds"),
    ("no lead", "the lead L is left out"),
])
def test_check_short_delays_names_the_cause(slip: str, phrase: str) -> None:
    assert_fails(phrase, checks.check_short_delays, *short_task(slip))


@pytest.mark.slow
def test_the_going_further_checks_judge_against_another_draw() -> None:
    """Numbers from the same code on another noise draw agree with each other, not the task."""
    import dataclasses

    other = dataclasses.replace(DEFAULT, seed=DEFAULT.seed + 1)
    tracking = experiments.track(other, runs=DEFAULT.mc_runs)
    delays = np.arange(51) * DEFAULT.dt
    sweep_mse = {which: np.array([experiments.delay_and_compensate(tracking, d).mse(which)
                                  for d in delays]) for which in ("delayed", "predicted")}
    assert_fails('sweep_mse["delayed"] does not match the per-run MSEs recomputed',
                 checks.check_delay_sweep, delays, sweep_mse)
    mean_v2, _, break_even = short_task()
    shortest = metrics.mean_ci95(sweep_mse["delayed"][1] - tracking.mse())
    assert_fails("shortest (mean", checks.check_short_delays, mean_v2, shortest, break_even)
