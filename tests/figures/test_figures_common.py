"""The legend labels several pictures share are written once, in figures/common.py (issue 25).

Every other module of figures/ imports them: a second copy of such a string ("true path",
"filtered estimate", …) anywhere else in figures/ fails here, and the explorers' labels
(by which their tests find the artists) are common's.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from lqe_helpers.figures import background, bias, common, initial_covariance, vision
from lqe_helpers.plotting import COLORS

FIGURES = Path(common.__file__).resolve().parent
#: The shared labels: every ``*_LABEL`` string constant of common.py.
SHARED = {name: value for name, value in vars(common).items()
          if name.endswith("_LABEL") and isinstance(value, str)}


#: Those a copy of which is found: not "vision", also the name of a style role.
FOUND = set(SHARED.values()) - set(COLORS)


def copies(source: str) -> list[str]:
    """``"text":line`` of every string constant in ``source`` equal to a shared label
    (of :data:`FOUND`), a dict's keys (the gids an explorer refills by) left out."""
    tree = ast.parse(source)
    keys = {id(key) for node in ast.walk(tree) if isinstance(node, ast.Dict)
            for key in node.keys}
    return [f"{node.value!r}:{node.lineno}" for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and node.value in FOUND and id(node) not in keys]


def test_common_defines_the_shared_labels() -> None:
    assert {"true path", "true position", "vision", "noisy vision", "filtered estimate",
            "±2σ of the filter's own variance", "vision only",
            "vision readings"} <= set(SHARED.values())
    assert len(set(SHARED.values())) == len(SHARED), "a label defined twice in common.py"


@pytest.mark.parametrize("path", sorted(FIGURES.glob("*.py")), ids=lambda path: path.stem)
def test_no_other_module_of_figures_writes_a_shared_label_again(path) -> None:
    if path.name == "common.py":
        return
    assert copies(path.read_text(encoding="utf-8")) == [], (
        f"import the label from figures/common.py instead ({sorted(SHARED)})")


def test_a_copy_of_a_shared_label_would_be_found() -> None:
    assert copies('TRUTH_LABEL = "true path"\nx = ("true", "path")\n') == ["'true path':1"]
    assert copies('lines = {"vision readings": (0, "vision", "vision readings")}') == [
        "'vision readings':1"]
    assert copies(f'label = "{common.ESTIMATE_LABEL}"') == ["'filtered estimate':1"]


@pytest.mark.parametrize(("module", "labels"), [
    (background, {"TRUTH_LABEL": "TRUE_PATH_LABEL", "VISION_LABEL": "VISION_LABEL",
                  "ESTIMATE_LABEL": "ESTIMATE_LABEL"}),
    (bias, {"TRUTH_LABEL": "TRUE_PATH_LABEL", "VISION_LABEL": "VISION_LABEL",
            "ESTIMATE_LABEL": "ESTIMATE_LABEL"}),
    (initial_covariance, {"VISION_LABEL": "NOISY_VISION_LABEL",
                          "ESTIMATE_LABEL": "ESTIMATE_LABEL", "BAND_LABEL": "BAND_LABEL"}),
    (vision, {"TRUTH_LABEL": "TRUE_POSITION_LABEL", "VISION_LABEL": "NOISY_VISION_LABEL",
              "ESTIMATE_LABEL": "ESTIMATE_LABEL", "BAND_LABEL": "BAND_LABEL"}),
], ids=lambda value: getattr(value, "__name__", "labels").rsplit(".", 1)[-1])
def test_the_explorers_labels_are_commons(module, labels) -> None:
    """The labels each explorer (and its tests) find artists by, unchanged in value."""
    for name, shared in labels.items():
        assert getattr(module, name) is getattr(common, shared), f"{module.__name__}.{name}"
