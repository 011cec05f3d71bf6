"""Checks of notebook 02: the worked answer of every task passes, a student's slips fail.

Each wrong answer below is written as a student would write it (an edit of the worked
solution), and must fail with the message that names its cause. The worked answers are
computed here independently of the checks: the filter by the test oracle
``reference_loops`` (outside the package), the gains and convergence times by hand loops.
"""

from __future__ import annotations

import numpy as np
import pytest
import reference_loops as reference
from check_outcomes import assert_fails, assert_passes

from lqe_helpers import checks, experiments, metrics, model
from lqe_helpers.scenario import DEFAULT

BURN, DT, RUNS, N = DEFAULT.burn_in_steps, DEFAULT.dt, DEFAULT.mc_runs, DEFAULT.n_steps
TRUTH = DEFAULT.truth
P0_SMALL, P0_LARGE = np.diag([1.0, 1.0, 1.0]), np.diag([1e5, 1e5, 1e5])


def hand_convergence_time(curve: np.ndarray, dt: float, factor: float = 2.0) -> float:
    """The pack's definition, as a plain loop: after the last sample above 2 × the level."""
    steady = sum(curve[len(curve) // 2:]) / (len(curve) - len(curve) // 2)
    last_outside = -1
    for index, value in enumerate(curve):
        if value > factor * steady:
            last_outside = index
    return (last_outside + 1) * dt


# ------------------------------------------------------------------------------------------
# check_initial_covariance (one matrix)
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("variance", [1.0, 1e5])
def test_check_initial_covariance_passes_the_worked_solution(capsys, variance) -> None:
    line = assert_passes(capsys, checks.check_initial_covariance,
                         model.diagonal_covariance(variance), variance)
    assert line == f"✓ P0 = {variance:g} · I (3 × 3, diagonal) cm²"


@pytest.mark.parametrize(("P0", "phrase"), [
    (np.sqrt(1e5) * np.eye(3), "a standard deviation"),
    (1e5, "P0 is a single number"),
    (np.full(3, 1e5), "P0 is a vector of 3 numbers"),
    (1e5 * np.eye(2), "P0 must be 3 × 3"),
    (np.full((3, 3), 1e5), "every entry of P0 is 100000"),
    (np.diag([1e5, 1e5, 1.0]), "P0's diagonal entries differ"),
    (1e10 * np.eye(3), "the variance was squared again"),
])
def test_check_initial_covariance_names_each_typical_mistake(P0, phrase: str) -> None:
    assert_fails(phrase, checks.check_initial_covariance, P0, 1e5)


@pytest.mark.parametrize(("P0", "variance", "phrase"), [
    (None, 1e5, "P0 must be the initial covariance, a 3 × 3 matrix (cm², cm²/s², cm²/s⁴), "
                "got None"),
    ([[1e5, 0, 0], [0, 1e5, 0], [0, 0, 1e5]], 1e5, "got a Python list, not a NumPy array"),
    (np.eye(3) * (1e5 + 0j), 1e5, "got complex numbers (dtype complex128)"),
    (np.eye(3) * 1e5, "1e5", "variance must be a number > 0 cm², got text ('1e5')"),
    (np.eye(3) * 1e5, -1.0, "variance must be a number > 0 cm², got -1"),
])
def test_check_initial_covariance_names_a_bad_argument(P0, variance, phrase) -> None:
    assert_fails(phrase, checks.check_initial_covariance, P0, variance)


# ------------------------------------------------------------------------------------------
# Task 1: check_start_of_trial, both P0 and the student's filter on one trial from each
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def trial() -> dict[str, np.ndarray]:
    """The task's inputs as notebook 02 gives them, and the worked estimates (oracle loop)."""
    vision = experiments.filter_model(DEFAULT)
    inputs = {"y": experiments.track(DEFAULT).measurements, "A": vision.A, "C": vision.C,
              "Q": vision.Q, "R": vision.R, "z0": vision.z0}
    return {**inputs, "small": reference.lqe_filter(**inputs, P0=P0_SMALL),
            "large": reference.lqe_filter(**inputs, P0=P0_LARGE)}


def run(trial: dict[str, np.ndarray], P0: np.ndarray, **changed: np.ndarray) -> np.ndarray:
    """The oracle filter on the task's inputs, with some of them changed."""
    inputs = {key: trial[key] for key in ("y", "A", "C", "Q", "R", "z0")} | changed
    return reference.lqe_filter(**inputs, P0=P0)


def test_check_start_of_trial_passes_the_worked_solution(capsys, trial) -> None:
    line = assert_passes(capsys, checks.check_start_of_trial, P0_SMALL, P0_LARGE,
                         trial["small"], trial["large"])
    assert "P0_small = 1 · I and P0_large = 100000 · I" in line
    assert "match the pack's engine on this trial" in line and "to 1e-9" in line


@pytest.mark.parametrize(("small", "large", "phrase"), [
    (P0_LARGE, P0_SMALL, "P0_small is diag(100000, 100000, 100000), the other start: "
                         "P0_small and P0_large are swapped"),
    (P0_LARGE, P0_LARGE, "P0_small is diag(100000, 100000, 100000), the other start. "
                         "P0_small is the confident start, diag(1, 1, 1)"),
    (P0_SMALL, np.sqrt(1e5) * np.eye(3), "P0_large's diagonal holds √100000 = 316.228, a "
                                         "standard deviation"),
    (P0_SMALL, np.full((3, 3), 1e5), "every entry of P0_large is 100000"),
    (np.ones(3), P0_LARGE, "P0_small is a vector of 3 numbers"),
    (1.0, P0_LARGE, "P0_small is a single number (1)"),
    (P0_SMALL, np.diag([1e-5, 1e-5, 1e-5]), "P0_large's diagonal holds 1e-05, expected the "
                                            "variance 100000"),
])
def test_check_start_of_trial_names_each_typical_mistake_in_p0(trial, small, large,
                                                                phrase) -> None:
    """A wrong P0 is named first, whatever the estimates (here those of that P0)."""
    estimates = [run(trial, np.asarray(P0) * np.eye(3)) if np.ndim(P0) < 2 else run(trial, P0)
                 for P0 in (small, large)]
    assert_fails(phrase, checks.check_start_of_trial, small, large, *estimates)


def test_check_start_of_trial_names_each_typical_mistake(trial) -> None:
    small, large = trial["small"], trial["large"]
    cases = [
        ("estimates_small is not right: it is the run from P0_large", (large, small)),
        ("estimates_large is not right: it is the run from P0_small", (small, small)),
        ("estimates_small holds one number per reading (the positions only?)",
         (small[:, 0], large[:, 0])),
        ("the filter started from the butterfly's true state",
         (run(trial, P0_SMALL, z0=TRUTH[0].copy()), large)),
        ("R holds σ_v (cm) where its variance σ_v² (cm²) belongs",
         (run(trial, P0_SMALL, R=np.array([[DEFAULT.sigma_v]])), large)),
        ("P0 held standard deviations (√p0) on its diagonal",
         (small, run(trial, np.sqrt(1e5) * np.eye(3)))),
        ("estimates_small has 1001 rows for 1000 readings",
         (np.vstack([trial["z0"], small]), large)),
        ("estimates_small is not right: the readings are in metres",
         (run(trial, P0_SMALL, y=trial["y"] / 100), run(trial, P0_LARGE, y=trial["y"] / 100))),
        ("estimates_large is not right: the readings are in metres",
         (small, run(trial, P0_LARGE, y=trial["y"] / 100))),
        # A filter broken since notebook 01 (Q left out of P): no usual mistake, a hint.
        ("if you changed my_filter since notebook 01, run its check there again",
         (run(trial, P0_SMALL, Q=np.zeros((3, 3))), large)),
    ]
    for phrase, answer in cases:
        assert_fails(phrase, checks.check_start_of_trial, P0_SMALL, P0_LARGE, *answer)


# ------------------------------------------------------------------------------------------
# Task 2: check_convergence_times
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def batch() -> experiments.Tracking:
    """Task 3's one call of the engine, as the worked solution makes it."""
    return experiments.track(DEFAULT, p0_variance=[1.0, 1e5], runs=RUNS)


@pytest.fixture(scope="module")
def squared(batch) -> np.ndarray:
    return (batch.positions - TRUTH[:, 0]) ** 2          # (runs, 2, n)


@pytest.fixture(scope="module")
def times(squared) -> tuple[float, float]:
    curves = squared.mean(axis=0)
    return hand_convergence_time(curves[0], DT), hand_convergence_time(curves[1], DT)


def test_check_convergence_times_passes_the_worked_solution(capsys, times) -> None:
    assert times[1] < 0.2 < 0.4 < times[0] < 1.0    # the question's contrast
    line = assert_passes(capsys, checks.check_convergence_times, *times)
    assert "over 300 runs" in line and "to 1e-9 s" in line


def test_check_convergence_times_names_the_slips_made_for_both(squared) -> None:
    """One slip in the code makes both times; named for both, not as another slip that
    happens to give one of them (issue 23: a band of 3 × was called the mean absolute error)."""
    curves = squared.mean(axis=0)
    band3 = [hand_convergence_time(curve, DT, 3.0) for curve in curves]
    message = assert_fails("are not right: the band is 3 × the steady level; the definition's "
                           "band is 2 ×", checks.check_convergence_times, *band3)
    assert "mean absolute error" not in message and message.startswith("t_small = ")
    median = [hand_convergence_time(np.median(squared[:, i], axis=0), DT) for i in range(2)]
    message = assert_fails("are not right: the curve is the median of the squared errors over "
                           "the runs", checks.check_convergence_times, *median)
    assert "one of these" not in message
    # For one P0 alone, a time two slips give names both, not only the first.
    message = assert_fails("t_small = 0.54 s is not right: two or more slips give this same "
                           "time", checks.check_convergence_times, band3[0],
                           hand_convergence_time(curves[1], DT))
    assert "mean absolute error" in message and "the band is 3 ×" in message


@pytest.mark.parametrize(("axis", "phrase"), [
    (2, "the mean was taken over axis 2, the samples (time), not over the runs"),
    (1, "the mean was taken over axis 1, the two P0, not over the runs")])
def test_check_convergence_times_names_the_mean_over_the_wrong_axis(squared, axis,
                                                                    phrase) -> None:
    """squared_error.mean(axis=2) got a guess between two other causes, .mean(axis=1) the
    wrong cause "a single run" (issue 23)."""
    mean_squared_error = squared.mean(axis=axis)     # (runs, 2) or (runs, n)
    curves = mean_squared_error.T if axis == 2 else mean_squared_error[:2]
    wrong = [hand_convergence_time(curve, DT) for curve in curves]
    message = assert_fails(f"t_small = {wrong[0]:g} s and t_large = {wrong[1]:g} s are not "
                           f"right: {phrase}", checks.check_convergence_times, *wrong)
    assert "one of these" not in message and "single run" not in message


def test_check_convergence_times_names_each_typical_mistake(batch, squared, times) -> None:
    t_small, t_large = times
    curve = squared[:, 0].mean(axis=0)
    per_run = [hand_convergence_time(one, DT) for one in squared[:, 0]]
    error = batch.positions[:, 0] - TRUTH[:, 0]
    steady = curve[N // 2:].mean()
    entered = int(np.argmax(curve <= 2 * steady)) * DT
    cases = [
        ("t_small = 0.09 s is not right: it is the convergence time from P0_large",
         (t_large, t_small)),
        ("your convergence time is in samples", (round(t_small / DT), t_large)),
        ("your convergence time is in milliseconds", (1000 * t_small, t_large)),
        ("the convergence time of a single run (run 0)", (per_run[0], t_large)),
        ("the mean of the runs' convergence times", (float(np.mean(per_run)), t_large)),
        ("t_small holds one convergence time per run", (np.array(per_run), t_large)),
        ("the errors were averaged over the runs before squaring",
         (hand_convergence_time(error.mean(axis=0) ** 2, DT), t_large)),
        ("the first time the curve enters the band", (entered, t_large)),
        ("the curve is the root of the mean squared error",
         (hand_convergence_time(np.sqrt(curve), DT), t_large)),
        ("the time of the last sample outside the band", (t_small, t_large - DT)),
        ("t_large = 0.12 s does not match the convergence time of the Monte Carlo mean "
         "squared error from P0 = diag(1e5)", (t_small, t_large + 3 * DT)),
    ]
    assert entered < t_small          # the curve enters the band, then leaves it again
    for phrase, answer in cases:
        assert_fails(phrase, checks.check_convergence_times, *answer)


# ------------------------------------------------------------------------------------------
# Task 3: check_start_and_after
# ------------------------------------------------------------------------------------------


def paired(mses: np.ndarray) -> metrics.Interval:
    return metrics.mean_ci95(mses[:, 0] - mses[:, 1])


def test_check_start_and_after_passes_the_worked_solution(capsys, batch) -> None:
    start = metrics.mse(batch.positions[..., :BURN], TRUTH[:BURN, 0])
    after = batch.mse()
    line = assert_passes(capsys, checks.check_start_and_after, paired(start), paired(after))
    assert "paired over 300 runs" in line


def test_check_start_and_after_names_each_typical_mistake(batch) -> None:
    positions, truth = batch.positions, TRUTH[:, 0]
    start = paired(metrics.mse(positions[..., :BURN], truth[:BURN]))
    after = paired(batch.mse())
    whole = paired(metrics.mse(positions, truth))
    first_runs = metrics.mse(positions[:BURN], truth)   # [:burn_in] on the runs' axis
    one_mse = metrics.mse(positions[..., :BURN], truth[:BURN])
    alone = [metrics.mean_ci95(one_mse[:, i]) for i in range(2)]
    cases = [
        ("start_difference is not right: it is over the whole trial", (whole, after)),
        ("after_difference is not right: it is over the whole trial", (start, whole)),
        ("start_difference is not right: it is the difference after the first second",
         (after, start)),
        ("start_difference is over 100 runs: [:burn_in] on the first axis cut the first 100 "
         "runs", (paired(first_runs), after)),
        ("after_difference is not right: it leaves out only the first sample",
         (start, paired(metrics.mse(positions, truth, 1)))),
        ("after_difference is not right: it leaves out one sample too many (101 instead of "
         "100)", (start, paired(metrics.mse(positions, truth, BURN + 1)))),
        ("after_difference is not right: it leaves out one sample too few (99 instead of 100)",
         (start, paired(metrics.mse(positions, truth, BURN - 1)))),
        ("start_difference is not right: the first second ends one sample early",
         (paired(metrics.mse(positions[..., :BURN - 1], truth[:BURN - 1])), after)),
        ("the sign is reversed", (metrics.mean_ci95(one_mse[:, 1] - one_mse[:, 0]), after)),
        ("it combines the two separate intervals",
         (metrics.Interval(alone[0].mean - alone[1].mean, alone[0].low - alone[1].high,
                           alone[0].high - alone[1].low, RUNS), after)),
        ("the difference of the root mean squared errors", (paired(np.sqrt(one_mse)), after)),
        ("start_difference is a number; it must be the metrics.Interval",
         (float(one_mse[:, 0].mean() - one_mse[:, 1].mean()), after)),
    ]
    for phrase, answer in cases:
        assert_fails(phrase, checks.check_start_and_after, *answer)


# ------------------------------------------------------------------------------------------
# Going further 1: check_flight_scales
# ------------------------------------------------------------------------------------------

AMPLITUDE, OMEGA = DEFAULT.amplitude, 2 * np.pi * DEFAULT.frequency
SCALES = np.array([AMPLITUDE**2, (AMPLITUDE * OMEGA) ** 2, (AMPLITUDE * OMEGA**2) ** 2])


def test_check_flight_scales_passes_the_worked_solution(capsys) -> None:
    error = TRUTH[0] - np.asarray(DEFAULT.z0)
    assert error[1] == pytest.approx(AMPLITUDE * OMEGA)   # the guess misses the velocity
    line = assert_passes(capsys, checks.check_flight_scales, error, SCALES)
    assert "A = 10 cm, f = 0.5 Hz" in line


@pytest.mark.parametrize(("error", "scales", "phrase"), [
    (-TRUTH[0], SCALES, "it is the guess minus the true state"),
    (TRUTH[0] ** 2, SCALES, "initial_error is not right: it is squared"),
    (TRUTH[0], np.array([AMPLITUDE, AMPLITUDE * 0.5, AMPLITUDE * 0.25]) ** 2,
     "ω is in Hz (ω = f)"),
    (TRUTH[0], np.array([AMPLITUDE, AMPLITUDE * OMEGA, AMPLITUDE * OMEGA**2]),
     "the scales are not squared"),
    (TRUTH[0], np.array([AMPLITUDE**2, AMPLITUDE * OMEGA**2, AMPLITUDE * OMEGA**4]),
     "only ω was squared"),
    (TRUTH[0], np.array([AMPLITUDE, AMPLITUDE * 4 * np.pi, AMPLITUDE * 16 * np.pi**2]) ** 2,
     "ω = 2π / f"),
    (TRUTH[0], SCALES[::-1], "the order is reversed"),
])
def test_check_flight_scales_names_each_typical_mistake(error, scales, phrase) -> None:
    assert_fails(phrase, checks.check_flight_scales, error, scales)


# ------------------------------------------------------------------------------------------
# Going further 2: check_first_gains
# ------------------------------------------------------------------------------------------


def hand_gains(P0: np.ndarray, *, carry: str = "eq. (5)", r: float = DEFAULT.sigma_v**2,
               trial_model: experiments.FilterModel | None = None) -> np.ndarray:
    """K₁ and K₂ by eq. (5) as a student writes it, with the slip ``carry`` names."""
    vision = trial_model or experiments.filter_model(DEFAULT)
    A, C, Q, R = vision.A, vision.C, vision.Q, np.array([[r]])
    gains, P = np.zeros((2, 3)), P0
    for j in range(2):
        K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
        gains[j] = K[:, 0]
        corrected = P - K @ C @ P
        P = {"eq. (5)": A @ corrected @ A.T + Q, "no A": corrected + Q,
             "no Q": A @ corrected @ A.T, "not carried": P,
             "no correction": A @ P @ A.T + Q}[carry]
    return gains


def test_check_first_gains_passes_the_worked_solution(capsys) -> None:
    small, large = hand_gains(P0_SMALL), hand_gains(P0_LARGE)
    assert small[0, 0] == pytest.approx(1 / (1 + DEFAULT.sigma_v**2))   # K₁ = p0/(p0 + σ²)
    assert small[0, 1] == large[0, 1] == 0.0                            # diagonal P0
    line = assert_passes(capsys, checks.check_first_gains, small, large)
    assert "K₁ and K₂ of the pack's engine" in line


@pytest.mark.parametrize(("small", "large", "phrase"), [
    (hand_gains(P0_LARGE), hand_gains(P0_SMALL), "it holds the gains from P0 = diag(1e5)"),
    (hand_gains(P0_SMALL, carry="not carried"), hand_gains(P0_LARGE),
     "K₂ was computed from P0 again"),
    (hand_gains(P0_SMALL), hand_gains(P0_LARGE, carry="no Q"), "Q is missing from P₁"),
    (hand_gains(P0_SMALL, carry="no A"), hand_gains(P0_LARGE), "A is missing from P₁"),
    (hand_gains(P0_SMALL), hand_gains(P0_LARGE, carry="no correction"),
     "P₁ misses the correction −K₁CP0"),
    (hand_gains(P0_SMALL, r=DEFAULT.sigma_v), hand_gains(P0_LARGE),
     "R holds σ_v (cm) where its variance σ_v² (cm²) belongs"),
    (hand_gains(P0_SMALL).T, hand_gains(P0_LARGE), "gains_small has shape (3, 2): it is "
                                                   "transposed"),
    (hand_gains(P0_SMALL)[..., None], hand_gains(P0_LARGE), "each K is a 3 × 1 column"),
])
def test_check_first_gains_names_each_typical_mistake(small, large, phrase) -> None:
    assert_fails(phrase, checks.check_first_gains, small, large)


# ------------------------------------------------------------------------------------------
# Going further 3: check_overconfidence
# ------------------------------------------------------------------------------------------


def test_check_overconfidence_passes_the_worked_solution(capsys, batch, squared) -> None:
    ratio = squared.mean(axis=0)[:, :BURN] / batch.position_variances[0, :, :BURN]
    assert ratio[0].max() > 10 > 3 > ratio[1].max()     # the confident start is overconfident
    line = assert_passes(capsys, checks.check_overconfidence, ratio)
    assert "over the filter's own position variance" in line


def test_check_overconfidence_names_each_typical_mistake(batch, squared) -> None:
    mean = squared.mean(axis=0)
    own = batch.position_variances[0]
    prior = batch.result.covariances[0, :, :, 0, 0]
    cases = [
        ("it is the other way round", own[:, :BURN] / mean[:, :BURN]),
        ("it divides by the standard deviation", mean[:, :BURN] / np.sqrt(own[:, :BURN])),
        ("the ratio of the roots", np.sqrt(mean[:, :BURN] / own[:, :BURN])),
        ("the squared error of one run (run 0)", squared[0, :, :BURN] / own[:, :BURN]),
        ("it divides by the variance of the prediction", mean[:, :BURN] / prior[:, :BURN]),
        ("the rows are swapped", (mean[:, :BURN] / own[:, :BURN])[::-1]),
        ("overconfidence covers the whole trial", mean / own),
    ]
    for phrase, answer in cases:
        assert_fails(phrase, checks.check_overconfidence, answer)


# ------------------------------------------------------------------------------------------
# Going further 4: check_convergence_intervals
# ------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_check_convergence_intervals_passes_with_any_seed(capsys, squared) -> None:
    for seed in (DEFAULT.seed, 1, 2026):
        rng = np.random.default_rng(seed)
        intervals = [metrics.convergence_time_ci95(squared[:, i], DT, rng) for i in range(2)]
        line = assert_passes(capsys, checks.check_convergence_intervals, *intervals)
        assert "the ends to 0.02 s" in line


def test_check_convergence_intervals_names_each_typical_mistake(squared, times) -> None:
    rng = np.random.default_rng(DEFAULT.seed)
    small, large = (metrics.convergence_time_ci95(squared[:, i], DT, rng) for i in range(2))
    per_run = [hand_convergence_time(one, DT) for one in squared[:, 0]]
    in_samples = metrics.convergence_time_ci95(squared[:, 0], 1.0, np.random.default_rng(7))
    wide = metrics.Interval(small.mean, small.low - 0.1, small.high + 0.1, RUNS)
    cases = [
        ("convergence_small is not right: it is the interval from P0 = diag(1e5)",
         (large, small)),
        ("it is in samples (dt was given as 1)", (in_samples, large)),
        ("the interval of the runs' own convergence times",
         (metrics.mean_ci95(np.array(per_run)), large)),
        ("the squared errors were transposed",
         (small, metrics.convergence_time_ci95(squared[:, 1].T, DT, rng))),
        ("the convergence time (0.57 s) is right, but the interval's ends", (wide, large)),
        ("convergence_large is a tuple", (small, (large.low, large.high))),
    ]
    assert times[0] == pytest.approx(small.mean)
    for phrase, answer in cases:
        assert_fails(phrase, checks.check_convergence_intervals, *answer)


# ------------------------------------------------------------------------------------------
# Going further 5: check_p0_sweep
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def sweep() -> dict[str, np.ndarray]:
    """The worked sweep: one call of the engine, MSEs by window, times by the hand loop."""
    grid = np.logspace(-2, 6, 17)
    runs = experiments.track(DEFAULT, p0_variance=grid, runs=RUNS)
    squared_sweep = (runs.positions - TRUTH[:, 0]) ** 2
    return {"positions": runs.positions, "squared": squared_sweep,
            "start": metrics.mse(runs.positions[..., :BURN], TRUTH[:BURN, 0]),
            "after": runs.mse(),
            "times": np.array([hand_convergence_time(curve, DT)
                               for curve in squared_sweep.mean(axis=0)])}


@pytest.mark.slow
def test_check_p0_sweep_passes_the_worked_solution(capsys, sweep) -> None:
    line = assert_passes(capsys, checks.check_p0_sweep, sweep["start"], sweep["after"],
                         sweep["times"])
    assert "have the grid's shape and match 300 runs of the pack's engine at p0 = 0.01, 1, " \
           "1000, 100000, 1e+06" in line


@pytest.mark.slow
def test_check_p0_sweep_names_each_typical_mistake(sweep) -> None:
    start, after, times = sweep["start"], sweep["after"], sweep["times"]
    whole = metrics.mse(sweep["positions"], TRUTH[:, 0])
    one_run = np.array([hand_convergence_time(curve, DT) for curve in sweep["squared"][0]])
    cases = [
        ("sweep_start (at p0 = 0.01, 1, 1000, 100000, 1e+06) is not right: it is over the "
         "whole trial", (whole, after, times)),
        ("1e+06) is not right: it is over the whole trial: leave out", (start, whole, times)),
        ("it is the MSE after the first second; sweep_start", (after, start, times)),
        ("sweep_start must have shape (300, 17)", (start[:, ::2], after, times)),
        ("sweep_times must have shape (17,)", (start, after, times[::2])),
        ("sweep_start has shape (17, 300): it is transposed", (start.T, after, times)),
        ("sweep_after holds one number per p0", (start, after.mean(axis=0), times)),
        ("is not right: it is the root mean squared error",
         (np.sqrt(start), after, times)),
        ("sweep_times (at p0 = 0.01, 1, 1000, 100000, 1e+06) is not right: the times are in "
         "samples", (start, after, times / DT)),
        ("the convergence times of one run (run 0)", (start, after, one_run)),
    ]
    for phrase, answer in cases:
        assert_fails(phrase, checks.check_p0_sweep, *answer)
