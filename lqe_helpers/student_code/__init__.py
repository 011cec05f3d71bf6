"""The student's own functions: calling them safely, and keeping them between notebooks.

Every piece of the pack that runs code a student wrote (the checks after each task, the
explorers' sliders) calls it through :func:`call` and reads what it returned through
:func:`result_array`, so a student's function is run, timed and reported in one way
everywhere; :func:`save` and :func:`load` carry a function from one notebook to the next.

- ``errors``: :class:`StudentCodeError` (what every caller reports, one line), its
  subclass :class:`CheckFailed` (what a check raises; :class:`NotWrittenYet` and
  :class:`TimedOut` are both), and :class:`OwnCodeTraceback` (in Jupyter, only the
  student's own frames are shown): the pack's one hierarchy of errors for students;
- ``calling``: :func:`call`, with copies of the inputs and a time limit (``running``: a
  time limit the student's own code cannot catch);
- ``results``: :func:`result_array` and :func:`array_problem`, a real number array or
  one line saying what came instead;
- ``keeping``: :func:`save` and :func:`load`;
- ``guards``: what a loaded ``my_filter`` or ``compensate`` checks of its inputs' sizes, so
  that an R that does not fit its readings is named at the student's own call.
"""

from .calling import NOT_WRITTEN_ADVICE, TIME_LIMIT, call, function_name
from .errors import (
    CheckFailed,
    NotSavedYet,
    NotWrittenYet,
    OwnCodeTraceback,
    StudentCodeError,
    TimedOut,
    brief_errors,
    is_own_code,
    own_frames,
)
from .keeping import SAVE_FOLDER, SAVE_HEADER, SAVED_BY, load, save, save_folder
from .results import MAX_MAGNITUDE, array_problem, result_array

__all__ = [
    "MAX_MAGNITUDE",
    "NOT_WRITTEN_ADVICE",
    "SAVED_BY",
    "SAVE_FOLDER",
    "SAVE_HEADER",
    "TIME_LIMIT",
    "CheckFailed",
    "NotSavedYet",
    "NotWrittenYet",
    "OwnCodeTraceback",
    "StudentCodeError",
    "TimedOut",
    "array_problem",
    "brief_errors",
    "call",
    "function_name",
    "is_own_code",
    "load",
    "own_frames",
    "result_array",
    "save",
    "save_folder",
]
