"""Instant feedback for the tasks of the notebooks: one ``check_…`` after each task.

A check that passes prints one line starting with "✓ " saying what was verified. A check
that fails raises :class:`CheckFailed` (an ``AssertionError``, so "Run All" stops at the
wrong step) with a message that says what is wrong without giving the code.

Function checks (:func:`check_filter`, :func:`check_compensation`) call the student's
function on several small random models drawn from a fixed seed, not only on the pack's
scenario, so that a hard-coded answer cannot pass. When the answer is wrong they compare
it with typical mistakes computed here (kept private) to name the mistake.

One module per kind of task; this package re-exports what notebooks call:

- ``_common``: :class:`CheckFailed`, the tolerances, calling and comparing answers;
- ``_filter``: (a) the filter of eq. (5);
- ``_fusion``: (c) C and R for two senses;
- ``_compensation``: (e) the delay compensation;
- ``_numbers``: the numbers a task produces (P0, MSEs, convergence times, intervals);
- ``_model``: notebooks 00 and 06 (A, the covariance step, the bias model).
"""

from ._common import (
    FUNCTION_RTOL,
    INTERVAL_RTOL,
    MATRIX_RTOL,
    MSE_RTOL,
    SEED,
    TIME_ATOL,
    CheckFailed,
)
from ._compensation import check_compensation
from ._filter import check_filter
from ._fusion import check_fusion
from ._model import check_bias_model, check_covariance_step, check_transition_matrix
from ._numbers import (
    check_convergence_time,
    check_initial_covariance,
    check_mse,
    check_paired_difference,
)

__all__ = [
    "FUNCTION_RTOL",
    "INTERVAL_RTOL",
    "MATRIX_RTOL",
    "MSE_RTOL",
    "SEED",
    "TIME_ATOL",
    "CheckFailed",
    "check_bias_model",
    "check_compensation",
    "check_convergence_time",
    "check_covariance_step",
    "check_filter",
    "check_fusion",
    "check_initial_covariance",
    "check_mse",
    "check_paired_difference",
    "check_transition_matrix",
]
