"""lqe_helpers.student_code: calling a student's function, reading its result, keeping it.

Every failure of a student's function must become one StudentCodeError line (type,
message, the student's own line); an endless loop must end within the time limit on both
of its paths (SIGALRM in the main thread, a worker thread elsewhere); save and load must
replace only their own files. The kernel side (Jupyter shows only the student's frames) is
in ``test_student_code_kernel.py``.
"""

from __future__ import annotations

import os
import re
import signal
import threading
import time

import numpy as np
import pytest

from lqe_helpers import metrics, student_code
from lqe_helpers.student_code import (
    NotSavedYet,
    NotWrittenYet,
    StudentCodeError,
    TimedOut,
    calling,
)

LIMIT = 0.3  # s: short, so that the endless loops below end soon


def call(function, *args, **kwargs):
    return student_code.call(function, *args, time_limit=LIMIT, **kwargs)


def message_of(function, *args, **kwargs) -> str:
    with pytest.raises(StudentCodeError) as info:
        call(function, *args, **kwargs)
    text = str(info.value)
    assert "\n" not in text
    return text


# ------------------------------------------------------------------------------------------
# call: every failure is one line
# ------------------------------------------------------------------------------------------


def test_call_returns_what_the_function_returns_on_copies_of_arrays() -> None:
    data = np.arange(3.0)

    def doubles_in_place(x):
        x *= 2
        return x

    assert np.array_equal(call(doubles_in_place, data), [0.0, 2.0, 4.0])
    assert np.array_equal(data, [0.0, 1.0, 2.0])          # the caller's array is untouched
    assert "doubles_in_place changed its input x in place, on a test" in message_of(
        doubles_in_place, data, arg_names=("x",), where="a test")


def test_not_written_yet_says_what_to_do() -> None:
    def my_filter(y):
        """A stub."""
        raise NotImplementedError("write this")

    with pytest.raises(NotWrittenYet, match=r"^my_filter is not written yet: replace the line "
                       r"`raise NotImplementedError` with your code, run its cell, then run "
                       r"this check again$"):
        call(my_filter, 1)
    with pytest.raises(NotWrittenYet, match=r"then move the slider again$"):
        call(my_filter, 1, rerun="move the slider again")


def test_an_exception_names_its_type_message_and_the_students_line() -> None:
    def my_filter(y):
        S = np.ones((2, 3))
        return S @ S

    text = message_of(my_filter, 1, where="a model", shape_hint="Write the shapes.")
    assert text.startswith("my_filter raised ValueError: matmul: Input operand 1 has a mismatch")
    assert "(in my_filter, line " in text and "of test_student_code.py: `return S @ S`)" in text
    assert text.endswith(", on a model. Write the shapes.")


def test_an_exception_whose_str_fails_and_a_long_message() -> None:
    class Odd(Exception):
        def __str__(self):
            raise RuntimeError("cannot")

    def odd(x):
        raise Odd()

    def verbose(x):
        raise ValueError("the same sentence again. " * 200)

    assert "odd raised Odd: (its message could not be shown: its __str__ failed)" in message_of(
        odd, 1)
    assert len(message_of(verbose, 1)) < 400


@pytest.mark.parametrize(("stop", "phrase"), [
    (SystemExit(3), "leave called exit() (SystemExit) (in leave, line"),
    (KeyboardInterrupt(), "leave was interrupted (KeyboardInterrupt) (in leave, line"),
])
def test_exit_and_interrupt_inside_the_function_are_one_line(stop, phrase) -> None:
    def leave(x):
        raise stop

    assert phrase in message_of(leave, 1)


def test_a_call_that_does_not_fit_the_signature_names_the_arguments() -> None:
    def my_filter(y, A, C):
        return y

    text = message_of(my_filter, 1, 2, 3, 4, arg_names=("y", "A", "C", "Q"))
    assert text.startswith("my_filter could not be called with the arguments (y, A, C, Q): ")
    assert "my_filter() takes 3 positional arguments but 4 were given" in text
    assert text.endswith(". Its first line must be `def my_filter(y, A, C, Q):`")


def test_not_a_function_and_an_async_function() -> None:
    assert message_of(np.zeros(3), name="my_filter") == (
        "my_filter must be a function (its name, without parentheses), got a ndarray")

    async def my_filter(y):
        return y

    assert "my_filter is an async function (async def)" in message_of(my_filter, 1)


def test_a_function_that_replaces_the_packs_code_is_refused_and_undone() -> None:
    original, inv = metrics.mse, np.linalg.inv

    def cheat(x):
        metrics.mse = lambda *args: 0.0
        np.linalg.inv = lambda a: a
        return x

    text = message_of(cheat, 1)
    assert text.startswith("cheat replaced lqe_helpers.metrics.mse, numpy.linalg.inv (now "
                           "restored)")
    assert metrics.mse is original and np.linalg.inv is inv


# ------------------------------------------------------------------------------------------
# call: the time limit, on both paths
# ------------------------------------------------------------------------------------------


def endless(x):
    total = 0
    while True:
        try:
            total += 1
        except Exception:      # a student's own except cannot swallow the time limit
            pass


def swallowing(x):
    try:
        while True:
            pass
    except:  # noqa: E722 - a bare except, as a student might write it
        return x


@pytest.mark.parametrize("function", [endless, swallowing])
def test_the_time_limit_stops_an_endless_loop_in_the_main_thread(function) -> None:
    """Even one whose bare ``except:`` swallows the stop and returns: it took too long."""
    assert threading.current_thread() is threading.main_thread()
    start = time.monotonic()
    with pytest.raises(TimedOut, match=rf"^{function.__name__} did not return within 0.3 s"):
        call(function, 1)
    assert time.monotonic() - start < LIMIT + 0.5
    if function is endless:
        with pytest.raises(TimedOut, match=r"\(in endless, line \d+ of test_student_code.py: "
                                           r"`(while True:|total \+= 1)`\)"):
            call(function, 1)


def test_the_previous_alarm_handler_and_timer_are_restored() -> None:
    def handler(signum, frame):
        raise AssertionError("the outer timer fired during the test")

    previous = signal.signal(signal.SIGALRM, handler)
    try:
        signal.setitimer(signal.ITIMER_REAL, 30.0)
        with pytest.raises(TimedOut):
            call(endless, 1)
        assert call(len, [1, 2]) == 2
        assert signal.getsignal(signal.SIGALRM) is handler
        remaining, _ = signal.getitimer(signal.ITIMER_REAL)
        assert 28.0 < remaining <= 30.0
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def test_off_the_main_thread_a_worker_thread_is_stopped() -> None:
    outcome: dict[str, object] = {}

    def run() -> None:
        start = time.monotonic()
        try:
            call(endless, 1)
        except TimedOut as error:
            outcome["message"] = str(error)
        outcome["seconds"] = time.monotonic() - start
        outcome["result"] = call(lambda x: 2 * x, 21)

    thread = threading.Thread(target=run)
    thread.start()
    thread.join(10)
    assert outcome["message"].startswith("endless did not return within 0.3 s (in endless, line")
    assert outcome["seconds"] < LIMIT + 1.5
    assert outcome["result"] == 42


def test_without_sigalrm_the_worker_thread_is_used(monkeypatch) -> None:
    monkeypatch.delattr(signal, "setitimer")
    with pytest.raises(TimedOut, match=r"^endless did not return within 0\.3 s \(in endless, line"):
        call(endless, 1)
    assert call(lambda x: x + 1, 1) == 2
    text = message_of(lambda x: 1 / x, 0)
    assert text.startswith("your function raised ZeroDivisionError: division by zero (in "
                           "<lambda>, line")


def test_the_time_limit_must_be_a_positive_number() -> None:
    with pytest.raises(ValueError, match="time_limit must be a number of seconds > 0, got 0"):
        student_code.call(len, [], time_limit=0)
    assert student_code.TIME_LIMIT == calling.TIME_LIMIT == 5.0


# ------------------------------------------------------------------------------------------
# result_array: a real number array, or one line
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("value", "phrase"), [
    (None, "returned None (nothing). Does the function end by returning its result?"),
    ((np.zeros((3, 2)), np.eye(2)), "returned a tuple of 2 items (shapes (3, 2), (2, 2)): give "
                                    "only one array"),
    ([[0.0, 1.0]] * 3, "returned a Python list, not a NumPy array"),
    (1 + 0j, "returned a complex number ((1+0j)): the imaginary part is never dropped"),
    (np.zeros((3, 2), dtype=complex), "returned complex numbers (dtype complex128)"),
    (True, "returned True (a boolean), not a number"),
    (np.ones((3, 2), dtype=bool), "returned an array of True/False values (booleans)"),
    ("0.5", "returned text ('0.5'), not a number"),
    (np.array([[1, None], [2, 3], [4, 5]], dtype=object),
     "returned an array of Python objects (dtype object)"),
    ({"p": 1}, "returned a dict ({'p': 1}), not a NumPy array of numbers"),
    (np.ma.zeros((3, 2)), "returned a masked array"),
    (np.zeros((2, 3)), "returned an array of shape (2, 3), not of shape (3, 2)"),
    (np.array([[0, 1], [np.nan, 2], [3, 4]]), "returned NaN (not a number) or an infinite "
                                              "value at index (1, 0)"),
    (np.full((3, 2), 1e200), "returned values too large to square (up to 1e+200)"),
])
def test_result_array_refuses_each_kind_of_wrong_result(value, phrase) -> None:
    with pytest.raises(StudentCodeError) as info:
        student_code.result_array(value, name="f", what="an array of shape (3, 2)", shape=(3, 2),
                                  where="a test")
    assert phrase in str(info.value)
    assert str(info.value).endswith("; it must return an array of shape (3, 2) (on a test)")


@pytest.mark.filterwarnings("ignore:the matrix subclass:PendingDeprecationWarning")
def test_result_array_accepts_real_numbers_and_nan_where_allowed() -> None:
    assert student_code.result_array(3, name="f", what="a number", shape=()) == 3.0
    assert student_code.result_array(np.float32(0.5), name="f", what="a number") == 0.5
    matrix = student_code.result_array(np.matrix([[1, 2]]), name="f", what="a row")
    assert type(matrix) is np.ndarray and matrix.dtype == float
    assert student_code.result_array(np.zeros((4, 2)), name="f", what="z",
                                     shape=(None, 2)).shape == (4, 2)
    with_nan = np.array([np.nan, 1.0])
    assert np.isnan(student_code.result_array(with_nan, name="f", what="z", allow_nan=True)[0])
    assert student_code.array_problem(np.array([np.nan, np.inf]), allow_nan=True) == (
        "an infinite value at index 1")
    assert student_code.array_problem(10**400).startswith("a number too large to square")


# ------------------------------------------------------------------------------------------
# save and load
# ------------------------------------------------------------------------------------------

SCALE = 2.0


def doubled(x):
    """Twice x, as an array."""
    return 2 * np.asarray(x)


def scaled(x):
    return SCALE * helper(x)


def helper(x):
    return x


def shadows_sum(x):
    return sum(x)


def test_save_writes_the_source_and_returns_the_function_loaded_back(tmp_path, capsys) -> None:
    folder = tmp_path / "my_functions"
    loaded = student_code.save(doubled, folder)
    assert capsys.readouterr().out == (f"doubled is saved in {folder / 'doubled.py'}, where "
                                       f"student_code.load('doubled') finds it\n")
    text = (folder / "doubled.py").read_text("utf-8")
    assert text.splitlines()[0] == student_code.SAVE_HEADER
    assert "import numpy as np\n\n\ndef doubled(x):\n    \"\"\"Twice x, as an array.\"\"\"" in text
    assert (folder / "doubled.py").stat().st_mode & 0o777 == 0o644
    assert loaded is not doubled and loaded(21) == 42
    assert "SCALE" not in loaded.__globals__ and loaded.__globals__["np"] is np
    assert student_code.load("doubled", folder)(1) == 2


def gain(P, C, R):
    return P @ C.T @ np.linalg.inv(C @ P @ C.T + R)


def uses_a_helper(P, C, R):
    return 2 * gain(P, C, R) + twice(1)


def twice(x):
    return gain(np.eye(1), np.eye(1), np.eye(1)) * 0 + 2 * x


def test_save_keeps_the_helper_functions_of_the_notebook_it_calls(tmp_path, capsys) -> None:
    """The seventh trial (F2): a right my_filter that calls a helper of its own cell printed
    ✓, then could not be saved ("uses gain from the notebook"). A helper defined with def at
    the top of a cell, under the same rule, is saved with it (each once)."""
    loaded = student_code.save(uses_a_helper, tmp_path)
    text = (tmp_path / "uses_a_helper.py").read_text("utf-8")
    assert text.count("def gain(") == 1 and text.count("def twice(") == 1
    assert text.index("def gain(") < text.index("def uses_a_helper(")
    P, C, R = np.eye(2), np.ones((1, 2)), np.eye(1)
    assert np.allclose(loaded(P, C, R), uses_a_helper(P, C, R))
    assert student_code.load("uses_a_helper", tmp_path)(P, C, R).shape == (2, 1)


def test_save_rewrites_only_a_changed_file_of_its_own(tmp_path, capsys) -> None:
    folder = tmp_path / "my_functions"
    student_code.save(doubled, folder)
    path = folder / "doubled.py"
    before = path.stat().st_mtime_ns
    time.sleep(0.01)
    student_code.save(doubled, folder)
    first, again = capsys.readouterr().out.splitlines()
    assert first == again                          # the same line: a notebook's output is fixed
    assert path.stat().st_mtime_ns == before
    path.write_text(f"{student_code.SAVE_HEADER}\ndef doubled(x):\n    return 0\n", "utf-8")
    assert student_code.save(doubled, folder)(2) == 4
    assert sorted(os.listdir(folder)) == ["doubled.py"]        # no temporary file left


def test_save_never_replaces_a_file_it_did_not_write(tmp_path) -> None:
    folder = tmp_path / "my_functions"
    folder.mkdir()
    mine = folder / "doubled.py"
    mine.write_text("def doubled(x):\n    return 'my own'\n", "utf-8")
    with pytest.raises(StudentCodeError, match=r"doubled.py was not written by save \(its "
                                               r"first line is not save's header\), so it is "
                                               r"left as it is"):
        student_code.save(doubled, folder)
    assert mine.read_text("utf-8") == "def doubled(x):\n    return 'my own'\n"
    mine.unlink()
    mine.symlink_to(tmp_path / "elsewhere.py")
    with pytest.raises(StudentCodeError, match="is not a plain file"):
        student_code.save(doubled, folder)
    assert not (tmp_path / "elsewhere.py").exists()


def test_save_refuses_names_from_the_notebook(tmp_path, monkeypatch) -> None:
    with pytest.raises(StudentCodeError, match=r"^scaled uses SCALE from the notebook; "
                                               r"a saved function may use only its arguments"):
        student_code.save(scaled, tmp_path)
    monkeypatch.setitem(globals(), "sum", lambda x: 0)       # the notebook shadows a built-in
    with pytest.raises(StudentCodeError, match=r"^shadows_sum uses sum from the notebook"):
        student_code.save(shadows_sum, tmp_path)
    with pytest.raises(StudentCodeError, match="save needs a function written with def"):
        student_code.save(lambda x: x, tmp_path)

    def outer():
        factor = 2

        def closure(x):
            return factor * x
        return closure

    with pytest.raises(StudentCodeError, match="closure is defined inside another function"):
        student_code.save(outer(), tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_save_that_cannot_write_changes_nothing(tmp_path) -> None:
    blocked = tmp_path / "my_functions"
    blocked.write_text("a file where the folder should be", "utf-8")
    with pytest.raises(StudentCodeError, match=r"^save could not write "):
        student_code.save(doubled, blocked)
    assert blocked.read_text("utf-8") == "a file where the folder should be"


def test_save_and_load_use_my_functions_in_the_working_folder(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    student_code.save(doubled)
    assert (tmp_path / "my_functions" / "doubled.py").is_file()
    assert student_code.load("doubled")(3) == 6


def test_load_of_a_missing_file_gives_a_stand_in_naming_the_notebook_that_writes_it(
        tmp_path, capsys) -> None:
    """The notebook runs on; every use of the function (a task, a check, an explorer) says
    in one line which notebook's task saves it."""
    expected = (r"my_filter is not saved yet: .*my_filter.py does not exist\. notebook 01 "
                r"\(the check after Task 1\) writes it when its check passes; run that first")
    stand_in = student_code.load("my_filter", tmp_path)
    assert stand_in.__name__ == "my_filter"
    assert re.search(expected, capsys.readouterr().out)
    with pytest.raises(NotSavedYet, match=expected):
        stand_in(np.zeros((3, 1)))
    with pytest.raises(NotSavedYet, match=expected):  # through call: the same one line
        student_code.call(stand_in, np.zeros((3, 1)))
    with pytest.raises(NotSavedYet, match="the notebook whose task defines other"):
        student_code.load("other", tmp_path)()
    with pytest.raises(ValueError, match="name must be a function's name"):
        student_code.load("../x", tmp_path)


@pytest.mark.parametrize(("text", "phrase"), [
    ("def f(x:\n", "f.py could not be read as Python: "),
    ("g = 1\n", "f.py does not define a function f"),
    ("import sys\nsys.exit()\n", "f.py called exit() (SystemExit) (line 2 of f.py: `sys.exit()`)"),
    ("while True:\n    pass\n", "f.py did not return within 0.2 s (line 1 of f.py"),
])
def test_load_reports_a_broken_file_in_one_line(tmp_path, monkeypatch, text, phrase) -> None:
    monkeypatch.setattr(calling, "TIME_LIMIT", 0.2)
    (tmp_path / "f.py").write_text(text, "utf-8")
    with pytest.raises(StudentCodeError) as info:
        student_code.load("f", tmp_path)
    assert phrase in str(info.value)
