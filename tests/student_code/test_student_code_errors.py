"""One hierarchy of errors for students (issue 25): the checks' are student_code's.

``checks.machinery`` used to define its own CheckFailed, NotWrittenYet and TimedOut and
translate student_code's errors of the same names into them.
"""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import checks, student_code
from lqe_helpers.checks import machinery
from lqe_helpers.student_code import errors


def test_the_checks_errors_are_student_codes() -> None:
    assert machinery.CheckFailed is student_code.CheckFailed is errors.CheckFailed
    assert machinery.NotWrittenYet is student_code.NotWrittenYet
    assert machinery.TimedOut is student_code.TimedOut
    assert checks.CheckFailed is student_code.CheckFailed
    assert issubclass(errors.CheckFailed, errors.StudentCodeError)
    assert issubclass(errors.CheckFailed, AssertionError)
    assert issubclass(errors.NotWrittenYet, errors.CheckFailed)
    assert issubclass(errors.TimedOut, errors.CheckFailed)
    assert not issubclass(errors.NotSavedYet, errors.CheckFailed)


def stub(x):
    raise NotImplementedError


def broken(x):
    return 1 / 0


def test_a_check_raises_the_error_student_code_raises_with_the_same_message() -> None:
    with pytest.raises(student_code.NotWrittenYet) as plain:
        student_code.call(stub, 1)
    with pytest.raises(student_code.NotWrittenYet) as checked:
        machinery.call_student(stub, 1, name="stub", where="")
    assert str(checked.value) == str(plain.value)
    with pytest.raises(student_code.CheckFailed) as failed:
        machinery.call_student(broken, 1, name="broken", where="a test")
    assert type(failed.value) is student_code.CheckFailed
    assert str(failed.value).startswith("broken raised ZeroDivisionError: division by zero (in "
                                        "broken, line ")
    assert failed.value.student_traceback is not None
    with pytest.raises(student_code.StudentCodeError) as unchecked:
        student_code.call(broken, 1, where="a test")
    assert type(unchecked.value) is student_code.StudentCodeError
    assert str(unchecked.value) == str(failed.value)


def test_a_guards_error_inside_a_check_is_a_check_failure(tmp_path) -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        return np.zeros((len(y), len(z0)))

    guarded = student_code.guards.guarded("my_filter", my_filter)
    with pytest.raises(student_code.CheckFailed, match=r"^my_filter was given inputs that do "
                                                      r"not fit: y has shape \(3,\)"):
        machinery.call_student(guarded, np.zeros(3), np.eye(1), np.eye(1), np.eye(1),
                               np.eye(1), np.zeros(1), np.eye(1), name="my_filter", where="")
