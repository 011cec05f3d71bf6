"""Running a student's function under a time limit that its own code cannot catch.

When the time is up, an exception (:class:`TimeIsUp`) is raised inside the function; but a
bare ``except:`` (or ``except BaseException: continue``) inside a loop would swallow one
exception and loop on forever. So from that moment the call is *stopped*, not only
interrupted: a trace function is installed on the student's own frames on the stack (and,
through ``sys.settrace``, on every frame they start) that raises :class:`TimeIsUp` again
at every line they run. An ``except`` handler's own first line, a ``finally`` that loops,
a nested ``try`` inside an ``except``: each raises again, so the exception climbs out of
every ``try`` until the call ends. Python switches a trace function off once it has
raised, so it is put back at every call and return (a profile hook, ``sys.setprofile``,
chained to any hook already there, such as ``forbid``'s) and every 50 ms (the timer
repeats), so a handler in the caller of a function that raised is traced again. Tracing
stops when the call returns; code before the deadline runs untraced.

Why this and not a child process: the function stays in the notebook's process, so
closures, lambdas and the notebook's globals work, nothing is pickled, and the student's
traceback (their own lines) is kept for the message. What it cannot stop: one long C call
(a huge numpy operation) runs to its end first; and a ``try`` whose handler catches the
re-raise of a ``try`` nested in its body, in one function, with no call in either handler,
inside an endless loop (tracing is off there until the next 50 ms tick, whose raise lands
in the inner ``try`` again).
"""

from __future__ import annotations

import ctypes
import signal
import sys
import threading
import time
import types
from collections.abc import Callable

from .errors import is_own_code

__tracebackhide__ = True  # pytest: leave these frames out of a failure's traceback

#: Seconds between the re-raises of a call that goes on after its time is up.
_REPEAT = 0.05
#: Seconds a worker thread is given to end once its time is up, before it is left behind.
_GRACE = 1.0


class TimeIsUp(BaseException):
    """Raised inside a student's function when its time is up, until the call ends.

    A ``BaseException``, not an ``Exception``: ``except Exception`` does not swallow it.
    """


class _Stopper:
    """Stops one call in one thread: once :attr:`stopping`, every line it runs raises."""

    def __init__(self) -> None:
        self.stopping = False
        self.home: types.FrameType | None = None   # the runner's frame, never traced
        self.chained: Callable | None = None        # the profile hook found at the deadline

    def trace(self, frame: types.FrameType, event: str, arg: object) -> object:
        if not self.stopping or not is_own_code(frame.f_code.co_filename):
            return None          # before the deadline, and the pack's or a library's code
        if event == "line":
            raise TimeIsUp
        return self.trace

    def profile(self, frame: types.FrameType, event: str, arg: object) -> None:
        if self.chained is not None:
            self.chained(frame, event, arg)
        if self.stopping:
            self.trace_stack(frame)

    def mark(self, frame: types.FrameType | None) -> None:
        """Trace the student's own frames from ``frame`` up to :attr:`home` (any thread)."""
        while frame is not None and frame is not self.home:
            if is_own_code(frame.f_code.co_filename):
                frame.f_trace = self.trace
                frame.f_trace_lines = True
            frame = frame.f_back

    def trace_stack(self, frame: types.FrameType | None) -> None:
        """:meth:`mark` ``frame``'s stack, and trace every new frame (this thread)."""
        self.mark(frame)
        sys.settrace(self.trace)

    def stop(self, frame: types.FrameType | None) -> None:
        """From now on every line of the call raises (see the module); in its own thread."""
        if not self.stopping:
            self.stopping = True
            current = sys.getprofile()
            if current is not self.profile:
                self.chained = current
                sys.setprofile(self.profile)
        self.trace_stack(frame)

    def end(self, previous_trace: Callable | None, previous_profile: Callable | None) -> None:
        """The call has ended: put back the hooks found before it."""
        self.stopping = False
        sys.settrace(previous_trace)
        sys.setprofile(previous_profile)


def run_with_alarm(function: Callable, args: tuple, limit: float) -> tuple[str, object]:
    """``function(*args)`` stopped after ``limit`` s by SIGALRM (main thread only).

    Returns ``("returned", value)``, ``("raised", error)`` or ``("timeout", error or
    None)``. The previous SIGALRM handler is restored, and an outer timer (pytest-timeout's,
    say) is re-armed with its remaining time, late by at most this call's duration.
    """
    stopper = _Stopper()
    stopper.home = sys._getframe()
    state: dict[str, object] = {"armed": True, "fired": False, "first": None}
    hooks = (sys.gettrace(), sys.getprofile())

    def on_alarm(signum: int, frame: types.FrameType | None) -> None:
        if state["armed"]:
            error = TimeIsUp()
            if not state["fired"]:  # its traceback says where the function was
                state["fired"], state["first"] = True, error
            stopper.stop(frame)
            raise error

    previous = signal.signal(signal.SIGALRM, on_alarm)
    outer_delay, outer_interval = signal.setitimer(signal.ITIMER_REAL, limit, _REPEAT)
    start = time.monotonic()
    try:
        outcome: tuple[str, object] = ("returned", function(*args))
    except TimeIsUp as error:
        outcome = ("timeout", error)
    except BaseException as error:  # reported to the student, not hidden
        outcome = ("raised", error)
    finally:
        state["armed"] = False
        stopper.end(*hooks)
    signal.setitimer(signal.ITIMER_REAL, 0)
    signal.signal(signal.SIGALRM, signal.SIG_DFL if previous is None else previous)
    if outer_delay:  # an outer timer (e.g. pytest-timeout's) runs on, a little late
        remaining = max(outer_delay - (time.monotonic() - start), 1e-3)
        signal.setitimer(signal.ITIMER_REAL, remaining, outer_interval)
    if state["fired"]:   # perhaps swallowed, then returned or raised: it took too long
        outcome = ("timeout", state["first"])
    return outcome


def run_in_thread(function: Callable, args: tuple, limit: float) -> tuple[str, object]:
    """``function(*args)`` in a worker thread, stopped after ``limit`` s (see the module).

    The worker runs under the trace function and profile hook of its :class:`_Stopper`,
    which do nothing (no line is traced) until the time is up. Then the worker is sent
    :class:`TimeIsUp` once and its frames are traced, every 50 ms, as in
    :func:`run_with_alarm`. A worker that has not ended 1 s later (stuck in one long C call,
    say) is left to finish in the background while the time-out is reported.
    """
    box: dict[str, object] = {}
    stopper = _Stopper()

    def target() -> None:
        stopper.home = sys._getframe()
        hooks = (sys.gettrace(), sys.getprofile())
        sys.settrace(stopper.trace)
        sys.setprofile(stopper.profile)
        try:
            outcome: tuple[str, object] = ("returned", function(*args))
        except TimeIsUp as error:
            outcome = ("timeout", error)
        except BaseException as error:  # reported to the student
            outcome = ("raised", error)
        finally:
            stopper.end(*hooks)
        box["outcome"] = outcome

    worker = threading.Thread(target=target, name="student code", daemon=True)
    worker.start()
    try:
        worker.join(limit)
    except KeyboardInterrupt:  # the kernel was interrupted while waiting
        _send(worker, KeyboardInterrupt)
        worker.join(_GRACE)
        return box.get("outcome", ("raised", KeyboardInterrupt()))  # type: ignore[return-value]
    if worker.is_alive():
        stopper.stopping = True
        _send(worker, TimeIsUp)
        deadline = time.monotonic() + _GRACE
        while worker.is_alive() and time.monotonic() < deadline:
            stopper.mark(sys._current_frames().get(worker.ident))
            worker.join(_REPEAT)
        outcome = box.get("outcome")
        return ("timeout", outcome[1] if isinstance(outcome, tuple) and outcome[0] != "returned"
                else None)
    return box["outcome"]  # type: ignore[return-value]


def _send(worker: threading.Thread, kind: type[BaseException]) -> None:
    """Raise ``kind`` inside ``worker`` at its next line of Python (CPython only)."""
    try:
        ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(worker.ident),
                                                   ctypes.py_object(kind))
    except (AttributeError, TypeError):  # not CPython: the thread runs on in the background
        pass
