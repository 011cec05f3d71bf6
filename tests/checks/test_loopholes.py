"""Issue 23 §1, the loophole test: every public and private function of the pack, tried as
the student's answer, in every function task and every top-level and one-trial task.

The pack's functions and methods are walked module by module (``pack_functions``). Each is
entered with ``None`` for every parameter it needs (the profile hook sees the call as its
frame starts, before its first line fails on ``None``), so no argument has to be right for
the call to count: a student's function or task cell that reaches it in any way reaches the
same frame.

- Function tasks: each check runs the student's function through
  ``checks.machinery.call_student``; a student function that calls any pack function, at
  its top or in the middle of otherwise correct code behind a bare ``except``, fails naming
  it. Only the machinery around a loaded function (``student_code.calling.machinery``)
  may run, and each function task's allowlist is empty.
- Top-level and one-trial tasks: a task cell that calls any pack function has it in its
  record, and each check of ``own_work.TOP_LEVEL`` refuses it exactly when its forbidden set
  covers it.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from cell_runner import CellRunner

import lqe_helpers
from lqe_helpers.checks import CheckFailed, machinery, own_work
from lqe_helpers.student_code import calling, outside

#: The worked answers of the function tasks (what the student's function computes after
#: the pack's call), with arguments of each task's check, by the function the task asks for.
FUNCTION_TASKS = {
    "my_transition_matrix": (
        lambda dt: np.array([[1.0, dt, dt**2 / 2], [0.0, 1.0, dt], [0.0, 0.0, 1.0]]), (0.01,)),
    "predict_covariance": (lambda P, F, G, sigma: F @ P @ F.T + sigma**2 * G @ G.T,
                          (np.eye(3), np.eye(3), np.ones((3, 1)), 2.0)),
    "my_filter": (lambda y, A, C, Q, R, z0, P0: np.zeros((len(y), len(z0))),
                     (np.zeros((4, 1)), np.eye(2), np.ones((1, 2)), np.eye(2), np.eye(1),
                      np.zeros(2), np.eye(2))),
    "vision_trial": (lambda sigma_v: (np.zeros((4, 1)), np.zeros((4, 3))), (1.5,)),
    "my_smoother": (lambda y, alpha: np.asarray(y, dtype=float), (np.zeros((1, 4)), 0.5)),
    "compensate": (lambda estimates, A, delay_steps: estimates @ A.T,
                           (np.zeros((4, 2)), np.eye(2), 0)),
}


def pack_functions() -> list[tuple[str, types.FunctionType]]:
    """Every Python function of the pack: module level, in classes (methods, properties,
    static and class methods), public and private, by qualified name."""
    found: dict[types.CodeType, tuple[str, types.FunctionType]] = {}

    def add(function: object, module: str) -> None:
        function = inspect.unwrap(function) if callable(function) else function
        if isinstance(function, types.FunctionType) and calling.in_pack(
                function.__code__.co_filename):
            found.setdefault(function.__code__,
                             (f"{function.__module__}.{function.__qualname__}", function))

    for info in pkgutil.walk_packages(lqe_helpers.__path__, f"{lqe_helpers.__name__}."):
        module = importlib.import_module(info.name)
        for value in list(vars(module).values()):
            if getattr(value, "__module__", None) != module.__name__:
                continue
            add(value, module.__name__)
            if isinstance(value, type):
                for member in vars(value).values():
                    if isinstance(member, (staticmethod, classmethod)):
                        member = member.__func__
                    if isinstance(member, property):
                        for accessor in (member.fget, member.fset, member.fdel):
                            add(accessor, module.__name__)
                    else:
                        add(member, module.__name__)
    return sorted(found.values(), key=lambda item: item[0])


FUNCTIONS = pack_functions()


class _Entered(BaseException):
    """Stops a pack function as its frame starts: none of its lines runs."""


def enter(function: types.FunctionType) -> None:
    """Enter ``function``'s frame (None for each parameter it needs) and leave at once.

    A profile hook chained after any already set (the watch, the task-cell record, which
    see the call first) raises as the frame starts, so not one line of it runs: a function
    with side effects (a tool's main, the plot style) is entered safely.
    """
    signature = inspect.signature(function, follow_wrapped=False)
    args, kwargs = [], {}
    for parameter in signature.parameters.values():
        if parameter.default is not parameter.empty:
            continue
        if parameter.kind in (parameter.POSITIONAL_ONLY, parameter.POSITIONAL_OR_KEYWORD):
            args.append(None)
        elif parameter.kind is parameter.KEYWORD_ONLY:
            kwargs[parameter.name] = None
    previous = sys.getprofile()

    def stop(frame: types.FrameType, event: str, arg: object) -> None:
        if previous is not None:
            previous(frame, event, arg)
        if event == "call" and frame.f_code is function.__code__:
            raise _Entered

    sys.setprofile(stop)
    try:
        result = function(*args, **kwargs)
        if inspect.isgenerator(result):  # a generator function's frame starts at next()
            next(result)
    except BaseException:
        pass
    finally:
        sys.setprofile(previous)


def test_the_walk_finds_the_packs_functions_public_and_private() -> None:
    names = {name for name, _ in FUNCTIONS}
    assert len(FUNCTIONS) > 500
    for name in ("lqe_helpers.filter.kalman_filter", "lqe_helpers._engine._covariance_sequence",
                 "lqe_helpers.prediction._propagate", "lqe_helpers.scenario.Scenario.A",
                 "lqe_helpers.experiments.Tracking.positions",
                 "lqe_helpers.bias_model.equations.transition_matrix"):
        assert name in names, name


@pytest.fixture
def enter_is_a_library(monkeypatch):
    """:func:`enter` sets its own profile hook, which a student's code may not: for these
    tests its file counts as a library's."""
    library = outside.installation_file
    monkeypatch.setattr(outside, "installation_file",
                        lambda path: path == __file__ or library(path))


@pytest.mark.slow
@pytest.mark.parametrize("task", list(FUNCTION_TASKS))
@pytest.mark.usefixtures("enter_is_a_library")
def test_no_function_of_the_pack_passes_as_a_function_tasks_answer(task) -> None:
    """Every pack function, called at the top and in the middle (behind a bare except) of
    the task's worked answer: the call fails naming it, except the machinery."""
    worked, args = FUNCTION_TASKS[task]
    allowed = own_work.FUNCTION_TASKS[task]
    machinery_only = []
    for name, function in FUNCTIONS:
        def at_the_top(*given, function=function):
            enter(function)
            return worked(*given)

        def in_the_middle(*given, function=function):
            first = worked(*given)
            try:
                enter(function)
            except:  # noqa: E722 - a student's bare except must not hide it either
                pass
            return first

        for student in (at_the_top, in_the_middle):
            try:
                machinery.call_student(student, *args, name="answer", where="", allow=allowed)
            except CheckFailed as failure:
                assert f"runs the pack's own {calling.shown_function(name)}" in str(failure), \
                    (name, str(failure))
            else:
                machinery_only.append(name)
    assert set(machinery_only) == {name for name, function in FUNCTIONS
                                   if calling.machinery(function.__code__)
                                   or function in allowed}
    assert set(machinery_only) <= MACHINERY | {f"{f.__module__}.{f.__qualname__}" for f in allowed}


def test_every_function_task_is_called_with_its_allowlist() -> None:
    """Each call_student of the checks passes allow=FUNCTION_TASKS[<the task's function>],
    and every function task of own_work has a check calling it (and is tried above)."""
    used = set()
    folder = Path(own_work.__file__).parent
    for path in sorted(folder.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text("utf-8"))):
            if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "call_student":
                [allow] = [keyword.value for keyword in node.keywords if keyword.arg == "allow"]
                assert isinstance(allow, ast.Subscript), (path.name, node.lineno)
                assert getattr(allow.value, "id", "") == "FUNCTION_TASKS", (path.name, node.lineno)
                used.add(allow.slice.value)
    assert used == set(own_work.FUNCTION_TASKS) == set(FUNCTION_TASKS)


#: The only pack functions a student's function may run: the wrappers around it.
MACHINERY = {
    # running.py: the time limit's signal handler and the hooks that stop the function
    "lqe_helpers.student_code.running.TimeIsUp.__del__",
    "lqe_helpers.student_code.running._Stopper.__init__",
    "lqe_helpers.student_code.running._Stopper.end",
    "lqe_helpers.student_code.running._Stopper.error",
    "lqe_helpers.student_code.running._Stopper.give_room",
    "lqe_helpers.student_code.running._Stopper.in_hooks",
    "lqe_helpers.student_code.running._Stopper.mark",
    "lqe_helpers.student_code.running._Stopper.profile",
    "lqe_helpers.student_code.running._Stopper.rearm",
    "lqe_helpers.student_code.running._Stopper.retrace",
    "lqe_helpers.student_code.running._Stopper.stop",
    "lqe_helpers.student_code.running._Stopper.take_room_back",
    "lqe_helpers.student_code.running._Stopper.trace",
    "lqe_helpers.student_code.running._Stopper.trace_stack",
    "lqe_helpers.student_code.running._send",
    "lqe_helpers.student_code.running.run_in_thread",
    "lqe_helpers.student_code.running.run_with_alarm",
    "lqe_helpers.student_code.running._unraisable",
    # calling.py: what guards.py asks while it reports a loaded function's error
    "lqe_helpers.student_code.calling.inside_call",
    "lqe_helpers.student_code.calling.reported",
    "lqe_helpers.student_code.guards._readings_problem",
    "lqe_helpers.student_code.keeping._not_saved_yet.<locals>.stand_in",
    "lqe_helpers.student_code.task_runs.recorded.<locals>.recording",
    "lqe_helpers.student_code.task_runs.note_call",
    "lqe_helpers.student_code.task_runs.copied",
    "lqe_helpers.student_code.guards._sized",
    "lqe_helpers.student_code.guards.filter_inputs_problem",
    "lqe_helpers.student_code.guards.compensate_inputs_problem",
    "lqe_helpers.student_code.guards.guarded",
    "lqe_helpers.student_code.guards.guarded.<locals>.checked",
    # outside.py: the audit hook hearing a student's function read a file or run a program
    "lqe_helpers.student_code.outside._heard",
    "lqe_helpers.student_code.outside.use_of_outside",
    "lqe_helpers.student_code.outside.installation_file",
    "lqe_helpers.student_code.outside._installation_folders",
    "lqe_helpers.student_code.outside._shown",
    "lqe_helpers.student_code.outside.c_call_use",
    "lqe_helpers.student_code.outside.dropping",
    "lqe_helpers.student_code.outside.tampering",
    "lqe_helpers.student_code.outside.time_is_up",
    "lqe_helpers.student_code.running._Stopper.time_is_up",
    "lqe_helpers.student_code.calling._watch_kept",
    "lqe_helpers.student_code.running.is_time_limit_hook",
}


def test_the_machinery_is_what_wraps_a_loaded_function_and_nothing_else() -> None:
    names = {name for name, function in FUNCTIONS if calling.machinery(function.__code__)}
    assert names <= MACHINERY, names - MACHINERY


@pytest.mark.slow
@pytest.mark.usefixtures("enter_is_a_library")
def test_every_function_of_the_pack_a_task_cell_runs_is_refused_by_each_task_forbidding_it():
    """Each pack function entered in a task cell is in its record; each top-level and
    one-trial check refuses it exactly when its forbidden set covers it."""
    runner = CellRunner()
    refused = {check: set() for check in own_work.TOP_LEVEL}
    try:
        runner.namespace["enter"] = enter
        for name, function in FUNCTIONS:
            runner.namespace["pack_function"] = function
            assert runner.run("# Task: anything\nenter(pack_function)\n") is None
            run = own_work.task_runs._RECORD.runs[-1]
            assert name in run.pack_calls.values() or name.startswith(  # the record's own
                ("lqe_helpers.student_code.task_runs.", "lqe_helpers.student_code.outside.")), name
            for check in own_work.TOP_LEVEL:
                problem = own_work.task_problem(check, (), run)
                covered = any(own_work.covers(entry, name)
                              for entry in (*own_work.TOP_LEVEL[check], own_work.CHECKS))
                if covered:
                    assert problem is not None and "runs the pack's" in problem, (check, name)
                    refused[check].add(name)
                else:
                    assert problem is None, (check, name, problem)
    finally:
        runner.close()
    for check, names in refused.items():
        assert names, check


def test_a_new_object_of_the_pack_is_named_by_its_class() -> None:
    """The fifth trial: making a Scenario with dataclasses.replace inside a function task
    was refused naming Scenario.__post_init__, an inner method the student never wrote."""
    import dataclasses

    from lqe_helpers.scenario import DEFAULT

    def my_transition_matrix(dt):
        dataclasses.replace(DEFAULT, sigma_v=2.0)
        return np.eye(3)

    with pytest.raises(CheckFailed) as failure:
        machinery.call_student(my_transition_matrix, 0.01, name="my_transition_matrix",
                               where="", allow=())
    assert "runs the pack's own lqe_helpers.scenario.Scenario (making a new one)" in str(
        failure.value)
    assert "__post_init__" not in str(failure.value)
