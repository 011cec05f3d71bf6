"""Input checks shared by the public API.

Every check raises :class:`ValueError` whose message names the parameter, the value
received and what is allowed, e.g. ``"sigma_v must be > 0 cm, got -1.5"``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

#: Relative tolerance for "symmetric" and "positive semidefinite" checks.
MATRIX_RTOL = 1e-8

#: Largest memory (bytes) one call of the public API may allocate for its arrays: 2 GiB.
#: The pack's largest legitimate call (notebook 04's sweep of 25 σ_p values over 300 runs
#: of 1 000 samples) peaks at 0.46 GiB (tracemalloc). A call estimated above this limit
#: is refused by :func:`check_memory` before anything is allocated, with a ``ValueError``
#: that names the parameter responsible and the estimate, instead of numpy's
#: ``MemoryError`` (or minutes of swapping) on the shared 24 GiB machine.
MEMORY_LIMIT_BYTES = 2 * 1024**3

#: Bytes of one float64 number.
FLOAT_BYTES = 8

#: Copies of an input array that its checks and its caller may make (converted, absolute
#: values, differences, results): an input is refused beyond a quarter of the limit.
_INPUT_COPIES = 4


def check_memory(names: str, numbers: int, copies: float = 1.0,
                 what: str = "") -> int:
    """Refuse a call that would allocate more than :data:`MEMORY_LIMIT_BYTES`.

    Parameters
    ----------
    names : str
        The parameter(s) responsible, as the caller wrote them, with their values, e.g.
        ``"runs = 10000000"`` or ``"y of shape (300, 1000, 2) and R of shape (25, 2, 2)"``.
    numbers : int
        How many float64 numbers the largest set of arrays alive at once holds (a Python
        int: no overflow, however absurd the size).
    copies : float
        Multiplier for temporaries of the same size (e.g. 2 when a list of steps is
        stacked into a new array).
    what : str
        What the memory is for, quoted in the message (e.g. ``"the estimates"``).

    Returns
    -------
    int
        The estimate in bytes, when it is within the limit.

    Raises
    ------
    ValueError
        ``"<names> would need about 7.5 GiB <what>, more than the limit of 2 GiB
        (validation.MEMORY_LIMIT_BYTES)"``, raised before anything is allocated.
    """
    estimate = math.ceil(int(numbers) * FLOAT_BYTES * copies)
    if estimate > MEMORY_LIMIT_BYTES:
        purpose = f" {what}" if what else ""
        raise ValueError(
            f"{names} would need about {_bytes_text(estimate)}{purpose}, more than the limit "
            f"of {_bytes_text(MEMORY_LIMIT_BYTES)} (validation.MEMORY_LIMIT_BYTES); use fewer "
            f"runs, steps or sweep values, or split the call")
    return estimate


def _bytes_text(size: int) -> str:
    """A byte count in GiB, with a power of ten when it is astronomically large."""
    gib = size / 1024**3
    return f"{gib:.3g} GiB" if gib < 1e6 else f"{gib:.2e} GiB"


def elements(shape: tuple[int, ...]) -> int:
    """Number of entries of an array of ``shape``, as an exact Python int."""
    return math.prod(int(d) for d in shape)


def _describe(value: object) -> str:
    """Short text for a received value: the value itself, or the shape of an array."""
    array = np.asarray(value) if not isinstance(value, np.ndarray) else value
    if array.ndim == 0 or array.size <= 4:
        return repr(value if not isinstance(value, np.ndarray) else array.tolist())
    return f"an array of shape {array.shape}"


#: What each non-numeric dtype kind is called in messages.
_NOT_REAL_KINDS = {"b": "a boolean (True/False is not a number here)",
                   "c": "a complex number (the imaginary part would be lost)",
                   "U": "text (write the number without quotes)",
                   "S": "text (write the number without quotes)",
                   "M": "a date", "m": "a time interval (give plain seconds)"}


def not_real(value: object) -> str | None:
    """Why ``value`` is not real numeric data (a phrase for the message), else None.

    Booleans, complex numbers and text convert silently to float in numpy (True is 1,
    ``1+2j`` loses its imaginary part, ``"0.01"`` parses), so they are refused here,
    inside lists and tuples and in numpy arrays of any dtype, before any conversion.
    """
    if isinstance(value, (str, bytes)):
        return _NOT_REAL_KINDS["U"]
    if isinstance(value, (bool, np.bool_)):
        return _NOT_REAL_KINDS["b"]
    if isinstance(value, (complex, np.complexfloating)):
        return _NOT_REAL_KINDS["c"]
    if isinstance(value, np.ma.MaskedArray) and np.ma.is_masked(value):
        return ("a masked array with masked entries (numpy would use the hidden values "
                "behind the mask; pass only the valid ones)")
    if isinstance(value, (list, tuple)):
        for item in value:
            reason = not_real(item)
            if reason is not None:
                return reason
        return None
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "O":
            for item in value.flat:
                reason = not_real(item)
                if reason is not None:
                    return reason
            return None
        return _NOT_REAL_KINDS.get(value.dtype.kind)
    if isinstance(value, (int, float, np.number)):
        return None
    try:  # anything else numpy can read (a pandas Series, a memoryview, ...)
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):
        return None
    return _NOT_REAL_KINDS.get(kind)  # None for objects: the float conversion decides


def _number(name: str, value: object, requirement: str, unit_text: str,
            allowed: Callable[[float], bool], non_numeric: str = "a number") -> float:
    """``value`` as a finite float for which ``allowed`` holds, else a ``ValueError``.

    The message says "``name`` must be a finite number``requirement````unit_text``" and
    quotes ``value``; a value that is not a number at all (text, a boolean, a complex
    number, an array, None) is called ``non_numeric`` and the message says what it is.
    """
    reason = not_real(value)
    if reason is None and np.ndim(value) != 0:
        reason = "an array (give a single number)"
    if reason is not None:
        raise ValueError(
            f"{name} must be {non_numeric}{requirement}{unit_text}, got {value!r}: {reason}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(
            f"{name} must be {non_numeric}{requirement}{unit_text}, got {value!r}") from None
    if not np.isfinite(number) or not allowed(number):
        raise ValueError(
            f"{name} must be a finite number{requirement}{unit_text}, got {value!r}")
    return number


def positive(name: str, value: float, unit: str = "") -> float:
    """Return ``value`` as a float if it is finite and > 0, else raise ``ValueError``."""
    return _number(name, value, " > 0", f" {unit}" if unit else "", lambda x: x > 0)


def non_negative(name: str, value: float, unit: str = "") -> float:
    """Return ``value`` as a float if it is finite and >= 0, else raise ``ValueError``."""
    return _number(name, value, " >= 0", f" {unit}" if unit else "", lambda x: x >= 0)


def instance(name: str, value: object, kind: type, example: str) -> object:
    """Return ``value`` if it is a ``kind``, else a ``ValueError`` quoting ``example``."""
    if not isinstance(value, kind):
        text = repr(value)
        text = text if len(text) <= 60 else f"{text[:50]} …"
        article = "an" if kind.__name__[0] in "AEIOU" else "a"
        raise ValueError(
            f"{name} must be {article} {kind.__name__} ({example}), got "
            f"{type(value).__name__} {text}")
    return value


def count(name: str, value: int, minimum: int = 0, maximum: int | None = None) -> int:
    """Return ``value`` if it is a whole number in ``[minimum, maximum]``."""
    allowed = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be a whole number {allowed}, got {value!r}")
    if value < minimum or (maximum is not None and value > maximum):
        raise ValueError(f"{name} must be a whole number {allowed}, got {value!r}")
    return int(value)


def finite_number(name: str, value: float, unit: str = "") -> float:
    """Return ``value`` as a float if it is a finite number of any sign, else raise."""
    return _number(name, value, "", f" in {unit}" if unit else "", lambda x: True,
                   non_numeric="a finite number")


def whole_steps(name: str, value: float, dt: float) -> int:
    """A time ``value`` (s) as a whole number of time steps ``dt`` (s).

    ``value / dt`` must be a whole number up to the rounding of the numbers given: a
    relative tolerance of 1e-9, or four units of the coarser precision of the two
    inputs if that is larger (a float32 ``0.1`` is 0.10000000149 s, which is 10 steps
    of 0.01 s to float32 precision). ``0.004 / 0.01`` is refused rather than silently
    rounded to 0 steps. Callers check the sign of ``value`` themselves; ``dt`` must be
    > 0.
    """
    rtol = max(1e-9, 4.0 * max(_resolution(value), _resolution(dt)))
    given = value  # quoted as given: np.float32(0.104) prints as 0.104
    value = finite_number(name, value, "s")
    dt = positive("dt", dt, "s")
    ratio = value / dt
    if not abs(ratio) < _MAX_WHOLE_STEPS:  # also catches inf from 1e308 / 0.01
        raise ValueError(
            f"{name} must be at most {_MAX_WHOLE_STEPS:.0e} time steps dt = {dt} s, got "
            f"{given!s} s ({ratio:.3g} steps)")
    steps = round(ratio)
    if abs(ratio - steps) > rtol * max(1.0, abs(ratio)):
        raise ValueError(
            f"{name} must be a whole number of time steps dt = {dt} s, got {given!s} s "
            f"({ratio:.10g} steps), the nearest whole numbers of steps "
            f"being {math.floor(ratio) * dt:.10g} s and {math.ceil(ratio) * dt:.10g} s"
        )
    return steps


#: Largest step count :func:`whole_steps` converts (2⁵³: beyond it a float no longer holds
#: every whole number, so "a whole number of steps" means nothing).
_MAX_WHOLE_STEPS = 2.0**53


def _resolution(value: object) -> float:
    """Relative precision (machine epsilon) of a number's type: float32 1.2e-7, else 2.2e-16."""
    dtype = getattr(value, "dtype", None)
    if dtype is not None and np.issubdtype(dtype, np.floating):
        return float(np.finfo(dtype).eps)
    return float(np.finfo(float).eps)


def numeric_array(name: str, value: object, min_ndim: int = 0) -> np.ndarray:
    """Return ``value`` as a float array with at least ``min_ndim`` axes; NaN/inf allowed.

    Refused: text, booleans and complex numbers (numpy would convert them silently, see
    :func:`not_real`), anything that is not a rectangular array of numbers, and an
    empty array (nothing to compute with: ``[]`` where a number or a list is meant).
    """
    reason = not_real(value)
    if reason is not None:
        raise ValueError(
            f"{name} must be a numeric array, got {_describe_raw(value)}: "
            f"{reason}")
    size = getattr(value, "size", None)
    if isinstance(value, np.ndarray) and isinstance(size, int):
        # A broadcast view costs nothing to pass but as much as its size to convert or
        # to compute with: every caller allocates at least that much.
        # The checks below and every caller make a few temporaries of the same size.
        check_memory(f"{name} of shape {value.shape}", size, copies=_INPUT_COPIES,
                     what="as float64 numbers and their temporaries")
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(
            f"{name} must be a numeric array, got {_describe_raw(value)}") from None
    if array.size == 0:
        raise ValueError(
            f"{name} must hold at least one number, got an empty array of shape {array.shape}")
    if array.ndim < min_ndim:
        raise ValueError(
            f"{name} must have at least {min_ndim} axes, got shape {array.shape} "
            f"({_describe(array)})"
        )
    return array


def _describe_raw(value: object) -> str:
    """A value that may not convert to an array, on one line: its ``repr`` if short, else
    an array's shape and dtype (or the start of the repr)."""
    text = repr(value)
    if isinstance(value, np.ndarray) and ("\n" in text or len(text) > 80):
        return f"an array of shape {value.shape} and dtype {value.dtype}"
    text = " ".join(text.split())
    return text if len(text) <= 80 else f"{text[:60]} … (a {type(value).__name__})"


def finite_array(name: str, value: object, min_ndim: int = 0) -> np.ndarray:
    """Return ``value`` as a float array with at least ``min_ndim`` axes and no NaN/inf."""
    array = numeric_array(name, value, min_ndim)
    if not np.all(np.isfinite(array)):
        bad = int(np.size(array) - np.count_nonzero(np.isfinite(array)))
        raise ValueError(
            f"{name} must contain only finite numbers, got {bad} NaN or infinite "
            f"value(s) in {_describe(array)}"
        )
    return array


def positive_array(name: str, value: object, unit: str = "", min_ndim: int = 0) -> np.ndarray:
    """Return ``value`` as a finite float array whose entries are all > 0."""
    array = finite_array(name, value, min_ndim)
    if np.any(array <= 0):
        unit_text = f" {unit}" if unit else ""
        smallest = "" if array.size <= 4 else f" whose smallest entry is {array.min():g}"
        every = "must be" if array.ndim == 0 else "must all be"
        raise ValueError(
            f"{name} {every} > 0{unit_text}, got {_describe(array)}{smallest}"
        )
    return array


def shaped_array(name: str, value: object, shape: tuple[int, ...],
                 columns: str = "") -> np.ndarray:
    """Return ``value`` as a finite float array of exactly ``shape``.

    ``columns`` names what the last axis holds, e.g. ``"vision, proprioception"``,
    and is quoted in the error message.
    """
    array = finite_array(name, value)
    if array.shape != tuple(shape):
        what = f" ({columns})" if columns else ""
        raise ValueError(
            f"{name} must have shape {tuple(shape)}{what}, got shape {array.shape}"
        )
    return array


def square_matrix(name: str, value: object, size: int | None = None) -> np.ndarray:
    """Return a finite ``(..., n, n)`` array; ``size`` fixes n if given."""
    array = finite_array(name, value, min_ndim=2)
    n, m = array.shape[-2:]
    if n != m or (size is not None and n != size):
        wanted = f"({size}, {size})" if size is not None else "(n, n)"
        raise ValueError(
            f"{name} must have trailing shape {wanted}, got shape {array.shape}"
        )
    return array


def covariance(name: str, value: object, size: int | None = None,
               definite: bool = False) -> np.ndarray:
    """Return a symmetric positive semidefinite (or definite) ``(..., n, n)`` array.

    Symmetry and a semidefinite matrix's eigenvalue sign are checked relative to the
    largest absolute entry, with tolerance :data:`MATRIX_RTOL`; definiteness by the
    existence of a Cholesky factor.
    """
    array = square_matrix(name, value, size)
    check_memory(f"{name} of shape {array.shape}", 6 * array.size,
                 what="to check it is a covariance")
    scale = np.max(np.abs(array), axis=(-2, -1), keepdims=True)
    scale = np.where(scale > 0, scale, 1.0)
    # Entries in [−1, 1]: the checks below cannot overflow, whatever the units. A matrix
    # whose largest entry is subnormal (below 2.2e-308) has lost its relative precision
    # and is zero for every purpose here (e.g. Q of a jerk of 1e-158 cm/s³).
    unit = np.where(scale >= np.finfo(float).tiny, array / scale, 0.0)
    asymmetry = np.max(np.abs(unit - np.swapaxes(unit, -1, -2)))
    if asymmetry > MATRIX_RTOL:
        raise ValueError(
            f"{name} must be symmetric, got {_describe(array)} with relative "
            f"asymmetry {asymmetry:.3g}"
        )
    if definite:
        # Cholesky succeeds exactly for (numerically) positive definite matrices, however
        # different the scales of their entries (R = diag(10⁶, 10⁻⁶) is fine).
        try:
            np.linalg.cholesky(unit)
        except np.linalg.LinAlgError:
            raise ValueError(
                f"{name} must be positive definite, got {_describe(array)} (no Cholesky "
                f"factor exists)"
            ) from None
        return array
    eigenvalues = np.linalg.eigvalsh(unit)
    smallest = float(np.min(eigenvalues)) if eigenvalues.size else 0.0
    if smallest < -MATRIX_RTOL:
        raise ValueError(
            f"{name} must be positive semidefinite, got {_describe(array)} with an "
            f"eigenvalue of {smallest:.3g} times its largest entry"
        )
    return array


def one_run(values: np.ndarray, run: int | tuple[int, ...] | None,
            trailing: int = 1) -> np.ndarray:
    """``values[run]``, which must leave ``trailing`` axes: one run of a batch (a result's
    figure draws one run). Raises ValueError naming ``run`` if it does not pick one."""
    index = () if run is None else np.index_exp[run]
    try:
        one = values[index]
    except (IndexError, TypeError):
        one = None
    if one is None or one.ndim != trailing:
        raise ValueError(
            f"run must pick one run of the leading axes {values.shape[:-trailing]}, got {run!r}")
    return one


def broadcast_batches(**shapes: tuple[int, ...]) -> tuple[int, ...]:
    """Broadcast named batch shapes, raising ``ValueError`` that lists them if they clash."""
    try:
        return np.broadcast_shapes(*shapes.values())
    except ValueError:
        listed = ", ".join(f"{name} {shape}" for name, shape in shapes.items())
        raise ValueError(
            f"leading batch axes must broadcast against each other, got {listed}"
        ) from None


def in_float_range(inputs: str, compute: Callable[[], object],
                   positive: bool = False) -> np.ndarray:
    """``compute()`` as an array, or a ``ValueError`` naming ``inputs`` if it leaves float64.

    ``inputs`` describes the values behind the computation for the message (e.g.
    ``"sigmas (largest 1e+200 cm, smallest 1 cm)"``). With ``positive``, a result that
    underflows to 0 is refused too (a variance that must stay > 0).
    """
    try:
        with np.errstate(over="ignore", under="ignore"):
            result = np.asarray(compute())
    except OverflowError:  # Python's float power raises instead of returning inf
        result = np.array(np.inf)
    if not np.all(np.isfinite(result)) or (positive and np.any(result == 0)):
        raise ValueError(f"{inputs} give numbers beyond the float64 range (squares or cubes "
                         f"overflow to inf or underflow to 0)")
    return result
