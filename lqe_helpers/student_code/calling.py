"""Calling a student's function: copies of its inputs, a time limit, one line per failure."""

from __future__ import annotations

import ctypes
import functools
import inspect
import os
import signal
import sys
import threading
import time
import types
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from .errors import NotWrittenYet, StudentCodeError, TimedOut, error_text, location

__tracebackhide__ = True  # pytest: leave these frames out of a failure's traceback

#: Seconds a student's function may run in one call before it is stopped.
TIME_LIMIT = 5.0
#: What the "not written yet" message tells the student to do.
NOT_WRITTEN_ADVICE = ("replace the line `raise NotImplementedError` with your code, run its "
                      "cell, then {rerun}")


class _TimeIsUp(BaseException):
    """Raised inside a student's function when its time is up.

    A ``BaseException``, not an ``Exception``: the student's ``except Exception`` does
    not swallow it.
    """


def function_name(function: object) -> str:
    """The name a message gives the student's function ("your function" for a lambda)."""
    name = getattr(function, "__name__", None)
    return name if isinstance(name, str) and name.isidentifier() else "your function"


#: numpy modules whose attributes a student's function must leave alone, besides every
#: module of the pack (checked after each call).
_GUARDED_NUMPY = ("numpy", "numpy.linalg")


def _guarded_modules() -> list[types.ModuleType]:
    return [module for name, module in list(sys.modules.items())
            if (name == "lqe_helpers" or name.startswith("lqe_helpers.")
                or name in _GUARDED_NUMPY) and isinstance(module, types.ModuleType)]


def _snapshot() -> dict[types.ModuleType, dict[str, object]]:
    return {module: dict(vars(module)) for module in _guarded_modules()}


def _restore(before: dict[types.ModuleType, dict[str, object]]) -> list[str]:
    """Put back attributes of the guarded modules that were replaced or deleted.

    Returns their names. New attributes (a submodule imported on first use) are left, and
    so are dunder names (``__warningregistry__`` and the like change on their own).
    """
    changed = []
    for module, names in before.items():
        now = vars(module)
        for key in [key for key, value in names.items() if now.get(key, _MISSING) is not value]:
            if not key.startswith("__"):
                changed.append(f"{module.__name__}.{key}")
                setattr(module, key, names[key])
    return sorted(changed)


_MISSING = object()


def _run_with_alarm(function: Callable, args: tuple, limit: float) -> tuple[str, object]:
    """``function(*args)`` stopped after ``limit`` s by SIGALRM (main thread only)."""
    state = {"armed": True, "fired": False}

    def on_alarm(signum: int, frame: object) -> None:
        if state["armed"]:
            state["fired"] = True
            raise _TimeIsUp

    machinery_function(on_alarm)
    previous = signal.signal(signal.SIGALRM, on_alarm)
    outer_delay, outer_interval = signal.setitimer(signal.ITIMER_REAL, limit)
    start = time.monotonic()
    try:
        outcome: tuple[str, object] = ("returned", function(*args))
    except _TimeIsUp as error:
        outcome = ("timeout", error)
    except BaseException as error:  # reported to the student, not hidden
        outcome = ("raised", error)
    finally:
        state["armed"] = False
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, signal.SIG_DFL if previous is None else previous)
        if outer_delay:  # an outer timer (e.g. pytest-timeout's) runs on, a little late
            remaining = max(outer_delay - (time.monotonic() - start), 1e-3)
            signal.setitimer(signal.ITIMER_REAL, remaining, outer_interval)
    if state["fired"] and outcome[0] != "timeout":   # swallowed by a bare `except:`
        outcome = ("timeout", outcome[1] if outcome[0] == "raised" else None)
    return outcome


def _run_in_thread(function: Callable, args: tuple, limit: float) -> tuple[str, object]:
    """``function(*args)`` in a worker thread; after ``limit`` s it is sent :class:`_TimeIsUp`."""
    box: dict[str, tuple[str, object]] = {}

    def target() -> None:
        try:
            box["outcome"] = ("returned", function(*args))
        except _TimeIsUp as error:
            box["outcome"] = ("timeout", error)
        except BaseException as error:  # reported to the student
            box["outcome"] = ("raised", error)

    worker = threading.Thread(target=target, name="student code", daemon=True)
    worker.start()
    try:
        worker.join(limit)
    except KeyboardInterrupt:  # the kernel was interrupted while waiting
        _stop_thread(worker, KeyboardInterrupt)
        worker.join(1.0)
        return box.get("outcome", ("raised", KeyboardInterrupt()))
    if worker.is_alive():
        _stop_thread(worker, _TimeIsUp)
        worker.join(1.0)
        outcome = box.get("outcome")
        return ("timeout", outcome[1] if outcome and outcome[0] != "returned" else None)
    return box["outcome"]


def _stop_thread(worker: threading.Thread, kind: type[BaseException]) -> None:
    """Raise ``kind`` inside ``worker`` at its next line of Python (CPython only)."""
    try:
        ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(worker.ident),
                                                   ctypes.py_object(kind))
    except (AttributeError, TypeError):  # not CPython: the thread runs on in the background
        pass


class _Tripped(BaseException):
    """Raised inside a student's function when it runs a forbidden function of the pack."""


class _Watch:
    """Notices whether a student's function runs a function of the pack it may not.

    A profile hook (``sys.setprofile``, in the thread that runs the student's code) sees
    every Python function call. Entering a forbidden function's code records its name and
    raises :class:`_Tripped`, which ``except Exception`` cannot swallow; the record stands
    even if a bare ``except:`` swallows that exception too. Forbidden are the functions of
    ``forbid`` and, with ``pack=True``, every function whose code lies in the
    ``lqe_helpers`` package (public or private, any module, at any depth), except those of
    ``allow`` (and whatever they call) and the machinery that wraps the student's function
    (:data:`MACHINERY`: a loaded function's input guard and call record, the time limit's
    handler, a not-yet-saved function's stand-in).
    """

    def __init__(self, forbid: Sequence[Callable], pack: bool = False,
                 allow: Sequence[Callable] = ()) -> None:
        self.codes = {_code_of(function, "forbid"): _qualified(function)
                      for function in forbid}
        self.allowed = frozenset(_code_of(function, "allow") for function in allow)
        self.pack = pack
        self.tripped = ""

    def forbidden(self, frame: types.FrameType) -> str:
        """The qualified name of ``frame``'s function if the student may not run it, or ""."""
        code = frame.f_code
        if code in self.codes:
            return self.codes[code]
        if not self.pack or code in self.allowed or not in_pack(code.co_filename):
            return ""
        if machinery(code):
            return ""
        caller = frame.f_back
        while caller is not None:  # a function an allowed one calls is allowed
            if caller.f_code in self.allowed:
                return ""
            caller = caller.f_back
        return pack_name(frame)

    def wrap(self, function: Callable) -> Callable:
        if not self.codes and not self.pack:
            return function

        def watched(*args: object) -> object:
            previous = sys.getprofile()

            def profile(frame: types.FrameType, event: str, arg: object) -> None:
                if previous is not None:
                    previous(frame, event, arg)
                if event == "call":
                    name = self.forbidden(frame)
                    if name:
                        self.tripped = self.tripped or name
                        raise _Tripped

            sys.setprofile(profile)
            try:
                return function(*args)
            except _Tripped:
                return None
            finally:
                sys.setprofile(previous)

        watched.__name__ = getattr(function, "__name__", "watched")
        return watched


def _code_of(function: Callable, parameter: str) -> types.CodeType:
    code = getattr(inspect.unwrap(function), "__code__", None)
    if code is None:
        raise ValueError(f"{parameter} must hold Python functions, got {function!r}")
    return code


def _qualified(function: Callable) -> str:
    return f"{function.__module__}.{function.__qualname__}"


#: The pack's folder (``lqe_helpers``), with a trailing separator.
_PACK_FOLDER = os.path.join(os.path.realpath(Path(__file__).resolve().parent.parent), "")


@functools.lru_cache(maxsize=4096)
def in_pack(filename: str) -> bool:
    """Whether a code object's ``filename`` lies inside the ``lqe_helpers`` package."""
    return not filename.startswith("<") and os.path.realpath(filename).startswith(_PACK_FOLDER)


def pack_name(frame: types.FrameType) -> str:
    """"lqe_helpers.filter._covariance_sequence" for a frame of the pack's code."""
    module = frame.f_globals.get("__name__", "lqe_helpers")
    return f"{module}.{frame.f_code.co_qualname}"


#: Code of the pack that runs around a student's function, not as its answer: modules
#: whose every function is such machinery, and single functions registered by
#: :func:`machinery_function` (the time limit's signal handler, a stand-in, a recorder).
MACHINERY_MODULES = ("guards.py",)
_MACHINERY_CODES: set[types.CodeType] = set()


def machinery_function(function: Callable) -> Callable:
    """Mark ``function`` (of the pack) as machinery a student's function may run through.

    Its own code, not what it wraps (a wrapper's ``__wrapped__`` is the student's function).
    """
    _MACHINERY_CODES.add(function.__code__)  # type: ignore[attr-defined]
    return function


def machinery(code: types.CodeType) -> bool:
    """Whether ``code`` is machinery of :data:`MACHINERY_MODULES` or :func:`machinery_function`."""
    return code in _MACHINERY_CODES or (
        os.path.basename(code.co_filename) in MACHINERY_MODULES
        and os.path.dirname(os.path.realpath(code.co_filename)) == _HERE)


_HERE = os.path.dirname(os.path.realpath(__file__))


def _copy(value: object) -> object:
    return value.copy() if isinstance(value, np.ndarray) else value


def call(function: Callable, *args: object, name: str | None = None, where: str = "",
         time_limit: float | None = None, arg_names: Sequence[str] | None = None,
         hint: str = "", shape_hint: str = "", rerun: str = "run this check again",
         forbid: Sequence[Callable] = (), forbid_pack: bool = False,
         allow: Sequence[Callable] = ()) -> object:
    """Call a student's function on copies of ``args`` under a time limit.

    Array arguments are copied, so the student's function cannot change the caller's
    data. The function runs for at most ``time_limit`` seconds: in the main thread where
    the system has ``SIGALRM`` (Linux, macOS: a Jupyter kernel, pytest) a timer raises an
    exception inside it that its own ``except Exception`` cannot swallow, and the previous
    SIGALRM handler and timer are restored afterwards (an outer timer is re-armed with its
    remaining time, late by at most this call's duration). Elsewhere (off the main thread,
    or on Windows) the function runs in a worker thread that is sent the same exception
    after ``time_limit`` seconds; a thread stuck inside one long C call (a huge numpy
    operation, ``time.sleep``) is then left to finish in the background while this call
    reports the time-out. Either way only Python code is interrupted: a single numpy call
    runs to its end.

    These guard against a student's mistakes, not against deliberate cheating: code in the
    same process that switches the timer off or reads the caller's frames is not stopped.

    Parameters
    ----------
    function : callable
        The student's function.
    *args
        Its arguments.
    name : str, optional
        What messages call it; default its ``__name__``.
    where : str
        What it was called on, for messages ("a model with k = 3 states ...").
    time_limit : float, optional
        Seconds, > 0; default :data:`TIME_LIMIT`.
    arg_names : sequence of str, optional
        The names of its parameters: then an array argument changed in place is
        reported, and a call that does not fit its signature names them.
    hint, shape_hint : str
        Added to the message of any error, and of an error about shapes.
    rerun : str
        The last step of the "not written yet" advice.
    forbid : sequence of callables
        Functions of the pack that hold the task's answer (the engine's eq. (5), say).
        If the student's function runs one of them, directly or through anything it
        calls, the call fails: the task is to write it, not to call the pack's.
    forbid_pack : bool
        Forbid every function of the pack (any module, public or private, at any depth)
        but those of ``allow`` and the machinery around the student's function (see
        :class:`_Watch`). The checks of function tasks call with ``forbid_pack=True``.
    allow : sequence of callables
        With ``forbid_pack``: the pack's functions (and what they call) that the task's text
        lets the student use.

    Returns
    -------
    object
        What the function returned, unchecked (see :func:`result_array`).

    Raises
    ------
    NotWrittenYet
        If it raised ``NotImplementedError``.
    StudentCodeError
        If ``function`` is not callable, raised any other exception (including
        ``SystemExit`` and ``KeyboardInterrupt``), did not return within the limit,
        changed an input in place (with ``arg_names``), replaced a function of the pack
        or of numpy (restored first), ran a function of ``forbid``, or is an ``async``
        function. One line: the type,
        message and the line of the student's own code where it happened.
    """
    name = name or function_name(function)
    on = f", on {where}" if where else ""
    if not callable(function):
        raise StudentCodeError(
            f"{name} must be a function (its name, without parentheses), got a "
            f"{type(function).__name__}")
    time_limit = TIME_LIMIT if time_limit is None else time_limit
    if not (isinstance(time_limit, (int, float)) and 0 < time_limit < float("inf")):
        raise ValueError(f"time_limit must be a number of seconds > 0, got {time_limit!r}")
    copies = tuple(_copy(arg) for arg in args)
    before = _snapshot()
    alarm = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
    run = _run_with_alarm if alarm else _run_in_thread
    watch = _Watch(forbid, pack=forbid_pack, allow=allow)
    kind, value = run(watch.wrap(function), copies, float(time_limit))
    replaced = _restore(before)
    if watch.tripped:
        raise StudentCodeError(
            f"{name} runs the pack's own {watch.tripped}{on}: the task is to write this step "
            f"yourself, from the equation, with NumPy (@, np.linalg), not to call the pack's "
            f"solution")
    if kind == "timeout":
        error = value if isinstance(value, BaseException) else None
        failure = TimedOut(
            f"{name} did not return within {time_limit:g} s"
            f"{location(error.__traceback__) if error else ''}{on}: is there a loop that "
            f"never ends (a while loop whose condition never turns false), or one over far "
            f"more steps than its input has?")
        failure.student_traceback = error.__traceback__ if error else None
        raise failure
    if kind == "raised":
        assert isinstance(value, BaseException)
        raise _raised(value, name, on, arg_names, hint, shape_hint, rerun)
    if replaced:
        raise StudentCodeError(
            f"{name} replaced {', '.join(replaced[:3])}{' …' * (len(replaced) > 3)} (now "
            f"restored){on}: a function must compute its result, not change the pack's or "
            f"numpy's code")
    if inspect.iscoroutine(value):
        value.close()
        raise StudentCodeError(f"{name} is an async function (async def); write it with a "
                               f"plain def")
    if arg_names is not None:
        for label, given, original in zip(arg_names, copies, args, strict=False):
            if isinstance(original, np.ndarray) and not np.array_equal(
                    given, original, equal_nan=original.dtype.kind in "fc"):
                raise StudentCodeError(
                    f"{name} changed its input {label} in place{on}. A function must leave "
                    f"its inputs unchanged: work on new arrays instead of modifying {label} "
                    f"(e.g. with += or an assignment to {label}[...])")
    return value


def _raised(error: BaseException, name: str, on: str, arg_names: Sequence[str] | None,
            hint: str, shape_hint: str, rerun: str) -> StudentCodeError:
    """The StudentCodeError reporting ``error``, raised by the student's function."""
    if isinstance(error, StudentCodeError):  # already one line for the student (a stand-in's)
        return error
    if isinstance(error, NotImplementedError):
        return NotWrittenYet(
            f"{name} is not written yet: {NOT_WRITTEN_ADVICE.format(rerun=rerun)}")
    kind = type(error).__name__
    text = error_text(error)
    at = location(error.__traceback__)
    extra = f" {hint}" if hint else ""
    if shape_hint and isinstance(error, ValueError) and any(
            word in text for word in ("matmul", "shape", "broadcast", "aligned")):
        extra += f" {shape_hint}"
    if isinstance(error, SystemExit):
        message = (f"{name} called exit() (SystemExit){at}{on}: a function must return its "
                   f"result, not end the program")
    elif isinstance(error, KeyboardInterrupt):
        message = f"{name} was interrupted (KeyboardInterrupt){at}{on}"
    elif isinstance(error, TypeError) and not at and arg_names is not None:
        joined = ", ".join(arg_names)
        first = f" Its first line must be `def {name}({joined}):`" if name.isidentifier() else ""
        message = f"{name} could not be called with the arguments ({joined}): {text}.{first}"
    else:
        said = f": {text}" if text else ""
        message = f"{name} raised {kind}{said}{at}{on}.{extra}"
    failure = StudentCodeError(message)
    failure.student_traceback = error.__traceback__
    return failure

