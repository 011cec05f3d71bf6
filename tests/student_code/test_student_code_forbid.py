"""student_code.call(..., forbid=...): a student's function may not run the pack's answer."""

from __future__ import annotations

import sys
import threading

import numpy as np
import pytest

from lqe_helpers import prediction
from lqe_helpers.student_code import StudentCodeError, call

A = np.array([[1.0, 0.01], [0.0, 1.0]])
ESTIMATES = np.arange(10.0).reshape(5, 2)


def by_hand(estimates, A, steps):
    return estimates @ np.linalg.matrix_power(A, steps).T


def calls_the_engine(estimates, A, steps):
    return prediction.predict_ahead(estimates, A, steps)


def calls_an_alias(estimates, A, steps):
    from lqe_helpers.prediction import predict_ahead as shortcut

    return shortcut(estimates, A, steps)


def hides_the_call(estimates, A, steps):
    try:
        return prediction.predict_ahead(estimates, A, steps)
    except:  # noqa: E722 - a student's bare except must not hide the call either
        return by_hand(estimates, A, steps)


@pytest.mark.parametrize("function", [calls_the_engine, calls_an_alias, hides_the_call])
def test_a_function_that_runs_a_forbidden_function_fails_naming_it(function) -> None:
    with pytest.raises(StudentCodeError, match=r"runs the pack's own "
                       r"lqe_helpers\.prediction\.predict_ahead.*yourself"):
        call(function, ESTIMATES, A, 3, forbid=[prediction.predict_ahead])


def test_without_forbid_the_same_call_passes() -> None:
    np.testing.assert_array_equal(call(calls_the_engine, ESTIMATES, A, 3),
                                  prediction.predict_ahead(ESTIMATES, A, 3))


def test_a_function_written_by_hand_passes_and_the_profiler_is_restored() -> None:
    seen = []

    def outer_profiler(frame, event, arg) -> None:
        seen.append(event)

    sys.setprofile(outer_profiler)
    try:
        result = call(by_hand, ESTIMATES, A, 3, forbid=[prediction.predict_ahead])
        assert sys.getprofile() is outer_profiler
    finally:
        sys.setprofile(None)
    np.testing.assert_allclose(result, by_hand(ESTIMATES, A, 3))
    assert "call" in seen  # the outer profiler still saw the student's calls


def test_off_the_main_thread_the_forbidden_call_is_caught_too() -> None:
    outcome = {}

    def worker() -> None:
        try:
            call(calls_the_engine, ESTIMATES, A, 3, forbid=[prediction.predict_ahead])
        except StudentCodeError as error:
            outcome["error"] = str(error)

    thread = threading.Thread(target=worker)
    thread.start()
    thread.join(30)
    assert "predict_ahead" in outcome.get("error", "")


def test_forbid_takes_python_functions_only() -> None:
    with pytest.raises(ValueError, match="forbid must hold Python functions"):
        call(by_hand, ESTIMATES, A, 3, forbid=[np.linalg.matrix_power.__call__])
