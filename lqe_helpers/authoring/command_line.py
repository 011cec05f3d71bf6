"""The tools' command lines: every failure is one ``error: ...`` line and a status.

:func:`run_command` runs a tool's command line and turns any failure into one
``error: ...`` line on stderr and exit status 1 (``--verbose`` adds the traceback);
warnings become one ``warning: ...`` line. Standard library only.
"""

from __future__ import annotations

import argparse
import sys
import traceback
import warnings
from collections.abc import Callable, Sequence
from typing import Any, NoReturn

from lqe_helpers.authoring.errors import error_line, first_line, strip_colour


class CommandLineParser(argparse.ArgumentParser):
    """An :class:`argparse.ArgumentParser` with ``--verbose`` whose usage errors are one line.

    A bad option prints ``error: <what>; see --help`` on stderr and exits with status 1,
    like every other failure of the tools.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.add_argument("--verbose", action="store_true",
                          help="on failure, also print the traceback")

    def error(self, message: str) -> NoReturn:
        """Print one ``error:`` line and exit with status 1."""
        print(f"error: {message}; see {self.prog} --help", file=sys.stderr)
        raise SystemExit(1)


def fail(message: object) -> int:
    """Print ``error: <message>`` (its first line) on stderr; return 1 (a failed command)."""
    print(f"error: {first_line(str(message)) or message}", file=sys.stderr)
    return 1


def _one_line_warning(message: Warning | str, category: type[Warning], filename: str,
                      lineno: int, file: Any = None, line: str | None = None) -> None:
    print(f"warning: {first_line(str(message))}", file=sys.stderr if file is None else file)


def run_command(parser: argparse.ArgumentParser,
                command: Callable[[argparse.Namespace], int | None],
                argv: Sequence[str] | None = None) -> int:
    """Parse ``argv`` and run ``command(args)``; turn any failure into one ``error:`` line.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The tool's parser (a :class:`CommandLineParser`, which has ``--verbose``).
    command : callable
        Does the work; returns an exit status (``None`` means 0).
    argv : sequence of str, optional
        The arguments (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        ``command``'s status; 1 after an exception (printed as ``error: ...`` on
        stderr, preceded by the traceback with ``--verbose``); 130 after Ctrl-C.
        Warnings are printed as one ``warning: ...`` line each (in full with ``--verbose``).
    """
    args = parser.parse_args(argv)
    verbose = bool(getattr(args, "verbose", False))
    with warnings.catch_warnings():
        if not verbose:
            warnings.showwarning = _one_line_warning
        try:
            status = command(args)
        except KeyboardInterrupt:
            print("error: interrupted", file=sys.stderr)
            return 130
        except Exception as error:  # the one place every failure is reported
            if verbose:
                print(strip_colour(traceback.format_exc()).rstrip(), file=sys.stderr)
            print(f"error: {error_line(error)}", file=sys.stderr)
            return 1
    return 0 if status is None else int(status)
