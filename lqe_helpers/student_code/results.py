"""What a student's function returned (or a value passed): a real number array, or one line."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .errors import StudentCodeError, short_repr

__tracebackhide__ = True  # pytest: leave these frames out of a failure's traceback

#: Largest magnitude accepted in a result: its square, and a sum of a million squares, stay
#: far below the largest float (1.8e308).
MAX_MAGNITUDE = 1e150


_COMPLEX_ADVICE = ("the imaginary part is never dropped, even when it is 0: find where a "
                   "complex number enters (a square root of a negative number, the "
                   "eigenvalues of a matrix that is not symmetric) and compute with real "
                   "numbers")
_KIND_NAMES = {"b": "True/False values (booleans), not numbers", "U": "text, not numbers",
               "S": "text, not numbers", "M": "dates, not numbers",
               "m": "time intervals, not plain numbers", "V": "raw bytes, not numbers"}


def _shape_text(item: object) -> str:
    if isinstance(item, np.ndarray):
        return str(item.shape)
    if isinstance(item, (int, float, np.number)) and not isinstance(item, bool):
        return "()"
    return type(item).__name__


def _fits(shape: tuple[int, ...], wanted: Sequence[int | None]) -> bool:
    return len(shape) == len(wanted) and all(w is None or s == w
                                             for s, w in zip(shape, wanted, strict=True))


def array_problem(value: object, *, shape: Sequence[int | None] | None = None,
                  allow_nan: bool = False, returned: bool = True,
                  double: bool = False) -> str | None:
    """Why ``value`` is not a real, finite number array of ``shape``, or None if it is.

    The answer is a phrase that completes "my_filter returned …" (``returned``) or
    "C must be …, got …" (its advice then speaks of a value, not a return line).

    Parameters
    ----------
    value : object
        What the student's function returned, or a value they passed.
    shape : sequence of int or None, optional
        The shape due; None in it matches any length. Default: any shape.
    allow_nan : bool
        Accept NaN ("no value", e.g. before a delayed signal arrives); inf never.
    returned : bool
        Word the advice for a returned value.
    double : bool
        Refuse floats of less than double precision (float32 keeps about 7 digits, too
        few for a comparison to 1e-9).

    Returns
    -------
    str or None
        For None, a tuple, a list, a complex number (even with a zero imaginary part),
        a boolean, text, an object array, any other type, a wrong shape, NaN or inf, or a
        value too large to square (> :data:`MAX_MAGNITUDE`): what it is, and a hint.
    """
    if value is None:
        return ("None (nothing). Does the function end by returning its result?" if returned
                else "None (nothing)")
    if isinstance(value, (bool, np.bool_)):
        return f"{value} (a boolean), not a number"
    if isinstance(value, (str, bytes, np.str_, np.bytes_)):
        return f"text ({short_repr(value)}), not a number: give numbers, without quotes"
    if isinstance(value, (complex, np.complexfloating)):
        return f"a complex number ({value}): {_COMPLEX_ADVICE}"
    if isinstance(value, tuple):
        shapes = ", ".join(_shape_text(item) for item in value[:4])
        return (f"a tuple of {len(value)} items (shapes {shapes}): give only one array"
                if len(value) else "an empty tuple")
    if isinstance(value, list):
        return ("a Python list, not a NumPy array: convert it into an array"
                + (" before returning it" if returned else ""))
    if isinstance(value, np.ma.MaskedArray):
        return "a masked array: give a plain NumPy array (its masked entries would be lost)"
    if isinstance(value, (int, float, np.number)):
        try:
            array = np.asarray(float(value))
        except OverflowError:
            return f"a number too large to square ({short_repr(value)})"
    elif isinstance(value, np.ndarray):
        kind = value.dtype.kind
        if kind == "c":
            return f"complex numbers (dtype {value.dtype}): {_COMPLEX_ADVICE}"
        if kind == "O":
            return ("an array of Python objects (dtype object), not of numbers: that comes "
                    "from rows of different lengths, or None or arrays inside it; build a "
                    "rectangular array of numbers")
        if kind in _KIND_NAMES:
            return f"an array of {_KIND_NAMES[kind]}"
        if double and kind == "f" and value.dtype.itemsize < 8:
            return (f"{value.dtype} numbers, which keep only about "
                    f"{np.finfo(value.dtype).precision} digits: compute in float64, NumPy's "
                    f"default (leave out dtype=np.{value.dtype}, or .astype(...))")
        array = np.asarray(value, dtype=float)
    else:
        kind_name = type(value).__name__
        article = "an" if kind_name[:1].lower() in "aeiou" else "a"
        return f"{article} {kind_name} ({short_repr(value)}), not a NumPy array of numbers"
    if shape is not None and not _fits(array.shape, shape):
        wanted = tuple("any" if w is None else w for w in shape)
        found = (f"one number ({float(array):g})" if array.ndim == 0
                 else f"an array of shape {array.shape}")
        return f"{found}, not of shape {wanted}".replace("'any'", "any")
    finite = np.isfinite(array)
    bad = ~finite & ~np.isnan(array) if allow_nan else ~finite
    if np.any(bad):
        what = "an infinite value" if allow_nan else "NaN (not a number) or an infinite value"
        if array.ndim == 0:
            return "NaN (not a number)" if np.isnan(array) else f"{float(array)} (infinite)"
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        more = int(bad.sum()) - 1
        return (f"{what} at index {index[0] if len(index) == 1 else index}"
                + (f" and {more} more" if more else ""))
    largest = float(np.max(np.abs(array[finite]))) if finite.any() else 0.0
    if largest > MAX_MAGNITUDE:
        return (f"values too large to square (up to {largest:.3g}): look for a quantity "
                f"that grows at every step")
    return None


def result_array(value: object, *, name: str, what: str,
                 shape: Sequence[int | None] | None = None, allow_nan: bool = False,
                 double: bool = False, where: str = "",
                 failure: type[StudentCodeError] = StudentCodeError) -> np.ndarray:
    """What a student's function returned, as a float array, or a StudentCodeError.

    Parameters
    ----------
    value : object
        The return value (from :func:`call`).
    name : str
        The function's name for the message.
    what : str
        What it must return, with its shape ("the estimates ẑ, shape (n, k) = (15, 3)").
    shape, allow_nan, double
        See :func:`array_problem`.
    where : str
        What it was called on, for the message.
    failure : subclass of StudentCodeError
        What it raises (a check passes ``CheckFailed``).

    Returns
    -------
    ndarray
        ``value`` as a float array (a copy for anything but a float ndarray).

    Raises
    ------
    StudentCodeError
        (``failure``) One line naming what was returned (:func:`array_problem`).
    """
    problem = array_problem(value, shape=shape, allow_nan=allow_nan, double=double)
    if problem is not None:
        on = f" (on {where})" if where else ""
        raise failure(f"{name} returned {problem}; it must return {what}{on}")
    return np.asarray(value, dtype=float)

