"""What a student's code takes from outside the notebook: a file it reads, another program.

A check judges numbers it can trace to the student's code: the pack's functions a cell runs
are recorded (:mod:`~lqe_helpers.student_code.task_runs`), and a task's function runs with
the pack's functions refused (:mod:`~lqe_helpers.student_code.calling`). Numbers read from a
file, or made by another program, have no such trail: a program run beside the notebook (or
in an earlier cell, through ``os.system``) can compute the pack's answer and leave it in a
file for the task cell to read. :func:`watching` notes, through one audit hook
(:func:`sys.addaudithook`, added on first use and never removed, as Python allows), every
such use by the code running in the current thread and tells a listener what it was: "reads
the file answer.npy", "runs another program (os.system)".

The student's own code switching the watch off is news too: replacing the profile hook
through which the pack sees which functions run (``sys.setprofile``; Python announces it too
when it drops a hook that raised, which the pack's hooks say first: :func:`dropping`),
starting a thread
(whose calls no hook of this thread sees), or making a function from another's code by hand
(``code.replace``, ``types.FunctionType``, ``marshal``, ``__code__``: a pack function under
another file's name), or code made from text (``compile``, ``exec`` or ``eval`` of a
string: the pack's own source read and run under another name, say), or C code through
``ctypes`` (a thread of its own, say). Python's and the libraries' own uses (IPython
compiling a cell, ``dataclasses``) are not the student's.

Files of the installation are not news: Python's and its packages' (``sys.prefix``, the
site folders), the pack's modules, the system's folders, matplotlib's and IPython's settings
and caches. Neither are writes: what a cell writes it has computed in the notebook.
"""

from __future__ import annotations

import _thread
import contextlib
import functools
import os
import site
import sys
import sysconfig
import threading
from collections.abc import Callable, Iterator
from pathlib import Path

#: The audit events of starting another program (or becoming one).
PROGRAM_EVENTS = frozenset({
    "os.system", "subprocess.Popen", "os.exec", "os.posix_spawn", "os.spawn", "os.fork",
    "os.forkpty", "pty.spawn", "os.startfile"})
#: The audit events of reading from outside the process other than a file: a database, a
#: connection, a web address.
OTHER_SOURCES = {"sqlite3.connect": "opens the database {0}",
                 "socket.connect": "opens a network connection",
                 "urllib.Request": "opens the address {0}"}
#: The audit events of the student's own code changing what the pack's watch sees.
TAMPERING = {"sys.setprofile": "switches off the pack's watch of the functions it runs "
                               "(sys.setprofile)",
             "ctypes.dlopen": "uses C code through ctypes, whose calls the pack cannot watch",
             "ctypes.dlsym": "uses C code through ctypes, whose calls the pack cannot watch",
             "marshal.loads": "loads code with marshal",
             "compile": "makes code from text (compile, exec or eval)",
             "object.__setattr__": "replaces a function's code (__code__)",
             "sys._getframe": "looks into the frames of the code that runs (sys._getframe)",
             "object.__getattr__": "looks into the frames of a traceback or a generator",
             "gc.get_objects": "searches the memory for objects (gc.get_objects)",
             "gc.get_referrers": "searches the memory for objects (gc.get_referrers)",
             "gc.get_referents": "searches the memory for objects (gc.get_referents)",
             "code.__new__": "makes a code object by hand (code.replace, types.CodeType)",
             "function.__new__": "makes a function by hand (types.FunctionType)"}
#: Of the attribute events, the attributes that are news.
WATCHED_ATTRIBUTES = {"object.__setattr__": ("__code__",),
                      "object.__getattr__": ("tb_frame", "gi_frame", "cr_frame", "ag_frame")}
#: Modules whose frames ask on the student's behalf: the event's caller is the one above.
_ASKED_FOR = {"ctypes.dlopen": f"{os.sep}ctypes{os.sep}__init__.py",
              "ctypes.dlsym": f"{os.sep}ctypes{os.sep}__init__.py",
              "sys._getframe": f"{os.sep}inspect.py"}
#: The C functions that start or become another program (os.system, fork, exec, spawn).
PROCESS_CALLS = frozenset(getattr(os, name) for name in (
    "system", "fork", "forkpty", "execv", "execve", "execvp", "execvpe", "execl", "execle",
    "execlp", "execlpe", "posix_spawn", "posix_spawnp", "spawnv", "spawnve")
    if hasattr(os, name))
#: What a profile hook's ``c_call`` of a watched code says when it leaves the watch.
STARTS_A_THREAD = "starts another thread, whose calls the pack cannot watch"
#: What a watch says when its profile hook was gone after the code ran.
LOST_WATCH = ("switched off the pack's watch of the functions it runs (a RecursionError "
              "caught inside it, or sys.setprofile)")
#: Why a check refuses numbers made that way.
UNTRACEABLE = ("The check cannot see how numbers from a file, another program or code it "
               "cannot watch were made, so it cannot tell them from the pack's answer")
#: The system's folders (never a place a student's program leaves numbers), but /dev/shm.
SYSTEM_FOLDERS = ("/proc", "/sys", "/etc", "/usr", "/lib", "/lib64", "/bin", "/sbin", "/dev")
#: Suffixes of module files: read from the pack's own folder when a module is imported.
MODULE_SUFFIXES = (".py", ".pyc", ".so", ".pyd")

_PACK_FOLDER = os.path.realpath(Path(__file__).resolve().parent.parent)

_listeners: dict[int, list[Callable[[str], None]]] = {}
_dropping: set[int] = set()  # the threads whose profile hook of the pack is raising
_time_up: set[int] = set()   # the threads whose call a time limit is stopping
_hearing: set[int] = set()   # the threads whose audit hook is asking who caused an event
_hooked: list[bool] = []  # [True] once the audit hook is added (changed in place, so that a
                          # check's snapshot of the pack's globals sees no change)


@contextlib.contextmanager
def watching(listener: Callable[[str], None]) -> Iterator[None]:
    """Call ``listener(what)`` for each use of the outside by code of this thread meanwhile.

    ``what`` says it in a student's words ("reads the file answer.npy"). The listener may
    raise: the use (the ``open``, the ``os.system``) then fails with that exception. The
    innermost ``watching`` of a thread hears its uses.
    """
    if not _hooked:
        sys.addaudithook(_heard)
        _hooked.append(True)
    stack = _listeners.setdefault(threading.get_ident(), [])
    stack.append(listener)
    try:
        yield
    finally:
        stack.remove(listener)
        if not stack:
            _listeners.pop(threading.get_ident(), None)


def unheard() -> contextlib.AbstractContextManager[None]:
    """Meanwhile, this thread's uses of the outside are the pack's own (reading a student's
    saved function), not news to any listener."""
    return watching(_ignore)


def _ignore(what: str) -> None:
    """A listener that hears nothing."""


def dropping() -> None:
    """Say that a profile hook of the pack raises in this thread now: Python drops it, and
    the ``sys.setprofile`` event that announces it is not the student's."""
    _dropping.add(threading.get_ident())


def time_is_up(thread: int, up: bool = True) -> None:
    """While a time limit stops a call in ``thread`` (``up``), its exceptions land anywhere,
    in a profile hook too, which Python then drops: those ``sys.setprofile`` events are not
    the student's."""
    if up:
        _time_up.add(thread)
    else:
        _time_up.discard(thread)


def _heard(event: str, args: tuple) -> None:
    if event == "sys.setprofile" and (_dropping or _time_up):
        thread = threading.get_ident()
        if thread in _time_up:
            return
        if thread in _dropping:
            _dropping.discard(thread)
            return
    if not _listeners:
        return
    stack = _listeners.get(threading.get_ident())
    if not stack:
        return
    if event in TAMPERING:
        thread = threading.get_ident()
        if thread in _hearing:  # the sys._getframe of tampering() itself
            return
        _hearing.add(thread)
        try:
            what = tampering(event, args)
        finally:
            _hearing.discard(thread)
    else:
        what = use_of_outside(event, args)
    if what:
        stack[-1](what)


def tampering(event: str, args: tuple) -> str:
    """What the :data:`TAMPERING` event ``event`` says, if the student's own code (not a
    library's, not the pack's) caused it, or "". Called by the audit hook."""
    if event.startswith("object.") and (len(args) < 2 or args[1] not in WATCHED_ATTRIBUTES[
            event]):
        return ""
    frame = sys._getframe(2)  # the hook's caller
    asked_for = _ASKED_FOR.get(event)
    while asked_for and frame.f_back is not None and frame.f_code.co_filename.endswith(
            asked_for):
        frame = frame.f_back  # who asked ctypes or inspect: their own frames say nothing
    caller = frame.f_code.co_filename
    library = caller.startswith("<frozen ") or installation_file(caller)  # importlib's
    return "" if library else TAMPERING[event]


def use_of_outside(event: str, args: tuple) -> str:
    """What the audit event ``event`` with ``args`` takes from outside, or ""."""
    if event in PROGRAM_EVENTS:
        return f"runs another program ({event})"
    if event in OTHER_SOURCES:
        return OTHER_SOURCES[event].format(*(str(arg) for arg in args[:1]))
    if event != "open" or len(args) < 3:
        return ""
    path, mode, flags = args[:3]
    if not isinstance(path, (str, bytes, os.PathLike)):
        return ""  # a file already open (its descriptor)
    if isinstance(mode, str):  # open(): "r", "r+" and "a+" read what the file holds
        reading = "r" in mode or ("+" in mode and "a" in mode)
    else:  # os.open(): not write-only, and not emptied or new
        reading = isinstance(flags, int) and (
            flags & getattr(os, "O_ACCMODE", 3) != os.O_WRONLY
            and not flags & (os.O_TRUNC | os.O_EXCL))
    if not reading:
        return ""
    path = os.fsdecode(path)
    if installation_file(path):
        return ""
    return f"reads the file {_shown(path)}"


#: The built-in functions whose ``c_call`` :func:`c_call_use` names (a set: a profile hook
#: asks for each C call).
WATCHED_C_CALLS = frozenset({_thread.start_new_thread, *PROCESS_CALLS})


def c_call_use(function: object) -> str:
    """What a profile hook's ``c_call`` of the built-in ``function`` takes from outside the
    watch, or "": another program (``os.system``, fork, exec), another thread."""
    if function is _thread.start_new_thread:
        return STARTS_A_THREAD
    if function in PROCESS_CALLS:
        return f"runs another program (os.{getattr(function, '__name__', 'system')})"
    return ""


@functools.lru_cache(maxsize=4096)
def starts_a_program(filename: str) -> bool:
    """Whether code of ``filename`` is the standard library's way to run another program
    that no audit event announces (``multiprocessing``'s spawn, say)."""
    parts = filename.replace(os.sep, "/").split("/")
    return parts[-1] in {"subprocess.py", "pty.py"} or "multiprocessing" in parts or (
        "concurrent" in parts and parts[-1] == "process.py")


def installation_file(path: str) -> bool:
    """Whether ``path`` is a file of the installation (see the module's text), not a
    student's or their program's."""
    real = os.path.realpath(path)
    if real.startswith(os.path.join(_PACK_FOLDER, "")):
        return real.endswith(MODULE_SUFFIXES)
    if real.startswith("/dev/shm"):
        return False
    return any(real == folder or real.startswith(os.path.join(folder, ""))
               for folder in _installation_folders())


@functools.lru_cache(maxsize=1)
def _installation_folders() -> tuple[str, ...]:
    home = Path.home()
    folders = [sys.prefix, sys.base_prefix, sys.exec_prefix, *SYSTEM_FOLDERS,
               *(sysconfig.get_paths().get(key, "") for key in
                 ("stdlib", "platstdlib", "purelib", "platlib")),
               *site.getsitepackages(), site.getusersitepackages(),
               os.environ.get("MPLCONFIGDIR", ""), os.environ.get("IPYTHONDIR", ""),
               os.path.join(os.environ.get("XDG_CONFIG_HOME", home / ".config"), "matplotlib"),
               os.path.join(os.environ.get("XDG_CACHE_HOME", home / ".cache"), "matplotlib"),
               os.path.join(os.environ.get("XDG_CACHE_HOME", home / ".cache"), "fontconfig"),
               home / ".matplotlib", home / ".ipython"]
    return tuple(dict.fromkeys(os.path.realpath(folder) for folder in folders if folder))


def _shown(path: str) -> str:
    """``path`` as a student would write it: relative to the working folder if inside it."""
    try:
        relative = os.path.relpath(path)
    except ValueError:  # another drive (Windows)
        return path
    return path if relative.startswith("..") else relative


#: What runs inside a student's function when it uses the outside: the audit hook and what
#: it asks (``calling`` lets a watched function run them, as machinery).
HEARING = (_heard, use_of_outside, installation_file, _installation_folders.__wrapped__,
           _shown, c_call_use, dropping, time_is_up, tampering)
