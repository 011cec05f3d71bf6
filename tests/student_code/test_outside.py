"""What a student's code takes from outside the notebook (``student_code.outside``): a file it
reads, another program it runs. The fourth trial's loophole: numbers the pack computed in
another program, read from a file."""

from __future__ import annotations

import linecache
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import lqe_helpers
from lqe_helpers import checks, student_code
from lqe_helpers.student_code import outside


@pytest.fixture
def heard():
    """What this thread's code takes from outside while the test runs."""
    uses: list[str] = []
    with outside.watching(uses.append):
        yield uses


def test_reading_a_file_is_heard_and_writing_one_is_not(tmp_path, heard, monkeypatch):
    monkeypatch.chdir(tmp_path)
    np.save("answer.npy", np.eye(2))
    (tmp_path / "note.txt").write_text("written")
    assert heard == []
    np.load("answer.npy")
    os.close(os.open(tmp_path / "note.txt", os.O_RDONLY))
    assert heard == ["reads the file answer.npy", "reads the file note.txt"]


def test_the_installations_files_are_not_the_students(heard):
    with open(np.__file__, "rb"):
        pass
    with open(os.path.join(os.path.dirname(lqe_helpers.__file__), "model.py"), "rb"):
        pass
    assert heard == []


def test_a_data_file_in_the_packs_folder_or_in_shared_memory_is_the_students(heard):
    pack = os.path.dirname(lqe_helpers.__file__)
    assert not outside.installation_file(os.path.join(pack, "answer.npy"))
    assert not outside.installation_file("/dev/shm/answer.npy")
    assert outside.installation_file(os.path.join(pack, "model.py"))


def test_running_another_program_is_heard(heard):
    os.system("true")
    subprocess.run(["true"], check=True)
    assert heard == ["runs another program (os.system)", "runs another program (subprocess.Popen)"]


def test_another_threads_uses_are_not_this_threads(tmp_path, heard):
    path = tmp_path / "answer.npy"
    np.save(path, np.eye(2))
    worker = threading.Thread(target=np.load, args=(path,))
    worker.start()
    worker.join()
    assert heard == []


def test_the_innermost_listener_hears_and_unheard_hears_nothing(tmp_path, heard):
    path = tmp_path / "answer.npy"
    np.save(path, np.eye(2))
    inner: list[str] = []
    with outside.watching(inner.append):
        np.load(path)
    with outside.unheard():
        np.load(path)
    assert heard == [] and inner == [f"reads the file {path}"]


def test_a_function_task_that_reads_a_file_fails(tmp_path):
    """A ``my_filter`` returning numbers another program left in a file: the check cannot
    trace them, so the call fails, naming the file."""
    path = tmp_path / "answer.npy"
    np.save(path, np.eye(2))
    with pytest.raises(checks.CheckFailed, match=r"^my_filter reads the file .*answer\.npy: a "
                       r"task's function computes its result from its inputs"):
        checks.machinery.call_student(lambda: np.load(path), name="my_filter", where="")
    assert np.array_equal(student_code.call(lambda: np.load(path)), np.eye(2))  # no forbid


def test_a_function_task_that_runs_another_program_fails():
    def runs_the_pack_elsewhere():
        output = subprocess.run([sys.executable, "-c", "print(1)"], capture_output=True,
                                text=True, check=True).stdout
        return float(output)

    with pytest.raises(checks.CheckFailed, match=r"^my_filter runs another program"):
        checks.machinery.call_student(runs_the_pack_elsewhere, name="my_filter", where="")


def test_quoting_a_loaded_functions_source_reads_no_file(tmp_path, heard):
    """A traceback or warning through a loaded ``my_filter`` quotes its source: that is not a
    read of a file by the student's task cell."""
    def my_filter(y):
        return y

    student_code.save(my_filter, folder=tmp_path)
    student_code.load("my_filter", folder=tmp_path)
    path = str(tmp_path / "my_filter.py")
    assert "def my_filter(y):" in "".join(linecache.getlines(path))
    assert heard == []


def test_a_file_opened_to_be_written_afresh_is_not_read(tmp_path, heard):
    import tempfile
    with tempfile.NamedTemporaryFile("w+", dir=tmp_path, delete=False) as handle:
        handle.write("1")
    with open(tmp_path / "b.txt", "w+") as handle:
        handle.write("1")
    assert heard == []
    with open(tmp_path / "b.txt", "a+"):
        pass
    assert heard == [f"reads the file {tmp_path / 'b.txt'}"]


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
@pytest.mark.parametrize("how", ["sys.setprofile", "C's PyEval_SetProfile", "a thread",
                                 "code.replace", "ctypes", "marshal", "sys._getframe",
                                 "a traceback's frame", "the memory", "the pack's source",
                                 "eval"])
def test_a_function_task_that_leaves_the_watch_is_refused(how):
    """A function task's answer computed by the pack out of the watch's sight: with the
    profile hook off (switched off, or lost through C), in another thread, or by a copy of
    the pack's function under another file's name. Each passed before."""
    import ctypes
    import gc
    import marshal
    import types

    from lqe_helpers import model

    def my_transition_matrix(dt):
        found = []
        if how == "sys.setprofile":
            sys.setprofile(None)
        elif how == "C's PyEval_SetProfile":
            ctypes.pythonapi.PyEval_SetProfile(None, None)
        if how == "ctypes":
            ctypes.CDLL(None).getpid()
        elif how == "marshal":
            copy = lambda dt: None  # noqa: E731 - its code is replaced just below
            copy.__code__ = marshal.loads(marshal.dumps(model.transition_matrix.__code__))
        elif how == "sys._getframe":
            sys._getframe(1)
        elif how == "a traceback's frame":
            try:
                raise ValueError
            except ValueError as error:
                assert error.__traceback__.tb_frame is not None
        elif how == "the memory":
            gc.get_objects()
        elif how == "eval":
            return np.array(eval("model.transition_matrix(dt)"))  # the seventh trial (L3)
        if how == "the pack's source":  # the seventh trial (L1): run under another name
            with open(model.__file__, encoding="utf-8") as source:
                namespace = {"__name__": "mine"}
                exec(compile(source.read().replace("from .", "from lqe_helpers."),
                             "mine.py", "exec"), namespace)
            found.append(namespace["transition_matrix"](dt))
        elif how == "a thread":
            thread = threading.Thread(target=lambda: found.append(model.transition_matrix(dt)))
            thread.start()
            thread.join()
        elif how == "code.replace":
            copy = types.FunctionType(
                model.transition_matrix.__code__.replace(co_filename="mine.py"),
                model.transition_matrix.__globals__)
            found.append(copy(dt))
        else:
            found.append(model.transition_matrix(dt))
        return np.array(found[0])

    said = {"sys.setprofile": "switches off the pack's watch of the functions it runs",
            "C's PyEval_SetProfile": "uses C code through ctypes",
            "a thread": "starts another thread",
            "code.replace": "makes a code object by hand",
            "ctypes": "uses C code through ctypes", "marshal": "loads code with marshal",
            "sys._getframe": "looks into the frames of the code that runs",
            "a traceback's frame": "looks into the frames of a traceback",
            "the memory": "searches the memory for objects",
            "the pack's source": "makes code from text", "eval": "makes code from text"}[how]
    with pytest.raises(checks.CheckFailed, match=f"my_transition_matrix {said}"):
        checks.check_transition_matrix(my_transition_matrix, model.transition_matrix(0.01))
