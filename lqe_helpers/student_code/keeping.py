"""Keeping a student's function between notebooks: ``my_functions/<name>.py``."""

from __future__ import annotations

import ast
import builtins
import inspect
import linecache
import os
import stat
import symtable
import tempfile
import textwrap
import types
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .calling import call, function_name, machinery_function
from .errors import NotSavedYet, StudentCodeError, error_text, short_repr
from .guards import guarded
from .outside import unheard
from .task_runs import recorded

__tracebackhide__ = True  # pytest: leave these frames out of a failure's traceback

#: Folder beside the notebook (the kernel's working folder) where :func:`save` keeps functions.
SAVE_FOLDER = "my_functions"
#: First line of every file :func:`save` writes; a file without it is never replaced.
SAVE_HEADER = "# Written by lqe_helpers.student_code.save: edit the notebook, not this file."
#: Which task writes each saved function, for :func:`load`'s message.
SAVED_BY = {"my_filter": "notebook 01 (the check after Task 1)",
            "compensate": "notebook 05 (the check after Task 1)"}


#: The absolute folder that :func:`save` and :func:`load` use by default, fixed by the first
#: of them in this session (the kernel's working folder then: the notebook's folder).
_home: Path | None = None


def save_folder() -> Path:
    """The absolute path of :data:`SAVE_FOLDER` for this session.

    Fixed the first time it is asked for (by the first :func:`save` or :func:`load`), from
    the working folder at that moment, so that a later ``os.chdir`` (in a student's cell)
    cannot send a saved function elsewhere.
    """
    global _home
    if _home is None:
        _home = Path(os.path.abspath(SAVE_FOLDER))
    return _home


def _folder(folder: str | os.PathLike | None) -> Path:
    return save_folder() if folder is None else Path(os.path.abspath(folder))


def _shown(path: Path) -> str:
    """``path`` as a message shows it: from the notebook's folder when it is inside it."""
    try:
        return path.relative_to(save_folder().parent).as_posix()
    except ValueError:
        return str(path)


def _names_from_outside(source: str, name: str) -> set[str]:
    """Names the saved file would look up outside itself (globals and builtins)."""
    top = symtable.symtable(source, f"{name}.py", "exec")
    used = {symbol.get_name() for symbol in top.get_symbols()
            if symbol.is_referenced() and not symbol.is_assigned()
            and not symbol.is_imported()}

    def walk(table: symtable.SymbolTable) -> None:
        for symbol in table.get_symbols():
            if symbol.is_global() and (symbol.is_referenced() or symbol.is_assigned()):
                used.add(symbol.get_name())
        for child in table.get_children():
            walk(child)

    for child in top.get_children():
        walk(child)
    return used - {name}


def _source_of(function: types.FunctionType, name: str) -> str:
    """The code of ``function``, one ``def`` at the top of a cell (dedented)."""
    try:
        with unheard():  # the pack reading the student's code, not the student a file
            source = textwrap.dedent(inspect.getsource(function))
        tree = ast.parse(source)
    except (OSError, TypeError, SyntaxError):
        raise StudentCodeError(
            f"save could not read the code of {name}: define it with def in a notebook "
            f"cell and run that cell first") from None
    if len(tree.body) != 1 or not isinstance(tree.body[0], ast.FunctionDef):
        raise StudentCodeError(f"save could not read the code of {name} as one def")
    return source


def _self_contained(function: types.FunctionType,
                    name: str) -> tuple[list[str], set[str], list[str]]:
    """The code to save for ``function`` (its own last, after the helper functions of the
    notebook it calls, each under the same rule), the names it looks up outside, and those
    of the notebook it may not use (sorted)."""
    sources, outside, foreign = [], set(), set()
    queue, seen = [(function, name)], {name}
    while queue:
        current, current_name = queue.pop()
        source = _source_of(current, current_name)
        sources.insert(0, source)
        for word in _names_from_outside(source, current_name) - seen:
            outside.add(word)
            value = function.__globals__.get(word)
            if (isinstance(value, types.FunctionType) and not value.__closure__
                    and value.__globals__ is function.__globals__
                    and value.__name__ == word):  # a helper of the student's: saved too
                seen.add(word)
                queue.append((value, word))
            elif word != "np" and (word in function.__globals__
                                   or not hasattr(builtins, word)):
                foreign.add(word)
    return sources, outside - seen, sorted(foreign)


def save(function: Callable, folder: str | os.PathLike | None = None) -> Callable:
    """Keep a student's function for later notebooks: ``my_functions/<name>.py``.

    The function's source (as written in its notebook cell) is written, after the
    header line :data:`SAVE_HEADER` and ``import numpy as np``, through a temporary file
    and ``os.replace``. A file of that name without the header (written by hand) is never
    replaced; a file that already holds the same text is left untouched. Prints one line,
    the same whether or not the file changed (a notebook's output does not depend on it).

    Parameters
    ----------
    function : callable
        A function defined with ``def`` at the top of a notebook cell. It may use its
        arguments, numpy as ``np``, Python's built-ins and functions of the notebook under
        the same rule (saved with it) only (the later notebook does not have the others).
    folder : path, optional
        Where to write; default :data:`SAVE_FOLDER` in the working folder of the first save
        or load of this session (in Jupyter, the notebook's folder): :func:`save_folder`.

    Returns
    -------
    callable
        The function loaded back from the saved file (:func:`load`).

    Raises
    ------
    StudentCodeError
        One line: not a function written with def, its source cannot be read, it uses
        names of the notebook (listed), the file is someone else's, or it cannot be
        written (nothing is then changed).
    """
    name = function_name(function)
    if not isinstance(function, types.FunctionType) or name == "your function":
        raise StudentCodeError(
            f"save needs a function written with def, got {short_repr(function)}")
    if function.__closure__:
        raise StudentCodeError(
            f"{name} is defined inside another function; save needs a function defined "
            f"at the top of a cell")
    sources, outside, foreign = _self_contained(function, name)
    if "np" in outside and function.__globals__.get("np", np) is not np:
        foreign.insert(0, "np (which is not numpy in your notebook)")
    if foreign:
        raise StudentCodeError(
            f"{name} uses {', '.join(foreign)} from the notebook; a saved function may use "
            f"only its arguments, numpy as np, Python's built-ins and functions of yours "
            f"defined with def at the top of a cell under the same rule. Pass the others in "
            f"as arguments (or compute them inside), run its cell, then this one again")
    source = "\n\n".join(sources)
    imports = "import numpy as np\n\n\n" if "np" in outside else "\n"
    text = (f"{SAVE_HEADER}\n# Loaded in later notebooks by student_code.load({name!r}).\n"
            f"{imports}{source.rstrip()}\n")
    path = _folder(folder) / f"{name}.py"
    shown = _shown(path)
    if path.is_symlink() or (path.exists() and not path.is_file()):
        raise StudentCodeError(f"{shown} is not a plain file, so save leaves it as it is: "
                               f"rename or delete it, then run this cell again")
    if path.exists():
        try:
            with unheard():
                old = path.read_text("utf-8")
        except (OSError, UnicodeDecodeError):
            old = ""
        if old.partition("\n")[0] != SAVE_HEADER:
            raise StudentCodeError(
                f"{shown} was not written by save (its first line is not save's header), so "
                f"it is left as it is: rename or delete it, then run this cell again")
    else:
        old = None
    if old != text:
        _write(path, text)
    print(f"{name} is saved in {shown}, where student_code.load({name!r}) finds it")
    return load(name, path.parent)


def _write(path: Path, text: str) -> None:
    """``text`` into ``path`` through a temporary file and ``os.replace``."""
    temporary = None
    try:
        path.parent.mkdir(exist_ok=True)
        with tempfile.NamedTemporaryFile("w", encoding="utf-8", dir=path.parent,
                                         prefix=f".{path.stem}.", suffix=".tmp",
                                         delete=False) as handle:
            temporary = Path(handle.name)
            handle.write(text)
        # A temporary file is private (0600); the saved one reads like any file the student
        # writes (its old mode, or rw-r--r--).
        os.chmod(temporary, stat.S_IMODE(path.stat().st_mode) if path.exists() else 0o644)
        os.replace(temporary, path)
    except OSError as error:
        if temporary is not None:
            temporary.unlink(missing_ok=True)
        raise StudentCodeError(f"save could not write {_shown(path)}: "
                               f"{error.strerror or error}") from None


def load(name: str, folder: str | os.PathLike | None = None) -> Callable:
    """A function kept by :func:`save`: runs ``my_functions/<name>.py`` and returns ``name``.

    The file runs in a fresh namespace holding numpy as ``np`` (and nothing of the
    notebook), under the time limit of :func:`call`.

    Parameters
    ----------
    name : str
        The function's name, e.g. ``"my_filter"``.
    folder : path, optional
        Where the file is; default :func:`save_folder`.

    Returns
    -------
    callable
        The function, with the inputs guard of its name if the pack has one
        (:func:`~lqe_helpers.student_code.guards.guarded`: ``my_filter`` given an R that
        does not fit its readings stops with one line naming R), noting its calls in the
        task cell that runs it (:func:`~lqe_helpers.student_code.task_runs.recorded`). If
        its file does not exist yet, a stand-in of the same name that
        raises :class:`NotSavedYet` (one line naming the notebook whose task writes it)
        whenever it is called, so the rest of the notebook (an explorer, say) still runs
        and every use of the function says what to do; :func:`load` then prints that
        line once too.

    Raises
    ------
    StudentCodeError
        One line: the file cannot be read or run, or does not define ``name``.
    """
    if not isinstance(name, str) or not name.isidentifier():
        raise ValueError(f"name must be a function's name, e.g. 'my_filter', got {name!r}")
    path = _folder(folder) / f"{name}.py"
    shown = _shown(path)
    if path.exists() and not path.is_file():
        kind = "a folder" if path.is_dir() else "not a plain file"
        raise StudentCodeError(
            f"{shown} is {kind}, so {name} cannot be loaded from it: rename or delete it, run "
            f"the task of {SAVED_BY.get(name, 'the notebook that saves it')} again, then this "
            f"cell")
    if not path.is_file():
        writer = SAVED_BY.get(name, f"the notebook whose task defines {name}")
        message = (f"{name} is not saved yet: {shown} does not exist. {writer} writes it when "
                   f"its check passes; run that first, then run this notebook again")
        print(message)
        return _not_saved_yet(name, message)
    try:
        with unheard():  # the pack reading the student's function, not the student a file
            source = path.read_text("utf-8")
        code = compile(source, str(path), "exec")
    except (OSError, UnicodeDecodeError, SyntaxError, ValueError) as error:
        raise StudentCodeError(f"{shown} could not be read as Python: "
                               f"{error_text(error)}") from None
    # the source a traceback quotes is the one loaded, and quoting it reads no file (a task
    # cell's read of a file is refused: student_code.outside)
    linecache.cache[str(path)] = (len(source), None, source.splitlines(True), str(path))
    namespace: dict[str, object] = {"__name__": f"{SAVE_FOLDER}.{name}",
                                    "__file__": str(path), "np": np, "__builtins__": builtins}
    call(exec, code, namespace, name=shown, rerun="run this cell again")
    function = namespace.get(name)
    if not isinstance(function, types.FunctionType):
        raise StudentCodeError(f"{shown} does not define a function {name}")
    fix = (f"This {name} is yours, saved by {SAVED_BY[name]}: fix it there, run that check "
           f"again (it saves {name} anew), then restart this notebook's kernel and run it from "
           f"the top" if name in SAVED_BY else "")
    return recorded(name, guarded(name, function, fix))


def _not_saved_yet(name: str, message: str) -> Callable:
    """A stand-in for the function ``name`` that says it is not saved yet when called."""

    def stand_in(*args: object, **kwargs: object) -> object:
        raise NotSavedYet(message)

    stand_in.__name__ = stand_in.__qualname__ = name
    return machinery_function(stand_in)
