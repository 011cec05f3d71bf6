"""What the course tools raise, and how a failure becomes one line.

Every tool of :mod:`lqe_helpers.authoring` raises the exceptions defined here, and
:func:`lqe_helpers.authoring.command_line.run_command` prints any failure as one
``error: ...`` line made by :func:`error_line`. A fault found in many places (171 files
in the way, 12 cells with an error) is said once, with a count and the first few
places (:func:`summarise`). Standard library only.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

# Terminal colour codes, as IPython puts them in tracebacks.
_ANSI_COLOUR = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")
# Characters that would break a one-line message (newlines, tabs, other controls) or its
# printing (the surrogates that stand for the bytes of a file name that is not UTF-8).
_CONTROL = re.compile(r"[\x00-\x1f\x7f\ud800-\udfff]")
#: How many places :func:`summarise` names before saying how many more there are.
NAMED_PLACES = 3


class ToolError(Exception):
    """A failure a course tool explains fully in its message's first line (printed as it is)."""


class FileSafetyError(ToolError, ValueError):
    """A tool refused to read or write a file, to keep someone's work safe."""


class OutputFolderError(FileSafetyError):
    """An output folder cannot be used (it overlaps the source, or holds others' files)."""


class NotebookFileError(FileSafetyError):
    """A file that should be a notebook is missing, unreadable or not a valid notebook."""


class OutputWriteError(FileSafetyError):
    """Writing failed part-way (disk full, read-only folder); what was there is restored."""


class Terminated(BaseException):
    """The process was asked to stop (SIGTERM); raised where it was, like Ctrl-C."""


def strip_colour(text: str) -> str:
    """``text`` without terminal colour codes (as IPython puts them in tracebacks)."""
    return _ANSI_COLOUR.sub("", text)


def first_line(text: str) -> str:
    """The first non-blank line of ``text``, stripped, without colour codes ('' if none)."""
    lines = [line.strip() for line in strip_colour(text).splitlines() if line.strip()]
    return lines[0] if lines else ""


def shown(name: object) -> str:
    """``name`` as a message shows it: as it is, or quoted with escapes if it holds a
    newline, another control character or a byte of a name that is not UTF-8 (so the
    message stays one line, and printable)."""
    text = str(name)
    return repr(text) if _CONTROL.search(text) else text


def summarise(places: Sequence[str], limit: int = NAMED_PLACES, separator: str = ", ") -> str:
    """``places`` named once each: all of them, or the first ``limit`` and how many more.

    ``["a", "b", "c", "d", "e"]`` → ``"a, b, c and 2 more"``; each place goes through
    :func:`shown`, so the result is one line.
    """
    named = [shown(place) for place in places[:limit]]
    more = len(places) - len(named)
    return separator.join(named) + (f" and {more} more" if more > 0 else "")


def error_line(error: BaseException) -> str:
    """One line saying what went wrong, for ``error: ...`` (no traceback, no colour codes).

    An :class:`OSError` reads ``<file>: <reason>``; an error the tools raise on purpose
    (:class:`ToolError`, :class:`ValueError` and their kin) gives its message's first
    line; anything else also names its type. A message cut to its first line says so.
    """
    if isinstance(error, OSError) and error.strerror:
        names = " -> ".join(shown(name) for name in (error.filename, error.filename2) if name)
        return f"{names}: {error.strerror}" if names else error.strerror
    message = str(error)
    line = first_line(message)
    if not isinstance(error, (ToolError, ValueError)):
        line = f"{type(error).__name__}: {line}" if line else type(error).__name__
    if len([part for part in message.splitlines() if part.strip()]) > 1:
        line += " (--verbose shows the rest)"
    return line
