"""Running a student's function under a time limit that its own code cannot catch.

When the time is up, an exception (:class:`TimeIsUp`) is raised inside the function; but a
bare ``except:`` (or ``except BaseException: continue``) inside a loop would swallow one
exception and loop on forever. So from that moment the call is *stopped*, not only
interrupted: a trace function is installed on the student's own frames on the stack (and,
through ``sys.settrace``, on every frame they start) that raises :class:`TimeIsUp` again
at every line they run and at the start of every new frame of theirs. Python switches a
trace function off once it has raised, so it is put back (issue 26):

* when a swallowed :class:`TimeIsUp` is dropped (its ``__del__``): a ``try`` whose
  handler caught the re-raise of a ``try`` nested in its body, in one loop, in one function,
  with no call anywhere, raises again at the next line after its handler;
* at every call and return (a profile hook, ``sys.setprofile``, chained to any hook
  already there, such as ``forbid``'s), so a handler in the caller of a function that
  raised is traced again;
* every 50 ms (the timer repeats, and puts the profile hook back too).

A function that recurses to the limit and catches ``RecursionError`` leaves no room to call
the handler or the hooks: the handler's first act is to raise the recursion limit by
:data:`_HEADROOM` frames (given back when the call ends), and no new frame of the student's
outlasts its start from then on, so the room stays free. Tracing stops when the call
returns; code before the deadline runs untraced (no hook at all in the main thread).

Why this and not a child process: the function stays in the notebook's process, so
closures, lambdas and the notebook's globals work, nothing is pickled, and the student's
traceback (their own lines) is kept for the message. What it cannot stop: one long C call
(a huge numpy operation) runs to its end first; and a loop that keeps every
:class:`TimeIsUp` it catches alive (``kept = (kept, error)``) in two nested ``try`` s of one
frame, with no call anywhere: nothing is dropped or called, so the trace is off from its
handler's first raise until the next 50 ms tick, whose raise lands in the inner ``try``
again. A deep recursion that catches everything is stopped, but it may take a few seconds
to unwind (the 50 ms tick must land where there is room to run the handler); off the main
thread (:func:`run_in_thread`), where no tick runs inside the worker, it is left behind.
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
from .outside import dropping, time_is_up

__tracebackhide__ = True  # pytest: leave these frames out of a failure's traceback

#: Seconds between the re-raises of a call that goes on after its time is up.
_REPEAT = 0.05
#: Frames more that a call being stopped may use, so that its hooks run in a deep recursion.
_HEADROOM = 50
#: Seconds a worker thread is given to end once its time is up, before it is left behind.
_GRACE = 1.0


class TimeIsUp(BaseException):
    """Raised inside a student's function when its time is up, until the call ends.

    A ``BaseException``, not an ``Exception``: ``except Exception`` does not swallow it.
    One that a handler swallows puts the stopping trace back as it is dropped (see the
    module), so the next line of the call raises again.
    """

    rearm: Callable[[], None] | None = None

    def __del__(self) -> None:
        if self.rearm is not None:
            try:
                self.rearm()
            except BaseException:  # a finalizer cannot raise (Python would only print
                pass               # "Exception ignored"); a TimeIsUp sent meanwhile comes again


class _Stopper:
    """Stops one call in one thread: once :attr:`stopping`, every line it runs raises."""

    def __init__(self) -> None:
        self.stopping = False
        self.home: types.FrameType | None = None   # the runner's frame, never traced
        self.chained: Callable | None = None        # the profile hook found at the deadline
        self.thread = threading.get_ident()         # the thread that runs the call
        self.limits: list[int] = []                 # recursion limits: found, given
        self.hook = self.trace                      # the one bound method installed
        self.raised_in: types.FrameType | None = None  # the frame of the trace's last raise

    def give_room(self) -> None:
        """Raise the recursion limit (every thread's) by :data:`_HEADROOM` frames, once.

        A function that recurses to the limit and catches the ``RecursionError`` leaves no
        room for the hooks, which would fail in turn. Once the stop has started, no new
        frame of the call outlasts its first line, so the room stays free.
        """
        if not self.limits:
            self.limits[:] = [sys.getrecursionlimit(), sys.getrecursionlimit() + _HEADROOM]
            sys.setrecursionlimit(self.limits[1])

    def take_room_back(self) -> None:
        """Undo :meth:`give_room` (unless the limit was changed since)."""
        if self.limits and sys.getrecursionlimit() == self.limits[1]:
            sys.setrecursionlimit(self.limits[0])
        self.limits.clear()

    def error(self) -> TimeIsUp:
        """A :class:`TimeIsUp` that traces the call again when it is dropped."""
        error = TimeIsUp()
        error.rearm = self.rearm
        return error

    def rearm(self) -> None:
        """Trace the call's stack again (a swallowed :class:`TimeIsUp` was dropped)."""
        if self.stopping and threading.get_ident() == self.thread:
            try:
                self.retrace(sys._getframe(1))
            except RecursionError:  # at the recursion limit: the next tick traces again
                pass

    def retrace(self, frame: types.FrameType | None) -> None:
        """Trace again what a raise switched off: nothing if the trace is still on.

        A raise switches off the trace of this thread and of the frame it was raised in
        (:attr:`raised_in`); frames started since then are the newest on the stack, so the
        walk up from ``frame`` ends at the first of the student's frames still traced.
        """
        if sys.gettrace() is not self.hook:
            if self.raised_in is not None:
                self.raised_in.f_trace, self.raised_in = self.hook, None
            self.mark(frame, until_traced=True)
            sys.settrace(self.hook)

    def trace(self, frame: types.FrameType, event: str, arg: object) -> object:
        if not self.stopping or not is_own_code(frame.f_code.co_filename):
            return None          # before the deadline, and the pack's or a library's code
        if event in ("line", "call"):   # a new frame of the student's raises at once
            self.raised_in = frame
            raise self.error()
        return self.hook

    def profile(self, frame: types.FrameType, event: str, arg: object) -> None:
        try:
            if self.chained is not None:
                self.chained(frame, event, arg)
            if self.stopping:
                self.retrace(frame)
        except BaseException:  # Python drops a hook that raises: not the student's doing
            dropping()
            raise

    def mark(self, frame: types.FrameType | None, until_traced: bool = False) -> None:
        """Trace the student's own frames from ``frame`` up to :attr:`home` (any thread);
        with ``until_traced``, up to the first of them traced already."""
        hook = self.hook
        while frame is not None and frame is not self.home:
            if is_own_code(frame.f_code.co_filename):
                if until_traced and frame.f_trace is hook:
                    return
                frame.f_trace = hook
                frame.f_trace_lines = True
            frame = frame.f_back

    def trace_stack(self, frame: types.FrameType | None) -> None:
        """:meth:`mark` ``frame``'s stack, and trace every new frame (this thread)."""
        self.mark(frame)
        sys.settrace(self.hook)

    def stop(self, frame: types.FrameType | None) -> None:
        """From now on every line of the call raises (see the module); in its own thread."""
        if not self.stopping:
            self.time_is_up()
            self.chained = sys.getprofile()
        if sys.getprofile() != self.profile:  # at first, or removed by an error inside it
            sys.setprofile(self.profile)
        self.trace_stack(frame)

    def in_hooks(self, frame: types.FrameType | None) -> bool:
        """Whether ``frame`` runs inside one of this module's hooks (not the student's)."""
        while frame is not None and frame is not self.home:
            if frame.f_code.co_filename == __file__:
                return True
            if is_own_code(frame.f_code.co_filename):
                return False
            frame = frame.f_back
        return False

    def time_is_up(self) -> None:
        """From now on, stop the call (:attr:`stopping`); its thread's hooks may drop."""
        self.stopping = True
        time_is_up(self.thread)

    def end(self, previous_trace: Callable | None, previous_profile: Callable | None) -> None:
        """The call has ended: put back the hooks found before it."""
        self.stopping = False
        time_is_up(self.thread, False)
        sys.settrace(previous_trace)
        sys.setprofile(previous_profile)



def is_time_limit_hook(function: object) -> bool:
    """Whether ``function`` is the profile hook a time limit puts in place to stop a call."""
    return getattr(function, "__func__", None) is _Stopper.profile


def _unraisable(stopper: _Stopper, previous: Callable) -> Callable:
    """A ``sys.unraisablehook`` that drops what stopping the call leaves unraisable: a
    :class:`TimeIsUp` raised while Python closed an abandoned generator of the student's
    (or the generator's "ignored GeneratorExit" once time is up); anything else goes on."""

    def hook(unraisable: object) -> None:
        kind = getattr(unraisable, "exc_type", None)
        if kind is TimeIsUp or (stopper.stopping and kind is RuntimeError and "GeneratorExit"
                                in str(getattr(unraisable, "exc_value", ""))):
            return
        previous(unraisable)

    return hook


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
            if not stopper.limits:  # first of all, in this frame: room for the rest
                stopper.limits[:] = [sys.getrecursionlimit(), sys.getrecursionlimit() + _HEADROOM]
                sys.setrecursionlimit(stopper.limits[1])
            error = stopper.error()
            if not state["fired"]:  # its traceback says where the function was
                state["fired"], state["first"] = True, error
            stopper.stop(frame)
            if not stopper.in_hooks(frame):  # an error there would switch its hook off
                raise error

    previous = signal.signal(signal.SIGALRM, on_alarm)
    outer_delay, outer_interval = signal.setitimer(signal.ITIMER_REAL, limit, _REPEAT)
    start = time.monotonic()
    unraisable, sys.unraisablehook = sys.unraisablehook, _unraisable(stopper, sys.unraisablehook)
    try:
        outcome: tuple[str, object] = ("returned", function(*args))
    except TimeIsUp as error:
        outcome = ("timeout", error)
    except BaseException as error:  # reported to the student, not hidden
        outcome = ("raised", error)
    finally:
        state["armed"] = False
        stopper.end(*hooks)
        stopper.take_room_back()
        sys.unraisablehook = unraisable
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
    which do nothing (no line is traced) until the time is up. Then the worker is given
    room to recurse (:meth:`_Stopper.give_room`) and sent :class:`TimeIsUp`, and every
    50 ms its frames are traced and it is sent :class:`TimeIsUp` again, as the timer of
    :func:`run_with_alarm` repeats. A worker that has not ended 1 s later (stuck in one long
    C call, or a deep recursion that catches everything: another thread cannot put back its
    trace) is left to finish in the background, keeping its room, while the time-out is
    reported.
    """
    box: dict[str, object] = {}
    stopper = _Stopper()

    def target() -> None:
        stopper.home, stopper.thread = sys._getframe(), threading.get_ident()
        hooks = (sys.gettrace(), sys.getprofile())
        sys.settrace(stopper.hook)
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
        stopper.time_is_up()
        stopper.give_room()
        _send(worker, TimeIsUp)
        deadline = time.monotonic() + _GRACE
        while worker.is_alive() and time.monotonic() < deadline:
            stopper.mark(sys._current_frames().get(worker.ident))
            worker.join(_REPEAT)
            if worker.is_alive():  # the tick of run_with_alarm: a handler spinning untraced
                _send(worker, TimeIsUp)
        if not worker.is_alive():  # a worker left behind deep in a recursion keeps its room
            stopper.take_room_back()
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
