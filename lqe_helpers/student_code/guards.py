"""Input guards of the functions a student saves: a wrong-sized input named before it runs.

A student's ``my_filter`` loaded in a later notebook meets inputs its author never tried:
two senses, one sense cut out of two. Given ``y[:, :1]`` with both senses' R, a loop of
eq. (5) stops inside the saved file with numpy's "matmul: … mismatch in its core
dimension", or (with both senses' C) runs on silently by broadcasting. :func:`guarded`
wraps such a function so that inputs whose sizes do not agree stop at the student's own
call with one line naming the input and the size it needs.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from . import calling
from .errors import StudentCodeError

__tracebackhide__ = True  # pytest: leave these frames out of a failure's traceback


def _sized(value: object) -> tuple[int, ...] | None:
    try:
        return np.shape(value)
    except ValueError:  # a ragged list: the student's function reports it itself
        return None


def filter_inputs_problem(y: object, A: object, C: object, Q: object, R: object, z0: object,
                          P0: object) -> str | None:
    """What does not fit in the inputs of ``my_filter(y, A, C, Q, R, z0, P0)``, or None.

    With k states and m sensors: y (n, m), A, Q and P0 (k, k), C (m, k), R (m, m), z0 (k,).
    """
    shapes = {name: _sized(value) for name, value in
              (("y", y), ("A", A), ("C", C), ("Q", Q), ("R", R), ("z0", z0), ("P0", P0))}
    if any(shape is None for shape in shapes.values()):
        return None
    if len(shapes["y"]) != 2:
        return (f"y has shape {shapes['y']}; it must be (n, m): one row per time step, one "
                f"column per sensor (a single sensor's readings as y[:, :1] or y[:, None])")
    m = shapes["y"][1]
    if len(shapes["A"]) != 2 or shapes["A"][0] != shapes["A"][1]:
        return f"A has shape {shapes['A']}; it must be square, (k, k) for k states"
    k = shapes["A"][0]
    sensors = f"{m} sensor{'s' * (m != 1)} (the columns of y, shape {shapes['y']})"
    rows_of_c = shapes["C"][0] if len(shapes["C"]) == 2 else None
    if m == shapes["y"][0] > 3 and rows_of_c is not None and rows_of_c != m:
        # y is square while C has another number of sensors: the mark of an (n,) array
        # added to an (n, 1) one, which numpy broadcasts to (n, n).
        return (f"y has shape {shapes['y']}, one column per time step, while C is for "
                f"{rows_of_c} sensor{'s' * (rows_of_c != 1)}: y must be (n, {rows_of_c}). An "
                f"(n,) array added to an (n, 1) one makes (n, n): make both (n, 1) first")
    problem = _readings_problem(shapes, rows_of_c, k)
    if problem is not None:
        return problem
    if shapes["C"] != (m, k):
        cut = (" (for vision alone, C[:1] with y[:, :1])"
               if m == 1 and len(shapes["C"]) == 2 and shapes["C"][0] > 1 else "")
        return (f"C has shape {shapes['C']}; for {sensors} and {k} states it must be "
                f"({m}, {k}): one row per sensor{cut}")
    if shapes["R"] != (m, m):
        cut = (" (for vision alone, R[:1, :1])"
               if m == 1 and len(shapes["R"]) == 2 and shapes["R"][0] > 1 else "")
        return (f"R has shape {shapes['R']}; for {sensors} it must be ({m}, {m}): one row and "
                f"column per sensor{cut}")
    for name, needed in (("Q", (k, k)), ("P0", (k, k)), ("z0", (k,))):
        if shapes[name] != needed:
            return f"{name} has shape {shapes[name]}; for {k} states it must be {needed}"
    return None


def _readings_problem(shapes: dict[str, tuple[int, ...]], rows_of_c: int | None,
                      k: int) -> str | None:
    """y's columns against C and R that agree with each other: then y is the odd one out.

    Either y lost senses (``Y[:, :1]`` with both senses' C and R: the fix is y of both,
    or C and R cut to match) or gained columns (readings made from the whole true state
    (n, k) instead of its position).
    """
    y, R = shapes["y"], shapes["R"]
    m = y[1]
    rows_of_r = R[0] if len(R) == 2 and R[0] == R[1] else None
    if rows_of_c is None or rows_of_c != rows_of_r or rows_of_c == m:
        return None
    c = rows_of_c
    start = (f"y has shape {y}, {m} column{'s' * (m != 1)} of readings, while C {shapes['C']} "
             f"and R {R} are for {c} sensor{'s' * (c != 1)}")
    if m < c:
        return (f"{start}: with this C and R, y needs all {c} senses' readings, shape "
                f"(n, {c}) (y itself, not y[:, :{m}]); for the first {m} sense"
                f"{'s' * (m != 1)} alone, cut C and R to match: C[:{m}], R[:{m}, :{m}]")
    whole_state = (f". Were the readings made from the whole true state, shape (n, {k}), "
                   f"all {k} of its columns? A sense reads the position only: use its "
                   f"position column (truth[:, :1], shape (n, 1))" if m == k and c == 1
                   else "")
    return f"{start}: y must be (n, {c}), one column per sensor{whole_state}"


def compensate_inputs_problem(estimates: object, A: object, delay_steps: object) -> str | None:
    """What does not fit in the inputs of ``compensate(estimates, A, delay_steps)``, or None."""
    shape, a_shape = _sized(estimates), _sized(A)
    if shape is None or a_shape is None:
        return None
    if len(shape) != 2:
        return (f"estimates has shape {shape}; it must be (n, k): one row ẑ_j per time step "
                f"(all the states, not only the positions)")
    if a_shape != (shape[1], shape[1]):
        return (f"A has shape {a_shape}; for estimates of {shape[1]} states it must be "
                f"({shape[1]}, {shape[1]})")
    if isinstance(delay_steps, (bool, np.bool_)) or not isinstance(
            delay_steps, (int, np.integer)) or not 0 <= delay_steps < shape[0]:
        return (f"delay_steps is {delay_steps!r}; it must be a whole number of samples δ, "
                f"0 <= δ < {shape[0]} (δ = d / Δt)")
    return None


#: The guard of each function the pack's notebooks save, by name.
GUARDS: dict[str, Callable[..., str | None]] = {
    "my_filter": filter_inputs_problem,
    "compensate": compensate_inputs_problem,
}


def guarded(name: str, function: Callable, hint: str = "") -> Callable:
    """``function`` with the inputs guard of ``name`` (:data:`GUARDS`), if it has one.

    The wrapper calls the student's function unchanged when the inputs fit; otherwise it
    raises :class:`StudentCodeError`: "my_filter was given R of shape (2, 2); …". Called
    from a notebook cell (not through :func:`~lqe_helpers.student_code.call`), an error of
    the function is reported the same way, as one line and the student's own frames (not
    this wrapper's source), with ``hint``: where to fix it.
    """
    guard = GUARDS.get(name)
    if guard is None:
        return function

    @functools.wraps(function)
    def checked(*args: object, **kwargs: object) -> object:
        try:
            problem = guard(*args, **kwargs)
        except TypeError:  # the wrong number of arguments: the student's function says so
            problem = None
        if problem is not None:
            raise StudentCodeError(f"{name} was given inputs that do not fit: {problem}")
        if calling.inside_call():  # a check's or an explorer's call reports an error itself
            return function(*args, **kwargs)
        try:
            return function(*args, **kwargs)
        except Exception as error:  # called from the student's cell: their lines, one line
            raise calling.reported(error, name, hint) from None

    return checked
