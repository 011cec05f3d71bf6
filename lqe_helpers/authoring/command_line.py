"""The tools' command lines: every failure is one ``error: ...`` line and a status.

:func:`run_command` runs a tool's command line and turns any failure into one
``error: ...`` line on stderr and exit status 1 (``--verbose`` adds the traceback);
warnings become one ``warning: ...`` line. Ctrl-C ends a tool with one line and status
130, SIGTERM with one line and status 143 (it is raised where the tool is, as
:class:`~lqe_helpers.authoring.errors.Terminated`, so a build in progress is undone and
a kernel stopped), and so do Ctrl-C and SIGTERM while a tool is still importing what it
needs (:func:`interrupt_exits_quietly`). Standard library only.
"""

from __future__ import annotations

import argparse
import contextlib
import signal
import sys
import threading
import traceback
import warnings
from collections.abc import Callable, Iterator, Sequence
from typing import Any, NoReturn

from lqe_helpers.authoring.errors import Terminated, error_line, first_line, strip_colour

#: Exit status after Ctrl-C (128 + SIGINT), as a shell reports it.
INTERRUPTED_STATUS = 130
#: Exit status after SIGTERM (128 + SIGTERM).
TERMINATED_STATUS = 143


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
        stderr, preceded by the traceback with ``--verbose``); 130 after Ctrl-C, 143
        after SIGTERM. Warnings are printed as one ``warning: ...`` line each (in full
        with ``--verbose``).
    """
    verbose = False
    with warnings.catch_warnings(), sigterm_raises():
        try:
            args = parser.parse_args(argv)
            verbose = bool(getattr(args, "verbose", False))
            if not verbose:
                warnings.showwarning = _one_line_warning
            status = command(args)
        except KeyboardInterrupt as error:
            print(f"error: {first_line(str(error)) or 'interrupted'}", file=sys.stderr)
            return INTERRUPTED_STATUS
        except Terminated as error:
            print(f"error: {first_line(str(error)) or 'stopped by SIGTERM'}", file=sys.stderr)
            return TERMINATED_STATUS
        except Exception as error:  # the one place every failure is reported
            if verbose:
                print(strip_colour(traceback.format_exc()).rstrip(), file=sys.stderr)
            print(f"error: {error_line(error)}", file=sys.stderr)
            return 1
    return 0 if status is None else int(status)


@contextlib.contextmanager
def sigterm_raises() -> Iterator[None]:
    """While the block runs, SIGTERM raises :class:`Terminated` where the program is.

    So a tool asked to stop undoes a half-done build and stops its kernel, as after
    Ctrl-C. Only in the main thread (the only one where Python sets handlers).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminate(signum: int, frame: object) -> None:
        raise Terminated("stopped by SIGTERM")

    previous = signal.signal(signal.SIGTERM, terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous if previous is not None else signal.SIG_DFL)


@contextlib.contextmanager
def interrupt_exits_quietly(module_name: str) -> Iterator[None]:
    """Around a tool's imports: Ctrl-C or SIGTERM then ends ``python -m <tool>`` with one line.

    The heavy imports of a tool (nbconvert, nbclient) take a second or more; a Ctrl-C
    then would print a traceback, and SIGTERM end it without a word. For the module run
    as ``__main__`` this prints ``error: interrupted while starting`` (status 130) or
    ``error: stopped by SIGTERM while starting`` (status 143) instead; for a module
    imported by other code it does nothing.
    """
    if module_name != "__main__":
        yield
        return
    try:
        with sigterm_raises():
            yield
    except KeyboardInterrupt:
        print("error: interrupted while starting; nothing was done", file=sys.stderr)
        raise SystemExit(INTERRUPTED_STATUS) from None
    except Terminated:
        print("error: stopped by SIGTERM while starting; nothing was done", file=sys.stderr)
        raise SystemExit(TERMINATED_STATUS) from None
