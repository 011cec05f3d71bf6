"""What each task cell of a notebook did when it last ran: completed or not, which of the
pack's functions it ran, which calls of the student's saved functions it made.

A check must judge what the current task cell produced. In IPython, :func:`watch_task_cells`
(called by :func:`~lqe_helpers.student_code.brief_errors`, which every notebook's set-up
cell runs) registers two of IPython's events: ``pre_run_cell`` starts a :class:`TaskRun`
for every cell (a student may write a task's answer in a cell of their own, without the
``# Task:`` comment) and, unless the pack gives the cell, sets a profile hook
(``sys.setprofile``, chained to any hook already set) that notes every function of the
``lqe_helpers`` package the cell runs, at any depth; ``post_run_cell`` ends it, noting
whether the cell completed. A cell that the running cell runs itself
(``get_ipython().run_cell(...)``) is part of it: its events neither end that run nor start
one, its code's names count as the outer cell's, and its error as the outer cell's. A
function loaded with :func:`~lqe_helpers.student_code.load` records its calls (inputs and
output) into the task cell running it (:func:`note_call`).

A check finds its task cell with :func:`run_for`: the latest run of a cell that defines
(assigns or defs at its top level) one of the names the check cell passes it, or of a
still unwritten task cell (its stub) whose ``# Task:`` comment names one (the cell running
now first: a student may call the check in the cell of the task); else of any task cell
whose comment names one; else the latest task cell run. :func:`ancestry` follows a task
run's values back through the cells the student wrote: a value made by the pack's solution
in an earlier cell of theirs and copied into the task cell is theirs no more than if the
task cell had called the pack itself. The cells the pack gives
(:mod:`~lqe_helpers.student_code.given_cells`) before the task end that trail; one from
further on, run early, is on it (its values are not the student's). Outside IPython,
or before the set-up cell ran, there is no record and :func:`run_for` returns None: the
checks then behave as without it.
"""

from __future__ import annotations

import contextlib
import dataclasses
import sys
import types
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from . import given_cells
from . import outside as outside_module
from .calling import in_pack, machinery_function, pack_name
from .cell_code import (
    argument_names,
    calls_a_check,
    defined_names,
    is_task_cell,
    mentioned_names,
    read_names,
)
from .given_cells import is_given
from .outside import LOST_WATCH, WATCHED_C_CALLS, c_call_use, dropping, starts_a_program
from .outside import watching as listening_outside

#: Task runs kept (the most recent last).
KEPT_RUNS = 200
#: Of each cell of the student's, at most this many small results of the pack's functions
#: are kept (:attr:`TaskRun.results`), each of at most :data:`RESULT_SIZE` numbers.
RESULTS_KEPT = 100
RESULT_SIZE = 64
#: Of these, the most recent whose calls of the student's saved functions (their inputs and
#: outputs, copied) are kept; older runs forget them, so memory stays bounded.
RUNS_WITH_CALLS = 20
#: The record's own modules, whose functions a cell's record leaves out of its pack calls.
_OWN = (__name__, outside_module.__name__)
#: Of each run, the uses of the outside kept (:attr:`TaskRun.outside`).
OUTSIDE_KEPT = 5


@dataclass
class SavedCall:
    """One call of a loaded saved function (``my_filter``, ``compensate``) in a task cell."""

    name: str
    args: tuple
    output: object


@dataclass
class TaskRun:
    """One run of a task cell.

    Attributes
    ----------
    number : int
        Its position among the task runs of this kernel (1, 2, …).
    source : str
        The cell's code as it ran.
    defines : frozenset of str
        Names its top level assigns or defines (from its code, whether or not it ran).
    mentions : frozenset of str
        Identifiers its ``# Task:`` comment names.
    task : bool
        Whether its code starts with a ``# Task:`` comment (any other cell is recorded
        too, for the names it defines).
    given : bool
        Whether its code is a cell the pack gives, unchanged (not the student's). Such a
        cell runs unwatched: its pack calls, results and uses of the outside stay empty.
    reads : frozenset of str
        Names its code reads before it gives them a value (:func:`read_names`).
    completed : bool or None
        Whether it ran to its end without an error, and so did every cell it ran itself
        (``get_ipython().run_cell(...)``, whose code counts as its own); None while it runs.
    inner_failed : bool
        Whether a cell it ran itself stopped with an error (then ``completed`` is False).
    not_written : bool
        Whether it stopped with ``NotImplementedError`` (a student edition's stub).
    pack_calls : dict
        Qualified name of each function of the pack it ran, by code object.
    entries : dict
        For each of those names, the function of the pack the cell itself called that ran
        it (the same name for a function the cell called).
    results : list of (str, numpy.ndarray)
        The small numeric results (numbers and
        arrays of at most :data:`RESULT_SIZE` numbers, copied) of the pack's functions it
        ran, each with the function's name, at most :data:`RESULTS_KEPT`.
    outside : list of str
        What it took from outside the notebook, whose work the record cannot see: a file it
        read, another program it ran (``subprocess``, ``os.system``, ``multiprocessing``, a
        fork), each said as "reads the file answer.npy" (:mod:`.outside`), at most
        :data:`OUTSIDE_KEPT`.
    saved_calls : list of SavedCall
        Its calls of the student's loaded functions.
    passed : set of str
        The checks that passed on its values (their functions' names).
    """

    number: int
    source: str
    defines: frozenset[str]
    mentions: frozenset[str]
    task: bool = True
    given: bool = False
    reads: frozenset[str] = frozenset()
    completed: bool | None = None
    inner_failed: bool = False
    not_written: bool = False
    pack_calls: dict[types.CodeType, str] = field(default_factory=dict)
    entries: dict[str, str] = field(default_factory=dict)
    results: list[tuple[str, np.ndarray]] = field(default_factory=list)
    outside: list[str] = field(default_factory=list)
    saved_calls: list[SavedCall] = field(default_factory=list)
    passed: set[str] = field(default_factory=set)

    @property
    def first_line(self) -> str:
        """Its first line of code or comment (for a message)."""
        return next((line.strip() for line in self.source.splitlines() if line.strip()), "")

    def ran(self, qualified_names: frozenset[str] | set[str]) -> list[str]:
        """Which of ``qualified_names`` (``"lqe_helpers.model.observation_matrix"``) it ran."""
        return sorted(name for name in set(self.pack_calls.values()) if name in qualified_names)


class _Record:
    """The task runs of this kernel and the cell running now."""

    def __init__(self) -> None:
        self.runs: list[TaskRun] = []
        self.current: TaskRun | None = None
        self.cell = ""          # the code of the cell running now
        self.previous_profile: Callable | None = None
        self.noting: Callable | None = None   # the running cell's profile hook
        self.listening: contextlib.ExitStack | None = None
        self.shells: set[int] = set()
        # The cells running now, outermost first: a cell may run another
        # (get_ipython().run_cell(...)), whose events come inside its own. Each is the
        # event's info (IPython's ExecutionInfo, which its result carries back) and code.
        self.open: list[tuple[object, str]] = []
        self.inner_error: BaseException | bool | None = None  # a nested cell's failure

    def pre_run_cell(self, info: object) -> None:
        source = getattr(info, "raw_cell", "") or ""
        self.cell = source
        if self.current is not None and self.open:  # run by the cell running now: part of it
            self._nest(info, source)
            return
        self._stop()
        self.open, self.inner_error = [(info, source)], None
        number = self.runs[-1].number + 1 if self.runs else 1
        run = TaskRun(number=number, source=source, defines=defined_names(source),
                      mentions=mentioned_names(source), task=is_task_cell(source),
                      given=is_given(source), reads=read_names(source))
        self.current = run
        self.previous_profile = previous = sys.getprofile()
        if run.given:  # the pack's own code, never the student's work (see ancestry): no
            self.noting = previous  # hook, so that its figures and explorers run at speed
            return
        pack_calls, entries, results = run.pack_calls, run.entries, run.results
        entry = ["", 0]  # the pack function the cell itself called last; pack frames open

        def outside(what: str) -> None:
            if what not in run.outside and len(run.outside) < OUTSIDE_KEPT:
                run.outside.append(what)

        def noting(frame: types.FrameType, event: str, arg: object) -> None:
            # Most events are a library's (numpy's, matplotlib's): they leave first.
            if previous is None and (event == "c_return" or event == "c_exception"):
                return
            try:
                if previous is not None:
                    previous(frame, event, arg)
                if event == "c_call":
                    if arg in WATCHED_C_CALLS:
                        outside(c_call_use(arg))
                    return
                if event != "call" and event != "return":
                    return
                module = frame.f_globals
                if id(module) in _libraries:
                    return
                if id(module) not in _not_libraries and _is_library(module):
                    return
                if event == "call":
                    code = frame.f_code
                    name = pack_calls.get(code)
                    if name is None:
                        if not in_pack(code.co_filename):
                            if starts_a_program(code.co_filename):
                                named = str(module.get("__name__", "subprocess"))
                                outside(f"runs another program ({named.split('.')[0]})")
                            return
                        name = pack_calls[code] = pack_name(frame)
                    if not entry[1]:
                        entry[0] = name
                    entry[1] += 1
                    entries.setdefault(name, entry[0])
                elif frame.f_code in pack_calls:  # its return
                    entry[1] = max(entry[1] - 1, 0)
                    if len(results) < RESULTS_KEPT:
                        kept = _small_result(arg)
                        if kept is not None:
                            results.append((pack_calls[frame.f_code], kept))
            except BaseException:  # Python drops a hook that raises: not the student's doing
                dropping()
                raise

        sys.setprofile(noting)
        self.noting = noting
        self.listening = contextlib.ExitStack()
        self.listening.enter_context(listening_outside(outside))

    def _nest(self, info: object, source: str) -> None:
        """A cell run by the cell running now: its code counts as the outer cell's."""
        run = self.current
        assert run is not None
        run.reads = run.reads | (read_names(source) - run.defines)
        run.defines = run.defines | defined_names(source)
        self.open.append((info, source))

    def post_run_cell(self, result: object) -> None:
        success = bool(getattr(result, "success", False))
        error = getattr(result, "error_in_exec", None)
        info = getattr(result, "info", None)
        nested = len(self.open) > 1
        if self.open and info is not None and info is not self.open[-1][0]:
            nested = True  # a cell run inside stopped before it started (no pre_run_cell)
        elif nested:
            self.open.pop()
            self.cell = self.open[-1][1]
        if nested:  # the cell that ran it goes on; its failure is that cell's
            if not success and self.inner_error is None:
                self.inner_error = error if error is not None else True
            return
        self.open = []
        run = self._stop()
        if run is not None:
            run.completed = success and self.inner_error is None
            run.inner_failed = self.inner_error is not None
            run.not_written = any(isinstance(failure, NotImplementedError)
                                  for failure in (error, self.inner_error))
        self.inner_error = None

    def _stop(self) -> TaskRun | None:
        run, self.current = self.current, None
        if run is None:
            return None
        if sys.getprofile() is not self.noting and len(run.outside) < OUTSIDE_KEPT:
            run.outside.append(LOST_WATCH)
        self.noting = None
        sys.setprofile(self.previous_profile)
        self.previous_profile = None
        if self.listening is not None:
            self.listening.close()
            self.listening = None
        run.pack_calls = {code: name for code, name in list(run.pack_calls.items())
                          if not name.startswith(_OWN)}
        self.runs.append(run)
        del self.runs[:-KEPT_RUNS]
        for old in self.runs[:-RUNS_WITH_CALLS]:
            old.saved_calls.clear()
        return run


_RECORD = _Record()
#: The ids of the globals of the modules seen by a cell's profile hook: a library's, not a
#: library's. Their globals are kept (:data:`_seen`), so that an id is never reused.
_libraries: set[int] = set()
_not_libraries: set[int] = set()
_seen: list[dict] = []


def _is_library(module: dict) -> bool:
    """Whether code with the globals ``module`` is a library's (numpy's, matplotlib's): a
    module with a file outside the pack that runs no other program. Noted on first sight;
    the notebook's namespace, the pack's modules and code made with other globals are not
    libraries."""
    filename = module.get("__file__")
    library = (isinstance(filename, str) and not in_pack(filename)
               and not starts_a_program(filename)
               and not str(module.get("__name__", "")).startswith("lqe_helpers"))
    _seen.append(module)
    (_libraries if library else _not_libraries).add(id(module))
    return library


def watch_task_cells(shell: object) -> None:
    """Register the task-cell record with an IPython ``shell`` (once per shell).

    ``shell.events`` must offer ``register(name, callback)`` for ``pre_run_cell`` and
    ``post_run_cell`` (IPython's ``EventManager``).
    """
    if id(shell) in _RECORD.shells:
        return
    shell.events.register("pre_run_cell", _RECORD.pre_run_cell)
    shell.events.register("post_run_cell", _RECORD.post_run_cell)
    _RECORD.shells.add(id(shell))


def watching() -> bool:
    """Whether task cells are being recorded (a set-up cell registered the events)."""
    return bool(_RECORD.shells)


def current_cell() -> str:
    """The code of the cell running now ("" without the record)."""
    return _RECORD.cell


def run_for(check: str) -> TaskRun | None:
    """The task run that the check ``check`` (its function's name) called now judges.

    None without the record (plain Python, pytest) or before any task cell ran.
    """
    if not watching():
        return None
    names = set(argument_names(_RECORD.cell, check))
    now = _RECORD.current
    if now is not None and not now.given and names & now.defines:  # the task written in
        # the check's own cell (a given check cell that keeps the function it judged is not)
        return dataclasses.replace(  # as far as it ran: its pack calls up to this check
            now, completed=True, saved_calls=list(now.saved_calls),
            pack_calls={code: name for code, name in list(now.pack_calls.items())
                        if not name.startswith(_OWN)})
    for index in range(len(_RECORD.runs) - 1, -1, -1):
        run = _RECORD.runs[index]
        if run.given:  # a cell the notebook gives makes the task's inputs, not its answer
            continue
        if names & run.defines or (run.task and run.not_written and names & run.mentions):
            # a later try at the same task (the same ``# Task:`` comment) that stopped
            # before making them is the attempt to judge, not this older run
            failed = [later for later in _RECORD.runs[index + 1:] if run.task and later.task
                      and later.mentions == run.mentions and not later.completed]
            return failed[-1] if failed else run
    for run in reversed(_RECORD.runs):
        if run.task and names & run.mentions:
            return run
    tasks = [run for run in _RECORD.runs if run.task]
    return tasks[-1] if tasks else None


def _small_result(value: object) -> np.ndarray | None:
    """A copy of ``value`` as a float array if it is a number or a small numeric array."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(
            value, (int, float, np.number, np.ndarray)):
        return None
    if isinstance(value, np.ndarray) and (value.size > RESULT_SIZE or value.dtype.kind
                                          not in "iuf"):
        return None
    return np.array(value, dtype=float)


def earlier_results(run: TaskRun, check: str) -> list[tuple[TaskRun, str, np.ndarray]]:
    """The results kept (:attr:`TaskRun.results`) by the cells of the student's run before
    ``run`` and before the first run on which ``check`` passed (a cell after it compares
    what the student had already done): (cell, function, result)."""
    passed = [earlier.number for earlier in _RECORD.runs if check in earlier.passed]
    before = min([run.number, *passed])
    return [(earlier, name, result) for earlier in _RECORD.runs
            if earlier.number < before for name, result in earlier.results]


def ancestry(run: TaskRun) -> list[TaskRun]:
    """``run`` and the cells of the student's whose values it draws on, nearest first.

    For each name a run reads (:attr:`TaskRun.reads`), the runs before it that define the
    name, latest first, up to the first that completed; then the same for those runs in
    turn. A cell the pack gives (:attr:`TaskRun.given`) ends the trail if it comes before
    the task in its notebook: its values are the notebook's own. One from further on (run
    early, a later figure's model, say) ends it only for a name that a given cell before the
    task makes too (an input made again, such as ``sigma_v``); for any other name it is on
    the trail, and the task's values must not come from it (its code is not followed: it is
    the pack's, and its run unwatched). Where the task
    stands is the place of the cell running now (its check cell) or of ``run``'s
    ``# Task:`` line; where neither is the pack's, every given cell ends the trail.
    """
    anchor = given_cells.places(_RECORD.cell) or given_cells.places(run.source)
    inputs = set().union(*(cell.defines for cell in _RECORD.runs if cell.given and (
        given_cells.comes_before(cell.source, anchor))))
    found, queue = [run], [run]
    seen = {run.number}
    while queue:
        reader = queue.pop(0)
        for name in sorted(reader.reads):
            for earlier in reversed(_RECORD.runs):
                if earlier.number >= reader.number or name not in earlier.defines:
                    continue
                ends = earlier.given and (not anchor or name in inputs or
                                          given_cells.comes_before(earlier.source, anchor))
                if not ends and earlier.number not in seen:
                    seen.add(earlier.number)
                    found.append(earlier)
                    if not earlier.given:
                        queue.append(earlier)
                if earlier.completed:
                    break
    return found


def missing_name_message(error: BaseException, tb: types.TracebackType | None) -> str | None:
    """One line for a ``NameError`` raised in a check cell's own line, or None.

    None unless the cell running now calls a ``check_…`` function and the error was raised
    at the cell's top level (not inside a function it calls).
    """
    last = tb
    while last is not None and last.tb_next is not None:
        last = last.tb_next
    name = getattr(error, "name", None)
    if (last is None or last.tb_frame.f_code.co_name != "<module>" or not name
            or not calls_a_check(_RECORD.cell)):
        return None
    for attribute in ("defines", "mentions"):
        for run in reversed(_RECORD.runs):
            if name in getattr(run, attribute):
                if run.not_written:
                    return (f"name '{name}' is not defined: the task cell that makes {name} is "
                            f"not written yet: replace its line `raise NotImplementedError` "
                            f"with your code, run it, then this check again")
                if run.completed:
                    return (f"name '{name}' is not defined: the task cell that makes {name} "
                            f"ran without making it; make {name} there, run that cell, then "
                            f"this check again")
                return (f"name '{name}' is not defined: the task cell that makes {name} "
                        f"stopped with an error before making it: fix it and run it again, "
                        f"then this check")
    return (f"name '{name}' is not defined: no cell run so far makes it. Run the cells above "
            f"this check in order, its task cell too, then this check again")


@machinery_function
def note_call(name: str, args: tuple, output: object) -> None:
    """Record a call of the loaded function ``name`` in the task cell running now, if any."""
    run = _RECORD.current
    if run is not None:
        copies = tuple(map(copied, args))
        run.saved_calls.append(SavedCall(name, copies, copied(output)))


@machinery_function
def copied(value: object) -> object:
    """A copy of ``value`` if it is an array (the student may change it in place later)."""
    return value.copy() if isinstance(value, np.ndarray) else value


def recorded(name: str, function: Callable,
             note: Callable[[str, tuple, object], None] = note_call) -> Callable:
    """``function`` (a student's function) noting each of its calls (name, arguments,
    output) with ``note``: by default :func:`note_call`, the task cell's record."""

    def recording(*args: object, **kwargs: object) -> object:
        output = function(*args, **kwargs)
        note(name, args + tuple(kwargs.values()), output)
        return output

    recording.__name__ = recording.__qualname__ = getattr(function, "__name__", name)
    recording.__doc__ = getattr(function, "__doc__", None)
    recording.__wrapped__ = function  # type: ignore[attr-defined]
    return machinery_function(recording)


def _reset() -> None:
    """Forget every run and registered shell (tests)."""
    _RECORD._stop()
    _RECORD.__init__()
