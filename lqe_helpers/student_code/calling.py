"""Calling a student's function: copies of its inputs, a time limit, one line per failure."""

from __future__ import annotations

import contextlib
import functools
import inspect
import os
import signal
import sys
import threading
import types
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from .errors import NotWrittenYet, StudentCodeError, TimedOut, error_text, location
from .outside import HEARING, LOST_WATCH, UNTRACEABLE, c_call_use, dropping, starts_a_program
from .outside import watching as watching_outside
from .running import is_time_limit_hook, run_in_thread, run_with_alarm

__tracebackhide__ = True  # pytest: leave these frames out of a failure's traceback

#: Seconds a student's function may run in one call before it is stopped.
TIME_LIMIT = 5.0
#: What the "not written yet" message tells the student to do.
NOT_WRITTEN_ADVICE = ("replace the line `raise NotImplementedError` with your code, run its "
                      "cell, then {rerun}")


def function_name(function: object, *, yours: bool = False) -> str:
    """The name a message gives the student's function: ``my_filter``, or "your function"
    for a lambda; with ``yours``, "your my_filter" (and still "your function")."""
    name = getattr(function, "__name__", None)
    if not (isinstance(name, str) and name.isidentifier()):
        return "your function"
    return f"your {name}" if yours else name


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

#: How many calls of :func:`call` are running now (in any thread).
_depth = 0


#: Code of the pack that runs around a student's function, not as its answer: modules
#: whose every function is such machinery, and single functions registered by
#: :func:`machinery_function` (the time limit's signal handler, a stand-in, a recorder).
MACHINERY_MODULES = ("guards.py", "running.py")
_MACHINERY_CODES: set[types.CodeType] = {function.__code__ for function in HEARING}


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


@machinery_function
def inside_call() -> bool:
    """Whether a :func:`call` is running, which reports its function's errors itself."""
    return _depth > 0


@machinery_function
def reported(error: BaseException, name: str, hint: str = "") -> StudentCodeError:
    """The one-line StudentCodeError of :func:`call` for ``error``, raised by ``name``, with
    ``hint`` (what to do) after it."""
    return _raised(error, name, "", None, hint, "", "run this cell again")


def _working_folder() -> str | None:
    try:
        return os.getcwd()
    except OSError:  # the working folder was deleted
        return None


def _restore_working_folder(before: str | None) -> str | None:
    """Go back to the working folder ``before`` if the call left it; the folder it left."""
    now = _working_folder()
    if before is None or now == before:
        return None
    try:
        os.chdir(before)
    except OSError:  # deleted meanwhile: nothing to go back to
        pass
    return now or "a folder that no longer exists"


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
        self.outside = ""   # what it took from outside the notebook (student_code.outside)

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
                try:
                    if previous is not None:
                        previous(frame, event, arg)
                    if event == "call":
                        name = self.forbidden(frame)
                        if name:
                            self.tripped = self.tripped or name
                            raise _Tripped
                        if self.pack and starts_a_program(frame.f_code.co_filename):
                            outside("runs another program")
                    elif event == "c_call" and self.pack and c_call_use(arg):
                        outside(c_call_use(arg))
                except BaseException:  # Python drops a hook that raises: not the student's doing
                    dropping()
                    raise

            @machinery_function
            def outside(what: str) -> None:
                self.outside = self.outside or what
                raise _Tripped

            with watching_outside(outside) if self.pack else contextlib.nullcontext():
                sys.setprofile(profile)
                try:
                    result = function(*args)
                except _Tripped:
                    return None
                else:
                    if self.pack and not _watch_kept(profile):
                        self.outside = self.outside or LOST_WATCH
                    return result
                finally:
                    sys.setprofile(previous)

        watched.__name__ = getattr(function, "__name__", "watched")
        return watched


@machinery_function
def _watch_kept(profile: Callable) -> bool:
    """Whether the profile hook ``profile`` still watches this thread, or the time limit's
    (:mod:`.running`) took it over to stop the call."""
    current = sys.getprofile()
    return current is profile or is_time_limit_hook(current)


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


#: The methods that make a new object: a message names their class.
_CONSTRUCTORS = (".__init__", ".__post_init__", ".__new__")


def shown_function(name: str) -> str:
    """A pack function's qualified ``name`` as a message shows it: a constructor as its
    class ("lqe_helpers.scenario.Scenario (making a new one)")."""
    for suffix in _CONSTRUCTORS:
        if name.endswith(suffix):
            return f"{name.removesuffix(suffix)} (making a new one)"
    return name


def pack_name(frame: types.FrameType) -> str:
    """"lqe_helpers.filter._covariance_sequence" for a frame of the pack's code: the module
    named by the code's file, whatever name the module was run under (a pack file imported
    as another module is the pack's all the same)."""
    return f"{_module_of(frame.f_code.co_filename)}.{frame.f_code.co_qualname}"


@functools.lru_cache(maxsize=1024)
def _module_of(filename: str) -> str:
    """"lqe_helpers.filter" for the pack's file .../lqe_helpers/filter.py."""
    relative = os.path.relpath(os.path.realpath(filename), os.path.dirname(
        _PACK_FOLDER.rstrip(os.sep)))
    parts = os.path.splitext(relative)[0].split(os.sep)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)




def _copy(value: object) -> object:
    return value.copy() if isinstance(value, np.ndarray) else value


def call(function: Callable, *args: object, name: str | None = None, where: str = "",
         time_limit: float | None = None, arg_names: Sequence[str] | None = None,
         hint: str = "", shape_hint: str = "", rerun: str = "run this check again",
         forbid: Sequence[Callable] = (), forbid_pack: bool = False,
         allow: Sequence[Callable] = (),
         failure: type[StudentCodeError] = StudentCodeError) -> object:
    """Call a student's function on copies of ``args`` under a time limit.

    Array arguments are copied, so the student's function cannot change the caller's
    data. The function runs for at most ``time_limit`` seconds: in the main thread where
    the system has ``SIGALRM`` (Linux, macOS: a Jupyter kernel, pytest) a timer stops it,
    and the previous SIGALRM handler and timer are restored afterwards (an outer timer is
    re-armed with its remaining time, late by at most this call's duration). Elsewhere
    (off the main thread, or on Windows) the function runs in a worker thread that is
    stopped the same way; a thread stuck inside one long C call (a huge numpy operation,
    ``time.sleep``) is then left to finish in the background while this call reports the
    time-out. Either way the stop is raised again at every line the function runs until it
    has ended, so not even a bare ``except:`` inside a loop outlasts it
    (:mod:`~lqe_helpers.student_code.running`); only Python code is stopped: a single numpy
    call runs to its end.

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
    failure : subclass of StudentCodeError
        What a failure other than :class:`NotWrittenYet` and :class:`TimedOut` raises: a
        check passes :class:`~lqe_helpers.student_code.errors.CheckFailed`.

    Returns
    -------
    object
        What the function returned, unchecked (see :func:`result_array`).

    Warnings the function gives (numpy's "overflow encountered", say) are not printed: a
    failure's message quotes them; a call that returns drops them.

    Raises
    ------
    NotWrittenYet
        If it raised ``NotImplementedError``.
    StudentCodeError
        If ``function`` is not callable, raised any other exception (including
        ``SystemExit`` and ``KeyboardInterrupt``), did not return within the limit,
        changed an input in place (with ``arg_names``), replaced a function of the pack
        or of numpy (restored first), changed the working folder (changed back first),
        ran a function of ``forbid``, or is an ``async`` function. One line: the type,
        message and the line of the student's own code where it happened.
    """
    name = name or function_name(function)
    on = f", on {where}" if where else ""
    if not callable(function):
        raise failure(
            f"{name} must be a function (its name, without parentheses), got a "
            f"{type(function).__name__}")
    time_limit = TIME_LIMIT if time_limit is None else time_limit
    if not (isinstance(time_limit, (int, float)) and 0 < time_limit < float("inf")):
        raise ValueError(f"time_limit must be a number of seconds > 0, got {time_limit!r}")
    copies = tuple(_copy(arg) for arg in args)
    before, folder = _snapshot(), _working_folder()
    alarm = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
    run = run_with_alarm if alarm else run_in_thread
    watch = _Watch(forbid, pack=forbid_pack, allow=allow)
    global _depth
    _depth += 1
    try:
        # Recorded, not printed (the filters in force still apply: "error" still raises).
        with warnings.catch_warnings(record=True) as warned:
            kind, value = run(watch.wrap(function), copies, float(time_limit))
    finally:
        _depth -= 1
    replaced = _restore(before)
    moved = _restore_working_folder(folder)
    if watch.outside:
        raise failure(
            f"{name} {watch.outside}{on}: a task's function computes its result from its "
            f"inputs, in the notebook. {UNTRACEABLE}")
    if watch.tripped:
        raise failure(
            f"{name} runs the pack's own {shown_function(watch.tripped)}{on}: the task is to "
            f"write this step "
            f"yourself, from the equation, with NumPy (@, np.linalg), not to call the pack's "
            f"solution")
    if kind == "timeout":
        error = value if isinstance(value, BaseException) else None
        stopped = TimedOut(
            f"{name} did not return within {time_limit:g} s"
            f"{location(error.__traceback__) if error else ''}{on}: is there a loop that "
            f"never ends (a while loop whose condition never turns false), or one over far "
            f"more steps than its input has?")
        stopped.student_traceback = error.__traceback__ if error else None
        raise stopped
    if kind == "raised":
        assert isinstance(value, BaseException)
        hint = " ".join(part for part in (hint, _warnings_text(warned)) if part)
        raise _raised(value, name, on, arg_names, hint, shape_hint, rerun, failure)
    if moved:
        raise failure(
            f"{name} changed the working folder (os.chdir) to {moved} (now changed back){on}: "
            f"a function must compute its result, not move the notebook to another folder")
    if replaced:
        raise failure(
            f"{name} replaced {', '.join(replaced[:3])}{' …' * (len(replaced) > 3)} (now "
            f"restored){on}: a function must compute its result, not change the pack's or "
            f"numpy's code")
    if inspect.iscoroutine(value):
        value.close()
        raise failure(f"{name} is an async function (async def); write it with a "
                               f"plain def")
    if arg_names is not None:
        for label, given, original in zip(arg_names, copies, args, strict=False):
            if isinstance(original, np.ndarray) and not np.array_equal(
                    given, original, equal_nan=original.dtype.kind in "fc"):
                raise failure(
                    f"{name} changed its input {label} in place{on}. A function must leave "
                    f"its inputs unchanged: work on new arrays instead of modifying {label} "
                    f"(e.g. with += or an assignment to {label}[...])")
    return value


def _warnings_text(warned: list[warnings.WarningMessage]) -> str:
    """What the warnings a student's function gave say, for its failure's message."""
    said = list(dict.fromkeys(f"{type(item.message).__name__}: {error_text(item.message)}"
                              for item in warned))
    if not said:
        return ""
    more = f" and {len(said) - 2} more" if len(said) > 2 else ""
    return f"Before that it warned: {'; '.join(said[:2])}{more}."


def _raised(error: BaseException, name: str, on: str, arg_names: Sequence[str] | None,
            hint: str, shape_hint: str, rerun: str,
            failure: type[StudentCodeError] = StudentCodeError) -> StudentCodeError:
    """The ``failure`` reporting ``error``, raised by the student's function."""
    if isinstance(error, (failure, NotWrittenYet, TimedOut)):
        return error                      # already one line for the student
    if isinstance(error, StudentCodeError):  # a stand-in's or a guard's: its line, as failure
        reported = failure(str(error))
        reported.student_traceback = error.student_traceback or error.__traceback__
        return reported
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
    reported = failure(message)
    reported.student_traceback = error.__traceback__
    return reported

