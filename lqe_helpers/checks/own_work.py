"""The student's own work: what each task may not take from the pack, and stale values.

Two kinds of task, two guards:

- **Function tasks** (the student writes a function the check calls: ``my_transition_matrix``,
  ``predict_covariance``, ``my_filter``, ``vision_trial``, ``my_smoother``, ``compensate``):
  every check calls it through :func:`~lqe_helpers.checks.machinery.call_student`, which
  refuses every function of the pack (public or private, any module, at any depth) while the
  student's function runs (``student_code.call(..., forbid_pack=True)``) but those of the
  task's allowlist, :data:`FUNCTION_TASKS` (each call site passes its task's entry).
- **Top-level tasks** (the student writes code in the task cell): the task-cell record
  (:mod:`lqe_helpers.student_code.task_runs`, registered by ``student_code.brief_errors()``
  in every notebook's set-up cell) notes which of the pack's functions a task cell ran.
  :data:`TOP_LEVEL` lists, per check, the pack functions that compute the task's answer
  (the primitive ones: the record sees calls at any depth, so listing
  ``model.observation_matrix`` also catches ``experiments.filter_model`` and
  ``experiments.track``); a check refuses values whose task cell ran one of them, or drew
  on a cell the student wrote that ran one (:func:`~lqe_helpers.student_code.task_runs.ancestry`:
  a pack result computed in an earlier cell and copied is no more the student's own). The
  function tasks have an entry too, for the same trail from the cell defining the function.
  :data:`DRIVEN` lists, per one-trial check of 02–05, the values the student's saved
  ``my_filter`` (and 05's ``compensate``) must have produced in the task cell: each must
  equal the output of one of that cell's recorded calls of the loaded function.

:func:`judged` wraps every exported check (``checks/__init__.py``): before the check judges
anything it finds the check's task cell (:func:`~lqe_helpers.student_code.task_runs.run_for`)
and refuses when that cell's latest run stopped with an error, ran a forbidden function,
took numbers from outside the notebook (a file, another program: :func:`trail_problem`), or
did not produce the values with the student's function. Without the record (plain Python,
pytest, or before the set-up cell) a check behaves as without this module.
"""

from __future__ import annotations

import contextlib
import functools
import io
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from ..scenario import Scenario
from ..student_code import outside, task_runs
from ..student_code.calling import machinery_function
from ..student_code.cell_code import untraceable_reads
from .machinery import FUNCTION_RTOL, CheckFailed, close

__tracebackhide__ = True  # pytest: leave these frames out of a failure's traceback

#: The scenario's data a task may read (``DEFAULT.truth``, ``DEFAULT.unit_noise(...)``,
#: ``DEFAULT.dt``, ...): the getters of :class:`~lqe_helpers.scenario.Scenario`'s properties
#: and its noise draws. Reading the task's inputs computes none of its answer.
SCENARIO_DATA: tuple[Callable, ...] = (
    *(member.fget for member in vars(Scenario).values() if isinstance(member, property)),
    Scenario.unit_noise)

#: Per function task (by the function the student writes): the pack functions its text lets
#: the student use inside it. Empty for the tasks that get every input as an argument: each
#: asks for the equation written with NumPy.
FUNCTION_TASKS: dict[str, tuple[Callable, ...]] = {
    "my_transition_matrix": (),   # 00 Task 1
    "predict_covariance": (),     # 00 Task 2 (and Going further's covariance step)
    "my_filter": (),              # 01 Task 1
    "vision_trial": SCENARIO_DATA,  # 01 Task 2: the trial's data, then the student's my_filter
    "my_smoother": (),            # 01 Going further
    "compensate": (),             # 05 Task 1
}

#: The pack's filter engine: eq. (5) and everything built on it (a name ending in "." is
#: a whole module).
FILTER_ENGINE = ("lqe_helpers.filter.", "lqe_helpers._engine._covariance_sequence",
                 "lqe_helpers._engine.filter_run", "lqe_helpers._engine.riccati",
                 "lqe_helpers.steady_state.", "lqe_helpers.lowpass.", "lqe_helpers.fixed_gain.",
                 "lqe_helpers.bias_model.tracking.")

#: The pack's delay compensation, eq. (7), and its delayed runs.
COMPENSATION = ("lqe_helpers.prediction.predict_ahead",
                "lqe_helpers.experiments.delay_and_compensate",
                "lqe_helpers.experiments.DelayedTracking")

#: The pack's readings, truth + σ · noise (eq. (3)).
READINGS = ("lqe_helpers._engine.readings", "lqe_helpers.simulation.measure",
            "lqe_helpers.experiments.readings", "lqe_helpers.experiments.track")

#: Per check of a top-level task: the pack functions that compute its answer. A name is a
#: function's qualified name (``module.qualname``): it covers the function and whatever is
#: defined inside it (a class: its methods); a name ending in "." covers a whole module.
TOP_LEVEL: dict[str, tuple[str, ...]] = {
    # 00 Task 1: A of eq. (4)
    "check_transition_matrix": ("lqe_helpers.model.transition_matrix",
                                "lqe_helpers.bias_model.equations.transition_matrix"),
    # 00 Task 2: the covariance carried forward, F P Fᵀ + G σ² Gᵀ (the function, its use)
    "check_covariance_step": ("lqe_helpers.prediction.",
                              "lqe_helpers._matrices.input_noise_covariance",
                              "lqe_helpers.model.process_noise_covariance"),
    "check_eyes_closed": ("lqe_helpers.prediction.", "lqe_helpers._matrices.input_noise_covariance",
                          "lqe_helpers.model.process_noise_covariance"),
    # 00 Task 3: σ_j of each period
    "check_jerk_stds": ("lqe_helpers.scenario.matched_jerk_std",),
    # 01 Task 1: my_filter, eq. (5); Task 2: vision_trial, the readings and my_filter on them
    "check_filter": FILTER_ENGINE,
    "check_vision_trial": FILTER_ENGINE + READINGS,
    # 01 Going further: the smoother
    "check_smoother": (*FILTER_ENGINE, "lqe_helpers.smoothing."),
    # 05 Task 1: compensate, eq. (7)
    "check_compensation": COMPENSATION,
    # 02 Task 1, 03 Task 2, 04 Task 2: one trial of the student's my_filter
    "check_start_of_trial": FILTER_ENGINE,
    "check_fusion_trial": FILTER_ENGINE,
    "check_noisier_trial": FILTER_ENGINE,
    # 03 Task 1: C and R of both senses; 04 Task 1: R
    "check_fusion": ("lqe_helpers.model.observation_matrix",
                     "lqe_helpers.model.measurement_noise_covariance",
                     "lqe_helpers._matrices.observation", "lqe_helpers._matrices.noise_covariance"),
    "check_noisier_sense": ("lqe_helpers.model.measurement_noise_covariance",
                            "lqe_helpers._matrices.noise_covariance"),
    # 05 Task 2: one trial delayed and compensated by the student's my_filter and compensate
    "check_delay_signals": FILTER_ENGINE + COMPENSATION,
    # 06 Task 1: F, G and Q of the bias model
    "check_bias_model": ("lqe_helpers.bias_model.equations.transition_matrix",
                         "lqe_helpers.bias_model.equations.input_matrix",
                         "lqe_helpers.bias_model.equations.process_noise_covariance",
                         "lqe_helpers.bias_model.tracking.",
                         "lqe_helpers._matrices.input_noise_covariance"),
}


@dataclass(frozen=True)
class Produced:
    """A value a check is given that the student's saved function must have produced.

    ``position`` is the argument's index in the check's call. The value must equal one
    recorded output of ``function`` in the task cell, whole or one column of it (a wrong
    column is the check's to name), or (``delayed``) such a column shifted by a delay (its
    leading NaN rows).
    """

    position: int
    name: str
    function: str
    delayed: bool = False


#: Per one-trial check: the values the student's saved functions must have produced in the
#: task cell (the function's calls recorded by its loaded wrapper).
DRIVEN: dict[str, tuple[Produced, ...]] = {
    "check_start_of_trial": (Produced(2, "estimates_small", "my_filter"),
                             Produced(3, "estimates_large", "my_filter")),
    "check_fusion_trial": (Produced(0, "vision_positions", "my_filter"),
                           Produced(1, "fused_positions", "my_filter")),
    "check_noisier_trial": (Produced(0, "vision_positions", "my_filter"),
                            Produced(1, "fused_positions", "my_filter")),
    "check_delay_signals": (Produced(1, "delayed", "my_filter", delayed=True),
                            Produced(2, "compensated", "compensate")),
}

RERUN = "fix it and run it again, then this check"


def covers(entry: str, name: str) -> bool:
    """Whether the entry ``entry`` of :data:`TOP_LEVEL` covers the pack function ``name``."""
    if entry.endswith("."):
        return name.startswith(entry)
    return name == entry or name.startswith(f"{entry}.")


@dataclass(frozen=True)
class Forbidden:
    """A function of a check's forbidden set run by a cell that made the check's values."""

    name: str               # the forbidden function ("lqe_helpers._engine.filter_run")
    entry: str              # the pack function the cell called that ran it
    cell: task_runs.TaskRun  # the cell: the task cell or one of the student's it drew on


#: The checks' own code: it computes every task's answer, so a cell may run it only through
#: a check (:data:`A_CHECK`), which gives no answer away.
CHECKS = "lqe_helpers.checks."
A_CHECK = "lqe_helpers.checks.own_work.judged."


def forbidden_calls(check: str, run: task_runs.TaskRun) -> list[Forbidden]:
    """The functions of ``check``'s forbidden set (and of the checks' own code, but through a
    check) run by the task run ``run`` or by a cell of the student's whose values it drew on
    (:func:`~lqe_helpers.student_code.task_runs.ancestry`), the task cell's first, each
    cell's in the order it first ran them."""
    entries = (*TOP_LEVEL.get(check, ()), CHECKS)
    return [Forbidden(name, cell.entries.get(name, name), cell)
            for cell in task_runs.ancestry(run)
            for name in dict.fromkeys(cell.pack_calls.values())
            if not cell.entries.get(name, name).startswith(A_CHECK)
            and any(covers(entry, name) for entry in entries)]


def _short(name: str) -> str:
    """A pack function's name as a notebook writes it: ``experiments.track``."""
    return name.removeprefix("lqe_helpers.")


def _public(name: str) -> str:
    """A pack function's name as a notebook writes it, without what is defined inside it:
    ``model.transition_matrix`` for ``lqe_helpers.model.transition_matrix.<locals>.<lambda>``."""
    return _short(name).split(".<locals>", 1)[0]


def _runs(entry: str, name: str) -> str:
    """"the pack's own X", or "the pack's X, which runs its own Y" for an inner function."""
    entry, name = _public(entry), _public(name)
    return (f"the pack's own {entry}" if entry == name else
            f"the pack's {entry}, which runs its own {name}")


def forbidden_text(found: Forbidden, run: task_runs.TaskRun) -> str:
    """What a check says of ``found``, run by ``run`` or by a cell it drew on."""
    runs = _runs(found.entry, found.name)
    if found.cell.number == run.number:
        return (f"the task cell above runs {runs}: that computes what this task asks you to "
                f"compute yourself, from the equation, with NumPy, and with the pack's answer "
                f"made in the same cell the check cannot tell yours from it. Take that call "
                f"out (compare with the pack in a new cell below this check, if you like), run "
                f"the task cell, then this check again")
    return (f"the task cell above uses {_drawn(found.cell, run)} from a cell you ran before it "
            f"(`{found.cell.first_line[:60]}`), and that cell runs {runs}: a value the pack "
            f"computed there and copied is not your own work. If that cell is one of yours, "
            f"make the values in the task cell with your own code; if it is a cell of the "
            f"notebook whose code you changed, put its code back as it was and run it again. "
            f"Then run the task cell and this check")


def _drawn(cell: task_runs.TaskRun, run: task_runs.TaskRun) -> str:
    """The names of ``cell``'s values that ``run`` draws on: "C, R" ("a value" if none)."""
    names = cell.defines & set().union(*(other.reads for other in task_runs.ancestry(run)))
    return ", ".join(sorted(names)) or "a value"


def trail_problem(check: str, run: task_runs.TaskRun) -> str | None:
    """Why the values of the task run ``run`` or of a cell of the student's they draw on
    (:func:`~lqe_helpers.student_code.task_runs.ancestry`) may be the pack's, or None: a
    function of ``check``'s forbidden set ran there (:func:`forbidden_calls`), or the cell
    took something from outside the notebook (a file it read, another program it ran:
    :attr:`~lqe_helpers.student_code.task_runs.TaskRun.outside`), whose numbers the record
    cannot trace; or the values come from a cell the notebook gives further on, run before
    its turn, or reach the cell by names made as it runs (``globals()[...]``, ``builtins``,
    ``Out``: :func:`~lqe_helpers.student_code.cell_code.untraceable_reads`)."""
    used = forbidden_calls(check, run)
    if used:
        return forbidden_text(used[0], run)
    for cell in task_runs.ancestry(run):
        where = ("the task cell above" if cell.number == run.number else
                 f"a cell you ran before the task cell (`{cell.first_line[:60]}`), whose "
                 f"values it uses,")
        if cell.outside:
            return (f"{where} {cell.outside[0]}. {outside.UNTRACEABLE}. Compute them in "
                    f"the notebook itself, with your own code, run that cell, then this check "
                    f"again")
        if cell.given:  # on the trail, a given cell comes after the task (see ancestry)
            return (f"the task cell above uses {_drawn(cell, run)} from a cell of the "
                    f"notebook that comes after this task (`{cell.first_line[:60]}`), which "
                    f"you ran before it: its values are the notebook's, not your own work. "
                    f"Make them in the task cell with your own code, run it, then this check")
        reads = untraceable_reads(cell.source)
        if reads:
            return (f"{where} reaches values through {', '.join(reads)}: a value found by a "
                    f"name made as the code runs, or kept outside the notebook's names, "
                    f"cannot be traced to your own work. Use the variables by their names, "
                    f"run the cell, then this check again")
    return None


def _candidates(output: np.ndarray, delayed: bool, late: int) -> list[np.ndarray]:
    """What a value made from ``output`` may be: it whole, or one of its columns, (delayed:)
    shifted ``late`` rows down behind NaN."""
    found = [output] + [output[..., column] for column in range(output.shape[-1])
                        if output.ndim >= 2]
    if delayed:
        found = [np.concatenate([np.full((late, *part.shape[1:]), np.nan),
                                 part[: len(part) - late]]) for part in found if part.ndim]
    return found


def _saved_calls(run: task_runs.TaskRun) -> list[task_runs.SavedCall]:
    """The calls of the student's saved functions made by ``run`` and by the cells of the
    student's whose values it draws on (a task written over two cells)."""
    return [call for cell in task_runs.ancestry(run) for call in cell.saved_calls]


def _produced_by(value: object, wanted: Produced, run: task_runs.TaskRun) -> bool:
    try:
        value = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return True  # not an array of numbers: the check itself says what is wrong with it
    if value.ndim == 0:
        return True
    missing = np.isnan(value).reshape(len(value), -1).all(axis=1)
    late = int(np.argmin(missing)) if not missing.all() else len(value)
    for call in _saved_calls(run):
        if call.name != wanted.function:
            continue
        try:
            output = np.asarray(call.output, dtype=float)
        except (TypeError, ValueError):
            continue
        if output.ndim == 0 or len(output) != len(value):
            continue
        if any(close(value, candidate, FUNCTION_RTOL)
               for candidate in _candidates(output, wanted.delayed, late)):
            return True
    return False


def task_problem(check: str, args: tuple, run: task_runs.TaskRun) -> str | None:
    """What makes ``check``'s values not the current task cell's own work, or None."""
    if run.not_written:
        return ("the task cell above is not written yet: replace its line `raise "
                "NotImplementedError` with your code, run that cell, then this check again")
    if not run.completed:
        stopped = ("ran a cell of its own (get_ipython().run_cell) that stopped with an error"
                   if run.inner_failed else "stopped with an error")
        return (f"the task cell above {stopped}: {RERUN} (it judges what that cell makes, not "
                f"the values of an earlier run)")
    problem = trail_problem(check, run)
    if problem is not None:
        return problem
    for wanted in DRIVEN.get(check, ()):
        if wanted.position >= len(args):
            continue
        called = any(call.name == wanted.function for call in _saved_calls(run))
        if not called:
            return (f"the task cell above does not run your {wanted.function} (nor does a "
                    f"cell of yours whose values it uses): this task is "
                    f"done with your own {wanted.function} (loaded from my_functions/). Use it "
                    f"there, run that cell, then this check again")
    return None


def provenance_problem(check: str, args: tuple, run: task_runs.TaskRun) -> str | None:
    """Which value of ``check`` (right, as the check found) did not come from the student's
    saved function in the task cell ``run``, or None. Asked after the check passed, so
    that a wrong value gets its own cause (a delay with np.roll, say) first."""
    for wanted in DRIVEN.get(check, ()):
        if wanted.position < len(args) and not _produced_by(args[wanted.position], wanted,
                                                            run):
            return (f"{wanted.name} is not what your {wanted.function} returned in the task "
                    f"cell above: compute it from your {wanted.function}'s output, run that "
                    f"cell, then this check again")
    return None


def _leaves(value: object, depth: int = 2) -> list[np.ndarray]:
    """The numbers and numeric arrays in ``value`` (its items, to ``depth`` levels)."""
    if isinstance(value, dict):
        items = list(value.values())
    elif isinstance(value, (list, tuple)):
        items = list(value)
    else:
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            return []
        return [array] if array.size else []
    if depth == 0:
        return []
    return [leaf for item in items[:100] for leaf in _leaves(item, depth - 1)]


#: Code that can carry a value out of a cell without a name: files, globals, attributes.
_HIDDEN_CHANNEL = re.compile(
    r"\b(open|save|savez|savez_compressed|savetxt|tofile|dump|dumps|pickle|shelve|json|"
    r"globals|locals|vars|setattr|exec|eval|builtins|__builtins__|__dict__|modules|"
    r"write_text|write_bytes|store)\b|^\s*[%!]|\.[A-Za-z_]\w*\s*=[^=]", re.MULTILINE)


def copied_result(check: str, args: tuple, run: task_runs.TaskRun) -> str | None:
    """Which value of ``check`` (right, as the check found) equals a result of its forbidden
    set that a cell of the student's computed before the task cell, or None.

    The trail of :func:`forbidden_calls` follows names; a value can also travel through a
    file, a module's attribute or ``globals()``. What the check is given is compared, number
    for number, with what the pack's functions of the task returned in the student's earlier
    cells; an earlier version of the task cell (it defines a name the check is given, and
    has no code that could carry a value out of it otherwise) is replaced by this one. A
    one-trial check (:data:`DRIVEN`) is left to the record of the student's function.
    """
    entries = TOP_LEVEL.get(check, ())
    if check in DRIVEN or not entries:
        return None
    given = task_runs.argument_names(task_runs.current_cell(), check)
    earlier = [(cell, name, result) for cell, name, result in task_runs.earlier_results(run, check)
               if any(covers(entry, name) for entry in entries)
               and not cell.entries.get(name, name).startswith(A_CHECK)
               and (not cell.defines & set(given) or _HIDDEN_CHANNEL.search(cell.source))]
    for position, value in enumerate(args):
        for leaf in _leaves(value):
            for cell, name, result in earlier:
                if leaf.shape == result.shape and np.allclose(leaf, result, rtol=1e-12,
                                                              atol=0.0):
                    what = given[position] if position < len(given) else "a value"
                    return (f"{what} equals a value the pack's "
                            f"{_public(cell.entries.get(name, name))} computed in a cell you "
                            f"ran before the task cell (`{cell.first_line[:60]}`): the check "
                            f"cannot tell it from the pack's answer. If that cell is one of the "
                            f"notebook's whose code you changed, put its code back as it was. "
                            f"If you computed the value yourself, restart the kernel (Kernel → "
                            f"Restart Kernel), run the cells above the task without that one, "
                            f"then the task cell and this check")
    return None


def judged(check: Callable) -> Callable:
    """``check`` refusing values that are not its current task cell's own work (see above)."""
    name = check.__name__

    @functools.wraps(check)
    def judged_check(*args: object, **kwargs: object) -> object:
        __tracebackhide__ = True
        run = task_runs.run_for(name)
        if run is None:
            return check(*args, **kwargs)
        problem = task_problem(name, args, run)
        if problem is not None:
            raise CheckFailed(problem)
        with contextlib.redirect_stdout(io.StringIO()) as said:  # its ✓ line, if it passes
            result = check(*args, **kwargs)
        problem = provenance_problem(name, args, run) or copied_result(name, args, run)
        if problem is not None:
            raise CheckFailed(problem)
        run.passed.add(name)
        print(said.getvalue(), end="")
        return result

    return judged_check


@contextlib.contextmanager
def outputs_of(function: Callable, name: str) -> Iterator[list[object] | None]:
    """The outputs of ``name`` (the student's ``my_filter``) while ``function`` runs.

    ``function`` (the student's ``vision_trial``) reads ``name`` from its module's globals
    (the notebook's): for the time of the ``with`` block that global is a wrapper that
    notes each output, and it is put back afterwards whatever happens. Yields the list of
    outputs, or None when ``function`` has no such global to watch.
    """
    namespace = getattr(function, "__globals__", None)
    watched = namespace.get(name) if isinstance(namespace, dict) else None
    if not callable(watched):
        yield None
        return
    outputs: list[object] = []
    noting = task_runs.recorded(
        name, watched, note=machinery_function(
            lambda _name, _args, output: outputs.append(task_runs.copied(output))))
    namespace[name] = noting
    try:
        yield outputs
    finally:
        if namespace.get(name) is noting:
            namespace[name] = watched


def not_driven(value: np.ndarray, outputs: list[object] | None, name: str,
               function: str) -> str | None:
    """Why ``value`` (right, as the check found) is not an output of the student's ``name``
    recorded while their ``function`` ran (:func:`outputs_of`), or None."""
    if outputs is None or not outputs:
        return (f"{function} does not run your {name}: the task is to filter the readings with "
                f"your own {name} from Task 1, inside {function}. Call it there, run that "
                f"cell, then this check again")
    for output in outputs:
        try:
            output = np.asarray(output, dtype=float)
        except (TypeError, ValueError):
            continue
        if output.shape == value.shape and close(value, output, FUNCTION_RTOL):
            return None
    return (f"the estimates {function} returns are not what your {name} returned inside it: "
            f"return {name}'s output, run that cell, then this check again")
