"""What each task cell of a notebook did when it last ran: completed or not, which of the
pack's functions it ran, which calls of the student's saved functions it made.

A check must judge what the current task cell produced. In IPython, :func:`watch_task_cells`
(called by :func:`~lqe_helpers.student_code.brief_errors`, which every notebook's set-up
cell runs) registers two of IPython's events: ``pre_run_cell`` starts a :class:`TaskRun`
for every cell (a student may write a task's answer in a cell of their own, without the
``# Task:`` comment) and sets a profile hook
(``sys.setprofile``, chained to any hook already set) that notes every function of the
``lqe_helpers`` package the cell runs, at any depth; ``post_run_cell`` ends it, noting
whether the cell completed. A function loaded with :func:`~lqe_helpers.student_code.load`
records its calls (inputs and output) into the task cell running it (:func:`note_call`).

A check finds its task cell with :func:`run_for`: the latest run of a cell that defines
(assigns or defs at its top level) one of the names the check cell passes it, or of a
still unwritten task cell (its stub) whose ``# Task:`` comment names one (the cell running
now first: a student may call the check in the cell of the task); else of any task cell
whose comment names one; else the latest task cell run. :func:`ancestry` follows a task
run's values back through the cells the student wrote: a value made by the pack's solution
in an earlier cell of theirs and copied into the task cell is theirs no more than if the
task cell had called the pack itself. The cells the pack gives
(:mod:`~lqe_helpers.student_code.given_cells`) end that trail. Outside IPython,
or before the set-up cell ran, there is no record and :func:`run_for` returns None: the
checks then behave as without it.
"""

from __future__ import annotations

import ast
import dataclasses
import re
import sys
import types
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .calling import in_pack, machinery_function, pack_name
from .given_cells import is_given

#: How a task cell starts (after blank lines).
TASK_PREFIX = "# Task:"

#: Task runs kept (the most recent last).
KEPT_RUNS = 200
#: Of these, the most recent whose calls of the student's saved functions (their inputs and
#: outputs, copied) are kept; older runs forget them, so memory stays bounded.
RUNS_WITH_CALLS = 20


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
        Whether its code is a cell the pack gives, unchanged (not the student's).
    reads : frozenset of str
        Names its code reads before it gives them a value (:func:`read_names`).
    completed : bool or None
        Whether it ran to its end without an error; None while it runs.
    not_written : bool
        Whether it stopped with ``NotImplementedError`` (a student edition's stub).
    pack_calls : dict
        Qualified name of each function of the pack it ran, by code object.
    entries : dict
        For each of those names, the function of the pack the cell itself called that ran
        it (the same name for a function the cell called).
    saved_calls : list of SavedCall
        Its calls of the student's loaded functions.
    """

    number: int
    source: str
    defines: frozenset[str]
    mentions: frozenset[str]
    task: bool = True
    given: bool = False
    reads: frozenset[str] = frozenset()
    completed: bool | None = None
    not_written: bool = False
    pack_calls: dict[types.CodeType, str] = field(default_factory=dict)
    entries: dict[str, str] = field(default_factory=dict)
    saved_calls: list[SavedCall] = field(default_factory=list)

    @property
    def first_line(self) -> str:
        """Its first line of code or comment (for a message)."""
        return next((line.strip() for line in self.source.splitlines() if line.strip()), "")

    def ran(self, qualified_names: frozenset[str] | set[str]) -> list[str]:
        """Which of ``qualified_names`` (``"lqe_helpers.model.observation_matrix"``) it ran."""
        return sorted(name for name in set(self.pack_calls.values()) if name in qualified_names)


def is_task_cell(source: str) -> bool:
    """Whether a cell's code starts with a ``# Task:`` comment."""
    return source.lstrip().startswith(TASK_PREFIX)


def defined_names(source: str) -> frozenset[str]:
    """Names assigned or defined at the top level of ``source`` (empty if it does not parse)."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return frozenset()
    names: set[str] = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
            continue
        for child in _outer_nodes(node):
            if isinstance(child, ast.Name) and isinstance(child.ctx, ast.Store):
                names.add(child.id)
    return frozenset(names)


#: Nodes whose names live in a scope of their own (a comprehension's loop variable).
_OWN_SCOPE = (ast.ListComp, ast.SetComp, ast.DictComp, ast.GeneratorExp, ast.Lambda,
              ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)


def _outer_nodes(node: ast.AST) -> list[ast.AST]:
    """``node`` and the nodes below it, but not inside a scope of their own."""
    found, stack = [], [node]
    while stack:
        current = stack.pop()
        found.append(current)
        stack.extend(child for child in ast.iter_child_nodes(current)
                     if not isinstance(child, _OWN_SCOPE))
    return found


class _ReadOrder(ast.NodeVisitor):
    """Visits a cell's code in the order it runs (a value before the name it is given), noting
    whether each name is first read or first given a value."""

    def __init__(self) -> None:
        self.first_read: dict[str, bool] = {}

    def note(self, name: str, read: bool) -> None:
        self.first_read.setdefault(name, read)

    def visit_Name(self, node: ast.Name) -> None:
        self.note(node.id, isinstance(node.ctx, ast.Load))

    def visit_arg(self, node: ast.arg) -> None:
        self.note(node.arg, False)

    def visit_alias(self, node: ast.alias) -> None:
        self.note((node.asname or node.name).split(".")[0], False)

    def _value_first(self, node: ast.AST, value: ast.AST | None, targets: list[ast.AST]) -> None:
        if isinstance(node, ast.AugAssign) and isinstance(node.target, ast.Name):
            self.note(node.target.id, True)
        if value is not None:
            self.visit(value)
        for target in targets:
            self.visit(target)

    def visit_Assign(self, node: ast.Assign) -> None:
        self._value_first(node, node.value, node.targets)

    def visit_AugAssign(self, node: ast.AugAssign) -> None:
        self._value_first(node, node.value, [node.target])

    def visit_AnnAssign(self, node: ast.AnnAssign) -> None:
        self._value_first(node, node.value, [node.target])

    def visit_NamedExpr(self, node: ast.NamedExpr) -> None:
        self._value_first(node, node.value, [node.target])

    def visit_For(self, node: ast.For | ast.AsyncFor) -> None:
        self._value_first(node, node.iter, [node.target, *node.body, *node.orelse])

    visit_AsyncFor = visit_For

    def visit_comprehension(self, node: ast.comprehension) -> None:
        self._value_first(node, node.iter, [node.target, *node.ifs])

    def _comprehension(self, node: ast.AST, results: list[ast.AST]) -> None:
        for generator in node.generators:  # type: ignore[attr-defined]
            self.visit(generator)
        for result in results:
            self.visit(result)

    def visit_ListComp(self, node: ast.ListComp) -> None:
        self._comprehension(node, [node.elt])

    visit_SetComp = visit_GeneratorExp = visit_ListComp

    def visit_DictComp(self, node: ast.DictComp) -> None:
        self._comprehension(node, [node.key, node.value])

    def _definition(self, node: ast.AST, name: str | None) -> None:
        for decorator in getattr(node, "decorator_list", ()):
            self.visit(decorator)
        if name is not None:
            self.note(name, False)
        for field_name in ("bases", "keywords", "args", "body"):
            value = getattr(node, field_name, None)
            for child in value if isinstance(value, list) else [value] if value else []:
                self.visit(child)

    def visit_FunctionDef(self, node: ast.FunctionDef | ast.AsyncFunctionDef) -> None:
        self._definition(node, node.name)

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_ClassDef(self, node: ast.ClassDef) -> None:
        self._definition(node, node.name)

    def visit_Lambda(self, node: ast.Lambda) -> None:
        self._definition(node, None)


def read_names(source: str) -> frozenset[str]:
    """Names ``source`` reads before it gives them a value (empty if it does not parse).

    The code is taken in the order it runs (``x = f(x)`` reads ``x``); a function's body
    counts where the function is defined, its parameters as given.
    """
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return frozenset()
    order = _ReadOrder()
    order.visit(tree)
    return frozenset(name for name, read in order.first_read.items() if read)


def mentioned_names(source: str) -> frozenset[str]:
    """Identifiers in the comment lines at the top of ``source`` (its ``# Task:`` block)."""
    words: set[str] = set()
    for line in source.lstrip().splitlines():
        if not line.lstrip().startswith("#"):
            break
        words.update(re.findall(r"[A-Za-z_][A-Za-z_0-9]*", line))
    return frozenset(words)


def argument_names(source: str, check: str) -> list[str]:
    """The bare names passed to a call of ``check`` (``checks.check_x(C, R)``) in ``source``."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return []
    names: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            called = node.func
            called_name = (called.attr if isinstance(called, ast.Attribute)
                           else called.id if isinstance(called, ast.Name) else "")
            if called_name == check:
                arguments = [*node.args, *(keyword.value for keyword in node.keywords)]
                names += [argument.id for argument in arguments
                          if isinstance(argument, ast.Name)]
    return names


class _Record:
    """The task runs of this kernel and the cell running now."""

    def __init__(self) -> None:
        self.runs: list[TaskRun] = []
        self.current: TaskRun | None = None
        self.cell = ""          # the code of the cell running now
        self.previous_profile: Callable | None = None
        self.shells: set[int] = set()

    def pre_run_cell(self, info: object) -> None:
        source = getattr(info, "raw_cell", "") or ""
        self.cell = source
        self._stop()
        number = self.runs[-1].number + 1 if self.runs else 1
        run = TaskRun(number=number, source=source, defines=defined_names(source),
                      mentions=mentioned_names(source), task=is_task_cell(source),
                      given=is_given(source), reads=read_names(source))
        self.current = run
        self.previous_profile = previous = sys.getprofile()
        pack_calls, entries = run.pack_calls, run.entries
        entry = ["", 0]  # the pack function the cell itself called last; pack frames open

        def noting(frame: types.FrameType, event: str, arg: object) -> None:
            if previous is not None:
                previous(frame, event, arg)
            if event == "call":
                code = frame.f_code
                name = pack_calls.get(code)
                if name is None:
                    if not in_pack(code.co_filename):
                        return
                    name = pack_calls[code] = pack_name(frame)
                if not entry[1]:
                    entry[0] = name
                entry[1] += 1
                entries.setdefault(name, entry[0])
            elif event == "return" and frame.f_code in pack_calls:
                entry[1] = max(entry[1] - 1, 0)

        sys.setprofile(noting)

    def post_run_cell(self, result: object) -> None:
        run = self._stop()
        if run is not None:
            run.completed = bool(getattr(result, "success", False))
            run.not_written = isinstance(getattr(result, "error_in_exec", None),
                                         NotImplementedError)

    def _stop(self) -> TaskRun | None:
        run, self.current = self.current, None
        if run is None:
            return None
        sys.setprofile(self.previous_profile)
        self.previous_profile = None
        run.pack_calls = {code: name for code, name in list(run.pack_calls.items())
                          if not name.startswith(__name__)}
        self.runs.append(run)
        del self.runs[:-KEPT_RUNS]
        for old in self.runs[:-RUNS_WITH_CALLS]:
            old.saved_calls.clear()
        return run


_RECORD = _Record()


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
    if now is not None and names & now.defines:  # the task written in the check's own cell
        return dataclasses.replace(  # as far as it ran: its pack calls up to this check
            now, completed=True, saved_calls=list(now.saved_calls),
            pack_calls={code: name for code, name in list(now.pack_calls.items())
                        if not name.startswith(__name__)})
    for run in reversed(_RECORD.runs):
        if names & run.defines or (run.task and run.not_written and names & run.mentions):
            return run
    for run in reversed(_RECORD.runs):
        if run.task and names & run.mentions:
            return run
    tasks = [run for run in _RECORD.runs if run.task]
    return tasks[-1] if tasks else None


def ancestry(run: TaskRun) -> list[TaskRun]:
    """``run`` and the cells of the student's whose values it draws on, nearest first.

    For each name a run reads (:attr:`TaskRun.reads`), the runs before it that define the
    name, latest first, up to the first that completed; then the same for those runs in
    turn. A cell the pack gives (:attr:`TaskRun.given`) ends the trail: its values are the
    notebook's own.
    """
    found, queue = [run], [run]
    seen = {run.number}
    while queue:
        reader = queue.pop(0)
        for name in sorted(reader.reads):
            for earlier in reversed(_RECORD.runs):
                if earlier.number >= reader.number or name not in earlier.defines:
                    continue
                if not earlier.given and earlier.number not in seen:
                    seen.add(earlier.number)
                    found.append(earlier)
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


def calls_a_check(source: str) -> bool:
    """Whether ``source`` calls a function named ``check_…``."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return False
    return any(isinstance(node, ast.Call) and (
        getattr(node.func, "attr", "") or getattr(node.func, "id", "")).startswith("check_")
        for node in ast.walk(tree))


@machinery_function
def note_call(name: str, args: tuple, output: object) -> None:
    """Record a call of the loaded function ``name`` in the task cell running now, if any."""
    run = _RECORD.current
    if run is not None:
        copies = tuple(map(_copied, args))
        kept = output.copy() if isinstance(output, np.ndarray) else output
        run.saved_calls.append(SavedCall(name, copies, kept))


@machinery_function
def _copied(value: object) -> object:
    return value.copy() if isinstance(value, np.ndarray) else value


def recorded(name: str, function: Callable) -> Callable:
    """``function`` (a loaded saved function) noting each of its calls with :func:`note_call`."""

    def recording(*args: object, **kwargs: object) -> object:
        output = function(*args, **kwargs)
        note_call(name, args + tuple(kwargs.values()), output)
        return output

    recording.__name__ = recording.__qualname__ = getattr(function, "__name__", name)
    recording.__doc__ = getattr(function, "__doc__", None)
    recording.__wrapped__ = function  # type: ignore[attr-defined]
    return machinery_function(recording)


def _reset() -> None:
    """Forget every run and registered shell (tests)."""
    _RECORD._stop()
    _RECORD.__init__()
