"""The student's own functions: calling them safely, and keeping them between notebooks.

Every piece of the pack that runs code a student wrote (the checks after each task, the
explorers' sliders) calls it through this module, so a student's function is run, timed
and reported in one way everywhere.
"""

from __future__ import annotations


class StudentCodeError(Exception):
    """A student's function failed, hung or returned something unusable.

    Its message is one line, written for the student (what went wrong and where), with
    no library code in it. Checks turn it into a failed check; explorers show it in
    their numbers line instead of a picture.
    """
