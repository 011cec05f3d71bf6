"""The shared input checks: what counts as a number, an array, a whole number of steps."""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import validation


@pytest.mark.parametrize(
    ("value", "reason"),
    [
        (True, "a boolean"),
        (np.bool_(False), "a boolean"),
        (1 + 2j, "a complex number"),
        (np.complex64(1), "a complex number"),
        ("1.5", "text"),
        (b"1.5", "text"),
        ([1.0, True], "a boolean"),
        ((1.0, (2.0, 3j)), "a complex number"),
        (np.array([1.0, 2.0], dtype=complex), "a complex number"),
        (np.array([True]), "a boolean"),
        (np.array(["1"]), "text"),
        (np.array([1.0, True], dtype=object), "a boolean"),
        (np.array(["2026-01-01"], dtype="datetime64[D]"), "a date"),
    ],
)
def test_not_real_numbers_are_named(value: object, reason: str) -> None:
    assert validation.not_real(value).startswith(reason)
    with pytest.raises(ValueError, match=rf"^x must be a numeric array, got .*: {reason}"):
        validation.numeric_array("x", value)


@pytest.mark.parametrize("value", [1, 1.5, np.float32(2), np.int64(3), [1, 2.5],
                                   np.arange(3), np.zeros((2, 2), dtype=np.float32),
                                   [[1.0, np.nan]]])
def test_real_numbers_pass(value: object) -> None:
    assert validation.not_real(value) is None
    array = validation.numeric_array("x", value)
    assert array.dtype == float
    np.testing.assert_array_equal(array, np.asarray(value, dtype=float))


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: validation.positive("sigma", True, "cm"),
         r"^sigma must be a number > 0 cm, got True: a boolean"),
        (lambda: validation.non_negative("t", np.True_), r"^t must be a number >= 0, got np.True_"),
        (lambda: validation.finite_number("b", 2j),
         r"^b must be a finite number, got 2j: a complex"),
        (lambda: validation.positive("dt", "0.01", "s"),
         r"^dt must be a number > 0 s, got '0.01': text \(write the number without quotes\)$"),
        (lambda: validation.positive("dt", [0.01], "s"),
         r"^dt must be a number > 0 s, got \[0.01\]: an array \(give a single number\)$"),
        (lambda: validation.positive("dt", None, "s"), r"^dt must be a number > 0 s, got None$"),
        (lambda: validation.count("runs", True), r"^runs must be a whole number >= 0, got True$"),
        (lambda: validation.finite_array("y", []),
         r"^y must hold at least one number, got an empty array of shape \(0,\)$"),
        (lambda: validation.positive_array("p", np.zeros((3, 0)), "cm²"),
         r"^p must hold at least one number, got an empty array of shape \(3, 0\)$"),
        (lambda: validation.numeric_array("y", 1.5, min_ndim=1),
         r"^y must have at least 1 axes, got shape \(\) \(1.5\)$"),
    ],
)
def test_scalar_and_array_checks_name_parameter_value_and_rule(call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()


@pytest.mark.parametrize(
    ("value", "dt", "steps"),
    [
        (0.1, 0.01, 10),
        (np.float32(0.1), 0.01, 10),        # 0.10000000149 s: 10 steps at float32 precision
        (0.1, np.float32(0.01), 10),
        (np.float32(10.0), np.float32(0.01), 1000),
        (np.float16(0.5), 0.01, 50),
        (0.3, 0.1, 3),                      # 2.9999999999999996 in float64
        (0.0, 0.01, 0),
    ],
)
def test_whole_steps_accepts_rounding_of_the_given_precision(value, dt, steps: int) -> None:
    assert validation.whole_steps("delay", value, dt) == steps


@pytest.mark.parametrize(
    ("value", "dt", "message"),
    [
        (0.1000001, 0.01, r"got 0.1000001 s \(10.00001 steps\), the nearest whole numbers of "
                          r"steps being 0.1 s and 0.11 s$"),
        # Off by 2e-6 relative: far above float32's 1.2e-7, so refused even in float32.
        (np.float32(0.1000002), 0.01, r"got 0.1000002 s \(10.00002027 steps\)"),
        (0.004, 0.01, r"got 0.004 s \(0.4 steps\), the nearest whole numbers of steps being 0 s "
                      r"and 0.01 s$"),
        (True, 0.01, r"^delay must be a finite number in s, got True: a boolean"),
    ],
)
def test_whole_steps_refuses_and_says_how_many_steps(value, dt, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        validation.whole_steps("delay", value, dt)


def test_check_memory_returns_the_estimate_within_the_limit_and_refuses_beyond() -> None:
    assert validation.check_memory("runs = 3", 1000) == 8000
    assert validation.check_memory("runs = 3", 1000, copies=2.5) == 20000
    limit_numbers = validation.MEMORY_LIMIT_BYTES // validation.FLOAT_BYTES
    assert validation.check_memory("n", limit_numbers) == validation.MEMORY_LIMIT_BYTES
    with pytest.raises(ValueError, match=r"^runs = 10000000 would need about 2 GiB for the "
                                         r"estimates, more than the limit of 2 GiB "
                                         r"\(validation.MEMORY_LIMIT_BYTES\); use fewer runs"):
        validation.check_memory("runs = 10000000", limit_numbers + 1, what="for the estimates")
    # Python ints: a size no machine could hold is estimated, not overflowed.
    with pytest.raises(ValueError, match=r"would need about 7.45e\+1[0-9] GiB"):
        validation.check_memory("n_steps = 10**20", validation.elements((10**20, 10)))


def test_a_covariance_of_subnormal_numbers_counts_as_zero() -> None:
    # Found by hypothesis: Q for a jerk of 1e-158 cm/s³ has entries near 1e-328, whose
    # rounding made the scaled matrix look indefinite.
    from lqe_helpers import model

    Q = model.process_noise_covariance(0.01, 1.1344280960175625e-158)
    assert np.max(np.abs(Q)) < np.finfo(float).tiny
    np.testing.assert_array_equal(validation.covariance("Q", Q, size=3), Q)
