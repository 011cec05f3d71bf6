"""Errors shown to students: one line of text, and only their own code in the traceback."""

from __future__ import annotations

import functools
import linecache
import os
import re
import site
import sys
import sysconfig
import traceback
import types
from pathlib import Path

import numpy as np

__tracebackhide__ = True  # pytest: leave these frames out of a failure's traceback

#: Longest piece of a student's error message quoted in ours (characters).
QUOTE_LENGTH = 200

#: The pack's folder: its code is never the student's.
_PACKAGE_DIR = Path(__file__).resolve().parent.parent


class OwnCodeTraceback:
    """Mixin for errors shown to students: Jupyter shows only their own code and the message.

    IPython asks an exception for ``_render_traceback_`` before formatting it. This one
    keeps the frames of the student's own code (cells, saved files; not the pack, numpy,
    IPython or the standard library) of the error itself and, after them, those of
    :attr:`student_traceback` (the error their function raised, if this reports one), and
    formats them as IPython would.
    """

    #: The traceback of the error the student's own code raised, if this error reports one.
    student_traceback: types.TracebackType | None = None

    def _render_traceback_(self) -> list[str]:
        assert isinstance(self, BaseException)
        self.__cause__ = None
        self.__suppress_context__ = True
        tb = own_frames(self.__traceback__, self.student_traceback)
        shell = _ipython_shell()
        if shell is None:
            return traceback.format_exception(type(self), self, tb)
        return shell.InteractiveTB.structured_traceback(type(self), self, tb, tb_offset=0)


class StudentCodeError(OwnCodeTraceback, Exception):
    """A student's function failed, hung or returned something unusable.

    Its message is one line, written for the student (what went wrong and where), with
    no library code in it. Explorers show it in their numbers line instead of a picture.
    The pack's one hierarchy of errors for students: checks raise its subclass
    :class:`CheckFailed` (``student_code.call(..., failure=CheckFailed)``).
    """


class CheckFailed(StudentCodeError, AssertionError):
    """A task's answer is not right yet; the message says what is wrong.

    An ``AssertionError``, so "Run All" stops at the wrong step. In Jupyter it shows the
    student's own cells and the message only (:class:`OwnCodeTraceback`). Every check of
    :mod:`lqe_helpers.checks` raises it (``checks.machinery`` re-exports it).
    """


class NotWrittenYet(CheckFailed):
    """The student's function still raises ``NotImplementedError`` (the stub)."""


class TimedOut(CheckFailed):
    """The student's function did not return within its time limit (and was stopped)."""


class NotSavedYet(StudentCodeError):
    """A function another notebook saves (``my_functions/<name>.py``) is not saved yet."""


def brief_errors() -> None:
    """In a notebook, show an input error the pack raises under the student's own code only.

    A ``ValueError`` or ``TypeError`` raised inside ``lqe_helpers`` (it names the input
    and what is allowed, e.g. a NaN passed to ``metrics.mse``) is then shown as the
    student's own frames and that one message, like a failed check, instead of pages of
    the pack's source; any other error keeps IPython's usual traceback. A ``NameError`` in
    a check cell's own line (``checks.check_x(value)`` with ``value`` never made) is one
    line saying which task cell makes it. It also starts the task-cell record
    (:func:`~lqe_helpers.student_code.task_runs.watch_task_cells`), by which each check
    judges what its current task cell made. The notebooks call this in their first code
    cell; nothing happens outside IPython.
    """
    shell = _ipython_shell()
    if shell is None:
        return
    from . import task_runs  # here: task_runs imports calling, which imports this module

    task_runs.watch_task_cells(shell)

    def handler(self, etype, value, tb, tb_offset=None):  # IPython's CustomTB signature
        advice = read_only_advice(value, tb)
        if advice is not None:
            etype, value = ValueError, ValueError(advice)
            stb = self.InteractiveTB.structured_traceback(etype, value, own_frames(tb),
                                                          tb_offset=0)
        elif issubclass(etype, NameError) and (
                message := task_runs.missing_name_message(value, tb)) is not None:
            stb = [f"NameError: {message}"]
            self._showtraceback(etype, value, stb)
            return stb
        elif _raised_by_the_pack(tb):
            stb = self.InteractiveTB.structured_traceback(etype, value, own_frames(tb),
                                                          tb_offset=0)
        else:
            stb = self.InteractiveTB.structured_traceback(etype, value, tb,
                                                          tb_offset=tb_offset)
        self._showtraceback(etype, value, stb)
        return stb

    shell.set_custom_exc((ValueError, TypeError, NameError), handler)


#: The target of an assignment that changes an array in place: ``P += Q``, ``P[0] = 1``.
_IN_PLACE = re.compile(r"^\s*([A-Za-z_]\w*)\s*(?:\[.*\])?\s*(?:[-+*/@%&|^]|//|\*\*)?=(?!=)")


def read_only_advice(error: BaseException, tb: types.TracebackType | None) -> str | None:
    """For numpy's "assignment destination is read-only" in the student's own line, what to do.

    "P_close is read-only: copy it (P = P_close.copy()) before changing P in place" when
    the line changes ``P`` in place and ``P`` is the array ``P_close`` of the pack's results
    (or a view of it); None for any other error.
    """
    text = error_text(error)
    if not isinstance(error, ValueError) or "read-only" not in text:
        return None
    last = None
    while tb is not None:
        last, tb = tb, tb.tb_next
    if last is None or not is_own_code(last.tb_frame.f_code.co_filename):
        return None
    frame = last.tb_frame
    match = _IN_PLACE.match(linecache.getline(frame.f_code.co_filename, last.tb_lineno))
    if match is None:
        return None
    target = match.group(1)
    array = frame.f_locals.get(target, frame.f_globals.get(target))
    names = {name: value for name, value in {**frame.f_globals, **frame.f_locals}.items()
             if name != target and not name.startswith("_") and isinstance(value, np.ndarray)}
    source = next((name for name, value in names.items() if value is array), None) or next(
        (name for name, value in names.items() if isinstance(array, np.ndarray)
         and np.may_share_memory(value, array)), None)
    if source is None:
        return (f"{target} is read-only (the pack's results cannot be changed): copy it "
                f"({target} = {target}.copy()) before changing {target} in place")
    return (f"{source} is read-only: copy it ({target} = {source}.copy()) before changing "
            f"{target} in place")


def _raised_by_the_pack(tb: types.TracebackType | None) -> bool:
    """Whether the last frame of ``tb`` (where the error was raised) is the pack's code."""
    last = None
    while tb is not None:
        last, tb = tb, tb.tb_next
    if last is None:
        return False
    path = os.path.realpath(last.tb_frame.f_code.co_filename)
    return path.startswith(os.path.join(os.path.realpath(_PACKAGE_DIR), ""))


def _ipython_shell():
    module = sys.modules.get("IPython")
    return module.get_ipython() if module is not None else None


@functools.cache
def _library_folders() -> tuple[str, ...]:
    paths = sysconfig.get_paths()
    folders = {paths[key] for key in ("stdlib", "platstdlib", "purelib", "platlib")
               if key in paths}
    folders.add(site.getusersitepackages())
    folders.add(str(_PACKAGE_DIR))
    return tuple(os.path.join(os.path.realpath(folder), "") for folder in folders)


@functools.lru_cache(maxsize=1024)
def is_own_code(filename: str) -> bool:
    """Whether ``filename`` (a code object's) holds the student's own code.

    Everything but the pack (``lqe_helpers``), the standard library and installed
    packages (numpy, IPython, ...) counts as the student's: notebook cells, saved
    functions, a script of their own.
    """
    if filename.startswith("<"):
        return not filename.startswith("<frozen")
    path = os.path.realpath(filename)
    return not path.startswith(_library_folders())


def own_frames(*tracebacks: types.TracebackType | None) -> types.TracebackType | None:
    """One traceback chain of the student's own frames of ``tracebacks``, in order."""
    kept = []
    for tb in tracebacks:
        while tb is not None:
            if is_own_code(tb.tb_frame.f_code.co_filename):
                kept.append(tb)
            tb = tb.tb_next
    chain = None
    for tb in reversed(kept):
        chain = types.TracebackType(chain, tb.tb_frame, tb.tb_lasti, tb.tb_lineno)
    return chain


def one_line(text: str, limit: int = QUOTE_LENGTH) -> str:
    text = " ".join(text.split())
    return text if len(text) <= limit else f"{text[: limit - 1]}…"


def error_text(error: BaseException) -> str:
    """``str(error)`` on one line, or a note if even that fails."""
    try:
        text = str(error)
    except BaseException:  # a student's __str__ may raise anything
        return "(its message could not be shown: its __str__ failed)"
    if not isinstance(text, str):
        return "(its message could not be shown)"
    return one_line(text)


def _place(filename: str, lineno: int, function: str) -> str:
    """Where a line of the student's code is: "in my_filter, line 7 of cell In[5]"."""
    shell = _ipython_shell()
    cells = getattr(getattr(shell, "compile", None), "_filename_map", {}) or {}
    if filename in cells:
        where = f"line {lineno} of cell In[{cells[filename]}]"
    else:
        where = f"line {lineno} of {Path(filename).name}"
    return where if function == "<module>" else f"in {function}, {where}"


def location(tb: types.TracebackType | None) -> str:
    """" (in my_filter, line 7 of cell In[5]: `S = C @ P`)" for the deepest own frame."""
    deepest = None
    while tb is not None:
        if is_own_code(tb.tb_frame.f_code.co_filename):
            deepest = tb
        tb = tb.tb_next
    if deepest is None:
        return ""
    code = deepest.tb_frame.f_code
    line = linecache.getline(code.co_filename, deepest.tb_lineno).strip()
    quoted = f": `{one_line(line, 80)}`" if line else ""
    return f" ({_place(code.co_filename, deepest.tb_lineno, code.co_name)}{quoted})"



def short_repr(value: object, limit: int = 40) -> str:
    """``repr(value)`` on one line, shortened; the type's name if even that fails."""
    try:
        text = repr(value)
    except BaseException:  # a student's __repr__ may raise anything
        text = type(value).__name__
    return one_line(text, limit)
