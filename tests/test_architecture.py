"""docs/architecture.md says what is true: its import picture and the tests it names.

The picture's lines (``a ─► b, c``) are read from the markdown and compared with the
layer-to-layer imports of the package, computed with ``ast`` by the same reader as
``tests/test_import_layers.py``: an arrow that does not exist and one that is missing
both fail.
"""

from __future__ import annotations

import re
from pathlib import Path

from test_import_layers import LAYERS, imports, layer_of, sources

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "architecture.md"
#: The notebooks' module names, which a ``<module>`` in a test path stands for.
MODULES = ("background", "vision", "initial_covariance", "fusion", "noisier_proprioception",
           "delay", "bias")
ARROW = "─►"


def picture(text: str) -> set[tuple[str, str]]:
    """(layer, layer it imports) of every arrow in the fenced block after "Who imports whom"."""
    after = text[text.index("Who imports whom"):]
    block = re.search(r"```\n(.*?)```", after, re.S).group(1)
    arrows = set()
    for line in block.splitlines():
        if not line.strip():
            continue
        source, _, targets = line.partition(ARROW)
        source = source.strip()
        assert source in LAYERS, f"not a layer: {line!r}"
        targets = targets.strip()
        if targets != "(none)":
            arrows |= {(source, target.strip()) for target in targets.split(",")}
    return arrows


def real_imports() -> set[tuple[str, str]]:
    """(layer, another layer) for every import in the package from one layer to another."""
    found = set()
    for module, path in sources():
        for target, _, _ in imports(module, path.read_text(encoding="utf-8"),
                                    path.name == "__init__.py"):
            if layer_of(module) != layer_of(target):
                found.add((layer_of(module), layer_of(target)))
    return found


def test_the_import_picture_is_the_packages_imports() -> None:
    drawn, real = picture(DOC.read_text(encoding="utf-8")), real_imports()
    assert drawn - real == set(), "arrows drawn that no import makes"
    assert real - drawn == set(), "imports the picture does not draw"


def test_the_reader_sees_an_arrow_too_many_and_one_missing() -> None:
    text = DOC.read_text(encoding="utf-8")
    wrong = text.replace("authoring   ─► checks", "authoring   ─► checks, explorers")
    assert picture(wrong) - real_imports() == {("authoring", "explorers")}
    wrong = text.replace("checks      ─► experiments, science", "checks      ─► experiments")
    assert real_imports() - picture(wrong) == {("checks", "science")}


def test_every_test_file_the_page_names_exists() -> None:
    named = set(re.findall(r"tests/[\w/<>*.-]+\.py", DOC.read_text(encoding="utf-8")))
    assert named, "the page names no test file"
    missing = []
    for name in sorted(named):
        variants = ([name.replace("<module>", module) for module in MODULES]
                    if "<module>" in name else [name])
        for variant in variants:
            if not list(ROOT.glob(variant)):
                missing.append(variant)
    assert missing == []


def test_the_pictures_table_names_every_figure_and_explorer() -> None:
    from lqe_helpers import figures

    text = DOC.read_text(encoding="utf-8")
    section = text[text.index("## Each picture and its one drawing function"):
                   text.index("## Where to change what")]
    named = set(re.findall(r"`(\w+)`", section))
    drawers = {f"draw_{module}" for module in MODULES}
    assert set(figures.__all__) - named == set(), "figures the table does not list"
    assert drawers - named == set(), "explorers the table does not list"
    for module in MODULES:
        explorer = __import__(f"lqe_helpers.explorers.{module}", fromlist=["x"])
        assert hasattr(explorer, f"draw_{module}")
