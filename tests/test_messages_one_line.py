"""Messages that said more than they should, or the wrong thing (issues 27 and 23 §4)."""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers.explorers.student_functions import whose
from lqe_helpers.filter import kalman_filter
from lqe_helpers.student_code import function_name


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
