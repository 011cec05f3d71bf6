"""Messages that said more than they should, or the wrong thing (issues 27 and 23 §4)."""

from __future__ import annotations

import linecache
import warnings

import numpy as np
import pytest

from lqe_helpers import experiments, student_code
from lqe_helpers.explorers.student_functions import whose
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.student_code import StudentCodeError, function_name
from lqe_helpers.student_code.errors import read_only_advice


@pytest.mark.parametrize(("y", "dtype", "reason"), [
    (np.full((5, 1), 1 + 1j), "complex128", "a complex number"),
    (np.array([["1.5"], ["2.0"], ["0.5"], ["7.5"], ["1.0"]]), "<U3", "text"),
])
def test_the_filter_names_y_of_the_wrong_kind_in_one_line(y, dtype, reason) -> None:
    with pytest.raises(ValueError) as info:
        kalman_filter(y, np.eye(1), np.eye(1), np.eye(1), np.eye(1), np.zeros(1), np.eye(1))
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"y must be a numeric array, got an array of shape (5, 1) and "
                              f"dtype {dtype}: {reason}")


def test_a_lambda_is_your_function_once() -> None:
    def my_filter(y):
        return y

    assert whose(my_filter) == "your my_filter"
    assert whose(lambda y: y) == "your function"
    assert function_name(lambda y: y) == "your function"
    assert function_name(my_filter, yours=True) == "your my_filter"
    assert function_name(lambda y: y, yours=True) == "your function"


def overflows(x):
    return np.asarray(x) * 1e308 * 10


def overflows_then_fails(x):
    big = np.asarray(x) * 1e308 * 10
    return big @ np.ones((3, 3))


def test_warnings_of_a_students_function_are_quoted_in_its_failure_not_printed() -> None:
    with warnings.catch_warnings(record=True) as printed:
        warnings.simplefilter("always")
        assert np.isinf(student_code.call(overflows, [1.0, 2.0])).all()
        with pytest.raises(StudentCodeError) as info:
            student_code.call(overflows_then_fails, [1.0, 2.0])
    assert printed == []
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("overflows_then_fails raised ValueError: matmul: ")
    assert message.endswith("Before that it warned: RuntimeWarning: overflow encountered in "
                            "multiply.")


def _read_only_error(code: str, namespace: dict) -> str | None:
    """Run ``code`` as a notebook cell (IPython keeps its lines in linecache, so do we)."""
    linecache.cache["<cell In[7]>"] = (len(code), None, code.splitlines(True), "<cell In[7]>")
    try:
        exec(compile(code, "<cell In[7]>", "exec"), namespace)
    except ValueError as error:
        return read_only_advice(error, error.__traceback__)
    raise AssertionError("no error")


@pytest.mark.parametrize("change", ["P += Q", "P[0, 0] = 1.0", "P *= 2"])
def test_changing_the_packs_read_only_p_close_in_place_says_to_copy_it(change) -> None:
    P_close = experiments.track(DEFAULT, runs=2).result.estimate_covariances[0, 10]
    namespace = {"P_close": P_close, "Q": np.eye(3), "np": np}
    advice = _read_only_error(f"P = P_close\n{change}\n", namespace)
    assert advice == ("P_close is read-only: copy it (P = P_close.copy()) before changing P "
                      "in place")
    assert _read_only_error(f"P = P_close[:2, :2]\n{change}\n", namespace) == (
        "P_close is read-only: copy it (P = P_close.copy()) before changing P in place")


def test_another_value_error_gets_no_read_only_advice() -> None:
    try:
        np.ones(3) @ np.ones(2)
    except ValueError as error:
        assert read_only_advice(error, error.__traceback__) is None
