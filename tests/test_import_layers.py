"""The package's layers: who may import whom, no private name across modules, short modules.

Layers, bottom to top (issue 18):

* science: the equations, the engine and the scenario (every module of
  ``lqe_helpers`` not named below, e.g. ``model``, ``filter``, ``scenario``);
* drawing: ``plotting`` and ``figures`` (figures take arrays, so they import no
  experiment and no explorer);
* experiments: ``experiments``, ``tracking_figures``, ``own_runs``, ``systematic_error`` and
  ``bias_model``, whose results may draw themselves through ``figures``, and ``jerk_tuning``,
  which runs experiments;
* explorers and checks, side by side: neither imports the other;
* authoring: the instructor's tools, which nothing imports but grading;
* grading: grading a class, built on authoring, which nothing imports.

A module may import its own layer and the layers below it. A private module (``_x``)
may be imported only by modules inside its own package (its subpackages too), and no
module imports another module's private name. Imports inside functions count too.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "lqe_helpers"
LAYERS = ("science", "drawing", "experiments", "explorers", "checks", "authoring", "grading")
#: The layers each layer may import.
ALLOWED = {
    "science": {"science"},
    "drawing": {"science", "drawing"},
    "experiments": {"science", "drawing", "experiments"},
    "explorers": {"science", "drawing", "experiments", "explorers"},
    "checks": {"science", "drawing", "experiments", "checks"},
    "authoring": set(LAYERS) - {"grading"},
    "grading": set(LAYERS),
}
#: Longest module allowed (lines), in every layer (the instructor's tools too).
MAX_LINES = 500


def layer_of(module: str) -> str:
    """The layer of module ``lqe_helpers.<...>``."""
    parts = module.split(".")[1:]
    top = parts[0] if parts else ""
    if top in ("plotting", "figures"):
        return "drawing"
    if top in ("experiments", "tracking_figures", "own_runs", "systematic_error", "bias_model",
               "jerk_tuning"):
        return "experiments"
    if top in ("explorers", "checks", "authoring", "grading"):
        return top
    return "science"


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def package_of(module: str, path_is_init: bool) -> str:
    return module if path_is_init else module.rsplit(".", 1)[0]


def imports(module: str, source: str, is_init: bool = False) -> list[tuple[str, str | None, int]]:
    """(imported lqe_helpers module, name taken from it or None, line) of every import."""
    package = package_of(module, is_init)
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(alias.name, None, node.lineno) for alias in node.names
                      if alias.name.split(".")[0] == "lqe_helpers"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != "lqe_helpers":
                continue
            for alias in node.names:
                candidate = f"{target}.{alias.name}"
                if (PACKAGE.parent / candidate.replace(".", "/")).with_suffix(".py").exists() or (
                        PACKAGE.parent / candidate.replace(".", "/") / "__init__.py").exists():
                    found.append((candidate, None, node.lineno))  # a submodule
                else:
                    found.append((target, alias.name, node.lineno))
    return found


def module_aliases(module: str, source: str, is_init: bool = False) -> dict[str, str]:
    """Local name → lqe_helpers module, for every name an import binds to a module.

    ``from . import validation`` binds ``validation``; ``import lqe_helpers.filter as f``
    binds ``f``. (A plain ``import lqe_helpers.x`` binds ``lqe_helpers``, whose attribute
    chains :func:`private_attributes` follows from the top.)
    """
    bound = {}
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "lqe_helpers":
                    if alias.asname:
                        bound[alias.asname] = alias.name
                    else:
                        bound["lqe_helpers"] = "lqe_helpers"
    for target, name, _ in imports(module, source, is_init):
        if name is None:  # a submodule, bound under its last part (or its alias)
            bound.setdefault(target.rsplit(".", 1)[-1], target)
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            for alias in node.names:
                if alias.asname:
                    for target, name, _ in imports(module, f"from {'.' * node.level}"
                                                   f"{node.module or ''} import {alias.name}",
                                                   is_init):
                        if name is None:
                            bound[alias.asname] = target
    return bound


def private_attributes(module: str, source: str,
                       is_init: bool = False) -> list[tuple[str, str, int]]:
    """(lqe_helpers module, private attribute, line) of every ``module._name`` in ``source``.

    ``validation._not_real(x)`` after ``from . import validation``, or
    ``lqe_helpers.validation._not_real`` after ``import lqe_helpers.validation``.
    """
    aliases = module_aliases(module, source, is_init)
    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.Attribute):
            continue
        chain, value = [node.attr], node.value
        while isinstance(value, ast.Attribute):
            chain.insert(0, value.attr)
            value = value.value
        if not isinstance(value, ast.Name) or value.id not in aliases:
            continue
        target = aliases[value.id]
        for part in chain:
            if part.startswith("_") and not part.startswith("__"):
                found.append((target, part, node.lineno))
                break
            target = f"{target}.{part}"
    return sorted(set(found), key=lambda item: item[2])


def problems(module: str, source: str, is_init: bool = False) -> list[str]:
    """What breaks the rules in ``module``'s ``source``, one line each."""
    package = package_of(module, is_init)
    layer = layer_of(module)
    found = []
    for target, name, line in private_attributes(module, source, is_init):
        if target != module:
            found.append(f"{module}:{line} uses the private name {name} of {target}")
    for target, name, line in imports(module, source, is_init):
        if layer_of(target) not in ALLOWED[layer]:
            found.append(f"{module}:{line} ({layer}) imports {target} ({layer_of(target)})")
        parts = target.split(".")
        for depth, part in enumerate(parts):
            owner = ".".join(parts[:depth])
            inside = package == owner or package.startswith(owner + ".")
            if part.startswith("_") and not part.startswith("__") and not inside:
                found.append(f"{module}:{line} imports {target}, private to {owner}")
        if name is not None and name.startswith("_") and target != module:
            found.append(f"{module}:{line} imports the private name {name} of {target}")
    return found


def sources() -> list[tuple[str, Path]]:
    return sorted((module_name(path), path) for path in PACKAGE.rglob("*.py")
                  if "student_pack_files" not in path.parts)


@pytest.mark.parametrize(("module", "path"), sources(), ids=[name for name, _ in sources()])
def test_imports_run_down_the_layers_and_no_private_name_crosses_a_module(module, path) -> None:
    assert problems(module, path.read_text(encoding="utf-8"), path.name == "__init__.py") == []


def test_no_module_is_longer_than_the_limit() -> None:
    long = {module: length for module, path in sources()
            if (length := len(path.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert long == {}


def test_figures_mirror_the_explorers() -> None:
    def modules(folder: str) -> set[str]:
        return {path.stem for path in (PACKAGE / folder).glob("*.py")}
    notebooks = {"background", "vision", "initial_covariance", "fusion",
                 "noisier_proprioception", "delay", "bias"}
    assert notebooks | {"common"} <= modules("figures") and notebooks | {"common"} <= modules(
        "explorers")
    assert modules("figures") - notebooks == {"__init__", "common"}


@pytest.mark.parametrize(("module", "source", "expected"), [
    # Yesterday's explorer.py: a top-level module reaching into the explorers' private one.
    ("lqe_helpers.explorer", "from .explorers._layers import LayeredCanvas",
     "imports lqe_helpers.explorers._layers, private to lqe_helpers.explorers"),
    ("lqe_helpers.model", "from . import figures", "(science) imports lqe_helpers.figures"),
    ("lqe_helpers.model", "def f():\n    from .explorers import vision",
     "(science) imports lqe_helpers.explorers.vision (explorers)"),
    ("lqe_helpers.figures.delay", "from .. import experiments",
     "(drawing) imports lqe_helpers.experiments"),
    ("lqe_helpers.figures.delay", "from ..explorers.panels import reuse_panels",
     "(drawing) imports lqe_helpers.explorers.panels"),
    ("lqe_helpers.explorers.vision", "from ..checks import check_mse",
     "(explorers) imports lqe_helpers.checks"),
    ("lqe_helpers.explorers.vision", "from ..experiments import _one_run",
     "imports the private name _one_run of lqe_helpers.experiments"),
    ("lqe_helpers.checks._filter", "import lqe_helpers.authoring.files",
     "(checks) imports lqe_helpers.authoring.files (authoring)"),
    ("lqe_helpers.authoring.marking_guide", "from lqe_helpers.grading import rules",
     "(authoring) imports lqe_helpers.grading.rules (grading)"),
    # Yesterday's smoothing.py: a private function of another module, as an attribute.
    ("lqe_helpers.smoothing", "from . import validation\nreason = validation._not_real(w)",
     "uses the private name _not_real of lqe_helpers.validation"),
    ("lqe_helpers.checks.vision", "from .. import experiments as ex\nex._one_run(v, 0)",
     "uses the private name _one_run of lqe_helpers.experiments"),
    ("lqe_helpers.checks.vision", "import lqe_helpers.filter\nlqe_helpers.filter._largest({})",
     "uses the private name _largest of lqe_helpers.filter"),
    ("lqe_helpers.explorers.vision", "def f():\n    from ..figures import common\n"
     "    common._hidden()", "uses the private name _hidden of lqe_helpers.figures.common"),
])
def test_the_rules_catch_what_they_forbid(module, source, expected) -> None:
    assert any(expected in problem for problem in problems(module, source)), problems(
        module, source)


def test_the_rules_allow_what_the_layers_need() -> None:
    allowed = [
        ("lqe_helpers.experiments", "def figure(self):\n    from . import figures"),
        ("lqe_helpers.model", "from . import _matrices, validation"),
        ("lqe_helpers.explorers.fusion",
         "from .common import TrialLine\nfrom .. import experiments"),
        ("lqe_helpers.checks._filter",
         "from ._common import CheckFailed\nfrom .. import reference"),
        ("lqe_helpers.authoring.marking_guide", "from lqe_helpers import checks"),
        ("lqe_helpers.grading.grade", "from lqe_helpers.authoring.points import core_end"),
        # A private module of its own package, its public names; dunders; other objects.
        ("lqe_helpers.experiments", "from . import _engine\n_engine.filter_run(y)"),
        ("lqe_helpers.experiments", "from . import figures\nfigures.__name__"),
        ("lqe_helpers.experiments", "def f(model):\n    return model._checked"),
        ("lqe_helpers.validation", "import lqe_helpers.validation as v\nv._not_real(1)"),
    ]
    for module, source in allowed:
        assert problems(module, source) == [], (module, problems(module, source))


def definitions(name: str) -> list[str]:
    """The modules of lqe_helpers that define ``name`` at their top level."""
    found = []
    for module, path in sources():
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                names = [node.name]
            elif isinstance(node, ast.Assign):
                names = [target.id for target in node.targets if isinstance(target, ast.Name)]
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                names = [node.target.id]
            else:
                names = []
            found += [module] * names.count(name)
    return found


@pytest.mark.parametrize(("name", "home"), [
    ("filter_model", "lqe_helpers.experiments"),   # the one builder of the model
    ("FILTER_ARGS", "lqe_helpers.filter"),         # the parameters of eq. (5)'s filter
])
def test_one_thing_is_defined_in_one_place(name, home) -> None:
    assert definitions(name) == [home]


def test_filter_args_are_the_engines_parameters() -> None:
    import inspect

    from lqe_helpers.filter import FILTER_ARGS, kalman_filter

    assert FILTER_ARGS == tuple(inspect.signature(kalman_filter).parameters)[:7]
