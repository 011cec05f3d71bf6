"""The checks' shared machinery: judge, judge_interval, the usual mistakes, hidden frames."""

from __future__ import annotations

import numpy as np
import pytest
from check_outcomes import assert_fails

from lqe_helpers import checks, metrics
from lqe_helpers.checks import CheckFailed
from lqe_helpers.checks.judging import judge, judge_interval, mse_mistakes
from lqe_helpers.checks.machinery import argument_array, positive_number
from lqe_helpers.checks.paired_mistakes import interval_mistakes
from lqe_helpers.student_code import OwnCodeTraceback


def test_check_failed_is_an_assertion_error_shown_without_library_frames() -> None:
    assert issubclass(CheckFailed, AssertionError)
    assert issubclass(CheckFailed, OwnCodeTraceback)


def test_pytest_hides_the_frames_of_the_checks() -> None:
    with pytest.raises(CheckFailed) as info:
        checks.check_fusion(None, None, 1.5, 1.5)
    shown = info.traceback.filter(info)
    assert [entry.path for entry in shown] == [entry.path for entry in shown
                                               if "lqe_helpers" not in str(entry.path)]
    assert len(shown) == 1 and shown[0].path.name == "test_checks_judging.py"


# ------------------------------------------------------------------------------------------
# judge
# ------------------------------------------------------------------------------------------

MISTAKES = {"σ where σ² belongs": 1.5, "the whole trial": 2.5, "the same as right": 2.0 + 1e-12}


def test_judge_passes_within_its_tolerance_and_not_beyond() -> None:
    assert judge("x", 2.0 * (1 + 4e-7), 2.0, 1e-6) == pytest.approx(2.0)
    assert judge("x", np.array([2.0]), 2.0, 1e-6).shape == ()        # one number as an array
    assert_fails("x = 2.00001 cm² does not match the value recomputed from the task's inputs (to "
                 "1e-6 relative), and not by one of the usual mistakes: look again",
                 judge, "x", 2.00001, 2.0, 1e-6, mistakes=MISTAKES, unit="cm²",
                 hint="look again")


def test_judge_names_the_first_matching_mistake_in_words() -> None:
    assert_fails("x = 1.5 is not right: σ where σ² belongs", judge, "x", 1.5, 2.0, 1e-6,
                 mistakes=MISTAKES)
    assert_fails("x = 2.5 cm² is not right: the whole trial", judge, "x", 2.5, 2.0, 1e-6,
                 mistakes=MISTAKES, unit="cm²")
    # A mistake that gives the right value cannot explain a wrong one; None cannot occur.
    message = assert_fails("not by one of the usual mistakes", judge, "x", 2.1, 2.0, 1e-6,
                           mistakes={"a": None, "b": 2.0})
    assert "is not right" not in message


@pytest.mark.parametrize(("value", "phrase"), [
    (None, "x must be one number (cm²), got None (nothing)"),
    (True, "x must be one number (cm²), got True (a boolean)"),
    (2 + 0j, "x must be one number (cm²), got a complex number ((2+0j))"),
    ("2.0", "x must be one number (cm²), got text ('2.0')"),
    ([2.0], "x must be one number (cm²), got a Python list"),
    (np.ones(2), "x must be one number (cm²), got an array of shape (2,)"),
    (np.inf, "got inf (infinite)"),
    (1e160, "got values too large to square"),
    (np.nan, "x is NaN (not a number): the first δ samples are NaN"),
])
def test_judge_names_a_value_that_is_not_a_number(value, phrase) -> None:
    assert_fails(phrase, judge, "x", value, 2.0, 1e-6, unit="cm²",
                 nan_hint="the first δ samples are NaN")


def test_judge_compares_arrays_entry_by_entry() -> None:
    expected = np.array([1.0, 2.0, 3.0])
    assert judge("v", expected * (1 + 1e-9), expected, 1e-6).shape == (3,)
    assert_fails("v is not right: per run", judge, "v", expected + 1, expected, 1e-6,
                 mistakes={"per run": expected + 1})
    assert_fails("v must be an array of shape (3,), got an array of shape (2,)", judge, "v",
                 expected[:2], expected, 1e-6)


def test_mse_mistakes_are_the_usual_slips() -> None:
    truth = np.zeros(6)
    estimate = np.array([9.0, 9.0, 1.0, -1.0, 2.0, -2.0])
    found = mse_mistakes(estimate, truth, 2, dt=0.5)
    right = np.mean(estimate[2:] ** 2)                       # 2.5
    values = {cause.split(":")[0]: value for cause, value in found.items()}
    assert values["it is the root mean squared error (RMSE, in cm)"] == np.sqrt(right)
    assert values["it is the sum of the squared errors"] == 10.0
    assert values["the errors are not squared (the mean error)"] == 0.0
    assert values["it is the MSE of the whole trial"] == np.mean(estimate**2)
    assert values["it leaves out the first 1 sample(s)"] == np.mean(estimate[1:] ** 2)
    assert values["it leaves out one sample too many (3 instead of 2)"] == np.mean(
        estimate[3:] ** 2)
    assert values["it leaves out one sample too few (1 instead of 2)"] == np.mean(
        estimate[1:] ** 2)
    readings = mse_mistakes(estimate, truth, 2, readings={"the readings": estimate - 1.0})
    assert readings["it compares the estimate with the readings, not with the true position: "
                    "the MSE measures how far the estimate is from the truth"] == 1.0
    with_nan = mse_mistakes(np.array([np.nan, 1.0, 2.0]), np.zeros(3), 1)
    assert with_nan["it is the MSE of the whole trial: the first 1 samples (the burn-in) must "
                    "be left out"] is None
    assert with_nan["it leaves out one sample too few (0 instead of 1): the burn-in is the "
                    "first 1 samples, so keep the samples from index 1 on"] is None
    assert not [cause for cause in mse_mistakes(estimate, truth, 0) if "one sample" in cause]


# ------------------------------------------------------------------------------------------
# judge_interval
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def runs() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(3)
    shared = rng.gamma(10.0, 0.1, size=200)
    return shared + 0.1 + 0.01 * rng.normal(size=200), shared


def test_judge_interval_passes_the_right_one_and_names_the_usual_mistakes(runs) -> None:
    first, second = runs
    right = metrics.mean_ci95(first - second)
    judge_interval("d", right, right, 1e-9)
    mistakes = interval_mistakes(first, second, "the first MSE", "the second MSE")
    for cause, wrong in mistakes.items():
        assert_fails(f"d is not right: {cause}", judge_interval, "d", wrong, right, 1e-9,
                     mistakes=mistakes)
    assert next(iter(mistakes)).startswith("the sign is reversed: it is the second MSE − the "
                                           "first MSE")


def test_runs_shuffled_out_of_their_pairs_are_named(runs) -> None:
    """The mean survives a shuffle of one condition's runs; the paired interval does not."""
    first, second = runs
    right = metrics.mean_ci95(first - second)
    shuffled = metrics.mean_ci95(first - np.random.default_rng(0).permutation(second))
    message = assert_fails("Are the runs paired, run r with run r", judge_interval, "d",
                           shuffled, right, 1e-9,
                           mistakes=interval_mistakes(first, second, "a", "b"))
    assert message.startswith("d: the mean (")


def test_runs_of_another_draw_are_named_where_pairing_narrows_the_interval(runs) -> None:
    """Given the per-run values, an interval over another draw (mean off by noise, the
    unpaired width) is named as unpaired; the paired interval here is far narrower."""
    first, second = runs
    right = metrics.mean_ci95(first - second)
    rng = np.random.default_rng(11)
    other = rng.gamma(10.0, 0.1, size=first.size) + 0.1 + 0.01 * rng.normal(size=first.size)
    unpaired = metrics.mean_ci95(other - second)
    assert abs(unpaired.mean - right.mean) > 1e-3           # not the right mean
    assert_fails("d (mean", judge_interval, "d", unpaired, right, 1e-9,
                 runs_of=(first, second, "Pair them."))
    message = assert_fails("is not right: its runs are not paired: its mean is within the "
                           "spread of another noise draw", judge_interval, "d", unpaired,
                           right, 1e-9, runs_of=(first, second, "Pair them."))
    assert message.endswith("Pair them.")
    # Without the per-run values nothing is claimed.
    assert_fails("and not by one of the usual mistakes", judge_interval, "d", unpaired, right,
                 1e-9)
    # A mean far outside another draw's spread is not called unpaired.
    shifted = metrics.Interval(unpaired.mean + 1.0, unpaired.low + 1.0, unpaired.high + 1.0,
                               unpaired.runs)
    message = assert_fails("and not by one of the usual mistakes", judge_interval, "d",
                           shifted, right, 1e-9, runs_of=(first, second, "Pair them."))
    assert "noise draw" not in message


def test_judge_interval_names_what_is_not_an_interval(runs) -> None:
    first, second = runs
    right = metrics.mean_ci95(first - second)
    for value, found in (((right.low, right.high), "a pair of numbers"),
                         (right.mean, "a number"), (None, "None"),
                         (np.array([1.0, 2.0, 3.0]), "an array of shape (3,)")):
        assert_fails(f"d is {found}; it must be the metrics.Interval", judge_interval, "d",
                     value, right, 1e-9)
    half = metrics.mean_ci95((first - second)[:50])
    assert_fails("d is over 50 runs, but the task has 200", judge_interval, "d", half, right,
                 1e-9)
    wider = metrics.Interval(right.mean, right.low - 1, right.high + 1, right.runs)
    assert_fails("the mean (0.1", judge_interval, "d", wider, right, 1e-9)
    nan = metrics.Interval(np.nan, np.nan, np.nan, right.runs)
    assert_fails("d holds NaN (not a number): seconds?", judge_interval, "d", nan, right, 1e-9,
                 nan_hint="seconds?")


# ------------------------------------------------------------------------------------------
# Values a student passes
# ------------------------------------------------------------------------------------------


def test_arguments_are_named_with_what_they_must_be() -> None:
    assert argument_array(np.eye(2), "R", "a 2 × 2 matrix").shape == (2, 2)
    assert_fails("R must be a 2 × 2 matrix, got an array of shape (3,), not of shape (2, 2)",
                 argument_array, np.ones(3), "R", "a 2 × 2 matrix", (2, 2))
    assert positive_number(np.float32(1.5), "sigma_v", "cm") == 1.5
    assert_fails("sigma_v must be a number > 0 cm, got 0", positive_number, 0, "sigma_v", "cm")
    assert_fails("sigma_v must be a number > 0 cm, got None", positive_number, None, "sigma_v",
                 "cm")
    with pytest.raises(CheckFailed, match="needs your function my_filter itself"):
        checks.check_filter(None)
