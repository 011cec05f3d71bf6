"""What a cell's code says, read without running it: whether it is a task cell, the names it
defines, reads and mentions, and the names it passes to a check.

The task-cell record (:mod:`lqe_helpers.student_code.task_runs`) keeps these for every cell
it records: a check finds its task cell by the names it is passed, and follows that cell's
values back through the cells that defined the names it reads.
"""

from __future__ import annotations

import ast
import re

#: How a task cell starts (after blank lines).
TASK_PREFIX = "# Task:"


def is_task_cell(source: str) -> bool:
    """Whether a cell's code starts with a ``# Task:`` comment."""
    return source.lstrip().startswith(TASK_PREFIX)


def defined_names(source: str) -> frozenset[str]:
    """Names assigned or defined at the top level of ``source`` (empty if it does not parse)."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return frozenset()
    names: set[str] = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
            continue
        for child in _outer_nodes(node):
            if isinstance(child, ast.Name) and isinstance(child.ctx, ast.Store):
                names.add(child.id)
    return frozenset(names)


#: Nodes whose names live in a scope of their own (a comprehension's loop variable).
_OWN_SCOPE = (ast.ListComp, ast.SetComp, ast.DictComp, ast.GeneratorExp, ast.Lambda,
              ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)


def _outer_nodes(node: ast.AST) -> list[ast.AST]:
    """``node`` and the nodes below it, but not inside a scope of their own."""
    found, stack = [], [node]
    while stack:
        current = stack.pop()
        found.append(current)
        stack.extend(child for child in ast.iter_child_nodes(current)
                     if not isinstance(child, _OWN_SCOPE))
    return found


class _ReadOrder(ast.NodeVisitor):
    """Visits a cell's code in the order it runs (a value before the name it is given), noting
    whether each name is first read or first given a value."""

    def __init__(self) -> None:
        self.first_read: dict[str, bool] = {}

    def note(self, name: str, read: bool) -> None:
        self.first_read.setdefault(name, read)

    def visit_Name(self, node: ast.Name) -> None:
        self.note(node.id, isinstance(node.ctx, ast.Load))

    def visit_arg(self, node: ast.arg) -> None:
        self.note(node.arg, False)

    def visit_alias(self, node: ast.alias) -> None:
        self.note((node.asname or node.name).split(".")[0], False)

    def _value_first(self, node: ast.AST, value: ast.AST | None, targets: list[ast.AST]) -> None:
        if isinstance(node, ast.AugAssign) and isinstance(node.target, ast.Name):
            self.note(node.target.id, True)
        if value is not None:
            self.visit(value)
        for target in targets:
            self.visit(target)

    def visit_Assign(self, node: ast.Assign) -> None:
        self._value_first(node, node.value, node.targets)

    def visit_AugAssign(self, node: ast.AugAssign) -> None:
        self._value_first(node, node.value, [node.target])

    def visit_AnnAssign(self, node: ast.AnnAssign) -> None:
        self._value_first(node, node.value, [node.target])

    def visit_NamedExpr(self, node: ast.NamedExpr) -> None:
        self._value_first(node, node.value, [node.target])

    def visit_For(self, node: ast.For | ast.AsyncFor) -> None:
        self._value_first(node, node.iter, [node.target, *node.body, *node.orelse])

    visit_AsyncFor = visit_For

    def visit_comprehension(self, node: ast.comprehension) -> None:
        self._value_first(node, node.iter, [node.target, *node.ifs])

    def _comprehension(self, node: ast.AST, results: list[ast.AST]) -> None:
        for generator in node.generators:  # type: ignore[attr-defined]
            self.visit(generator)
        for result in results:
            self.visit(result)

    def visit_ListComp(self, node: ast.ListComp) -> None:
        self._comprehension(node, [node.elt])

    visit_SetComp = visit_GeneratorExp = visit_ListComp

    def visit_DictComp(self, node: ast.DictComp) -> None:
        self._comprehension(node, [node.key, node.value])

    def _definition(self, node: ast.AST, name: str | None) -> None:
        for decorator in getattr(node, "decorator_list", ()):
            self.visit(decorator)
        if name is not None:
            self.note(name, False)
        for field_name in ("bases", "keywords", "args", "body"):
            value = getattr(node, field_name, None)
            for child in value if isinstance(value, list) else [value] if value else []:
                self.visit(child)

    def visit_FunctionDef(self, node: ast.FunctionDef | ast.AsyncFunctionDef) -> None:
        self._definition(node, node.name)

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_ClassDef(self, node: ast.ClassDef) -> None:
        self._definition(node, node.name)

    def visit_Lambda(self, node: ast.Lambda) -> None:
        self._definition(node, None)


def read_names(source: str) -> frozenset[str]:
    """Names ``source`` reads before it gives them a value (empty if it does not parse).

    The code is taken in the order it runs (``x = f(x)`` reads ``x``); a function's body
    counts where the function is defined, its parameters as given.
    """
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return frozenset()
    order = _ReadOrder()
    order.visit(tree)
    return frozenset(name for name, read in order.first_read.items() if read)


def mentioned_names(source: str) -> frozenset[str]:
    """Identifiers in the comment lines at the top of ``source`` (its ``# Task:`` block)."""
    words: set[str] = set()
    for line in source.lstrip().splitlines():
        if not line.lstrip().startswith("#"):
            break
        words.update(re.findall(r"[A-Za-z_][A-Za-z_0-9]*", line))
    return frozenset(words)


def argument_names(source: str, check: str) -> list[str]:
    """The bare names passed to a call of ``check`` (``checks.check_x(C, R)``) in ``source``."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return []
    names: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            called = node.func
            called_name = (called.attr if isinstance(called, ast.Attribute)
                           else called.id if isinstance(called, ast.Name) else "")
            if called_name == check:
                arguments = [*node.args, *(keyword.value for keyword in node.keywords)]
                names += [argument.id for argument in arguments
                          if isinstance(argument, ast.Name)]
    return names


def calls_a_check(source: str) -> bool:
    """Whether ``source`` calls a function named ``check_…``."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return False
    return any(isinstance(node, ast.Call) and (
        getattr(node.func, "attr", "") or getattr(node.func, "id", "")).startswith("check_")
        for node in ast.walk(tree))


#: Ways to reach a value by a name made as the code runs (or kept outside the cell's
#: names), whose origin a check cannot trace: what each is called in a message.
_NAMESPACE_CALLS = {"globals": "globals()", "vars": "vars()", "locals": "locals()"}
_NAMESPACE_NAMES = {"builtins": "builtins", "__builtins__": "__builtins__", "Out": "Out",
                    "_oh": "_oh", "_": "_", "__": "__", "___": "___"}
_NAMESPACE_ATTRIBUTES = {"user_ns": "user_ns", "__dict__": "__dict__", "modules": "sys.modules",
                         "environ": "os.environ", "f_locals": "f_locals",
                         "f_globals": "f_globals"}


def untraceable_reads(source: str) -> list[str]:
    """How a cell's code reaches values by names it makes as it runs, or outside its names
    (``globals()[...]``, ``getattr(x, name)`` with a name not written out, ``builtins``,
    ``Out[...]``, ``user_ns``, ``__dict__``, ``sys.modules``, ``os.environ``), each as a
    message says it, in the order found; [] if none (or the code does not parse)."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return []
    found: list[str] = []
    for node in ast.walk(tree):
        what = ""
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            if node.func.id in _NAMESPACE_CALLS and not node.args:
                what = _NAMESPACE_CALLS[node.func.id]
            elif node.func.id == "getattr" and len(node.args) >= 2 and not isinstance(
                    node.args[1], ast.Constant):
                what = "getattr with a name made as the code runs"
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load):
            what = _NAMESPACE_NAMES.get(node.id, "")
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Load):
            what = _NAMESPACE_ATTRIBUTES.get(node.attr, "")
        if what and what not in found:
            found.append(what)
    return found
