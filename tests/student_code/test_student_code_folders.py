"""A student's function cannot move the notebook, nor send a saved function elsewhere (issue 27).

A function that called ``os.chdir`` used to pass its check, and ``student_code.save`` then
wrote into the other folder while printing ``my_functions/my_filter.py``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from reference_loops import student_lqe_filter as lqe_filter

from lqe_helpers import checks, student_code
from lqe_helpers.checks.machinery import CheckFailed
from lqe_helpers.student_code import StudentCodeError


def doubled(x):
    return 2 * np.asarray(x)


def test_a_function_that_changes_the_working_folder_fails_and_is_moved_back(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()

    def moves(x):
        os.chdir(elsewhere)
        return x

    with pytest.raises(StudentCodeError, match=(
            rf"^moves changed the working folder \(os.chdir\) to {elsewhere} \(now changed "
            rf"back\), on a test: a function must compute its result, not move the notebook")):
        student_code.call(moves, 1, where="a test")
    assert Path.cwd() == tmp_path


def test_a_right_filter_that_changes_the_working_folder_fails_its_check(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()

    def my_filter(y, A, C, Q, R, z0, P0):
        os.chdir(elsewhere)
        return lqe_filter(y, A, C, Q, R, z0, P0)

    with pytest.raises(CheckFailed, match=r"^my_filter changed the working folder"):
        checks.check_filter(my_filter)
    assert Path.cwd() == tmp_path


def test_save_writes_into_the_folder_of_the_sessions_first_save_or_load(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture) -> None:
    notebook, other = tmp_path / "notebook", tmp_path / "other"
    notebook.mkdir()
    other.mkdir()
    monkeypatch.chdir(notebook)
    student_code.load("my_filter")                   # the first load fixes the folder
    capsys.readouterr()
    os.chdir(other)                                  # a student's cell moves the kernel
    student_code.save(doubled)
    assert capsys.readouterr().out == ("doubled is saved in my_functions/doubled.py, where "
                                       "student_code.load('doubled') finds it\n")
    assert (notebook / "my_functions" / "doubled.py").is_file()
    assert not (other / "my_functions").exists()
    assert student_code.load("doubled")(2) == 4
    assert student_code.save_folder() == notebook / "my_functions"


def test_load_of_a_folder_says_it_is_a_folder(tmp_path: Path) -> None:
    (tmp_path / "my_filter.py").mkdir()
    with pytest.raises(StudentCodeError, match=(
            rf"^{tmp_path / 'my_filter.py'} is a folder, so my_filter cannot be loaded from "
            rf"it: rename or delete it")) as info:
        student_code.load("my_filter", tmp_path)
    assert "does not exist" not in str(info.value)
