"""No explorer at its default values shows a number a task of its notebook asks for (issue 15).

Each explorer's default numbers line (the line between its sliders and its figure, also
the caption of its static picture) and the texts of its figure are compared with every
number printed by the code cells of its notebook (the cells tagged ``solution`` and the
given cells that print what a task computed), as saved in the executed notebook.
Numbers that are the explorer's own inputs (its slider values, the scenario's
constants) are givens, not answers. A number leaks when, rounded to the precision a
cell printed, it gives that cell's number (so 0.304 leaks a printed 0.30). The
explorers avoid it by showing another noise draw than the tasks
(``Scenario.explorer_seed``) and, where a number does not depend on the noise, by
starting near, not at, a task's value (00's σ_j, 04's σ_p).
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path
from typing import NamedTuple

import pytest
from explorer_checks import fresh_figure
from matplotlib.axis import Tick
from matplotlib.text import Text

from lqe_helpers.explorers import (
    background,
    bias,
    delay,
    fusion,
    initial_covariance,
    noisier_proprioception,
    vision,
)
from lqe_helpers.scenario import DEFAULT

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"

#: notebook → (explorer module, its factory).
EXPLORERS = {
    "00_background_model": (background, "explore_background"),
    "01_vision_only": (vision, "explore_vision"),
    "02_initial_covariance": (initial_covariance, "explore_initial_covariance"),
    "03_fusion": (fusion, "explore_fusion"),
    "04_noisier_proprioception": (noisier_proprioception, "explore_noisier_proprioception"),
    "05_sensory_delay": (delay, "explore_delay"),
    "06_bonus_bias_and_input": (bias, "explore_bias"),
}

#: A number as printed: optional sign, thousands groups or digits, decimals, exponent.
NUMBER = re.compile(r"(?<![\w.])[-+−]?(?:\d{1,3}(?:,\d{3})+|\d+)(?:\.\d+)?(?:e[-+]?\d+)?")


class Printed(NamedTuple):
    """A number as text shows it: its value and how many decimals it was given."""

    text: str
    value: float
    decimals: int

    @property
    def significant(self) -> int:
        """Significant digits shown (trailing zeros of a whole number do not count)."""
        mantissa = self.text.lstrip("+-−").split("e")[0].replace(",", "")
        digits = mantissa.replace(".", "").lstrip("0")
        return len(digits if "." in mantissa else digits.rstrip("0"))


def numbers_in(text: str) -> list[Printed]:
    """Every number printed in ``text``."""
    found = []
    for match in NUMBER.finditer(text):
        token = match.group()
        plain = token.replace(",", "").replace("−", "-")
        mantissa = plain.split("e")[0]
        decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
        found.append(Printed(token, float(plain), decimals))
    return found


def reveals(shown: Printed, answer: Printed) -> bool:
    """True if ``shown``, as precise as ``answer`` or more, rounds to ``answer``'s number."""
    if answer.significant < 2 or shown.decimals < answer.decimals:
        return False
    return math.isclose(round(shown.value, answer.decimals), answer.value, rel_tol=0,
                        abs_tol=10.0 ** -(answer.decimals + 6))


def solution_outputs(name: str) -> list[str]:
    """The text every code cell of notebook ``name`` but its explorer's printed or displayed.

    A task need not print what it computed: a given cell after its check may do it.
    """
    notebook = json.loads((NOTEBOOKS / f"{name}.ipynb").read_text(encoding="utf-8"))
    texts = []
    for cell in notebook["cells"]:
        if cell["cell_type"] != "code" or "explorer" in cell["metadata"].get("tags", []):
            continue
        for output in cell.get("outputs", []):
            if output["output_type"] == "stream":
                texts.append("".join(output["text"]))
            for kind in ("text/markdown", "text/plain"):
                if kind in output.get("data", {}) and "image/png" not in output["data"]:
                    texts.append("".join(output["data"][kind]))
    return texts


def givens(sliders: dict[str, tuple[float, str]], scenario=DEFAULT) -> set[str]:
    """How an explorer prints what it is given, not computes: its slider values (name →
    (value, readout format)) and the scenario's constants, as ``:g`` prints them."""
    shown = set()
    for value, readout in sliders.values():
        shown |= {format(value, readout), f"{value:g}", f"{value:,.0f}"}
    constants = [v for v in dataclasses.asdict(scenario).values() if isinstance(v, (int, float))]
    constants += [scenario.delay / scenario.dt, scenario.process_jerk_std]
    return shown | {f"{value:g}" for value in constants}


def slider_values(explorer) -> dict[str, tuple[float, str]]:
    return {name: (slider.value, slider.readout_format)
            for name, slider in explorer.sliders.items()}


def figure_texts(figure) -> list[str]:
    """Every text the figure draws besides tick labels (titles, legends, bar labels)."""
    ticks = {label for tick in figure.findobj(Tick) for label in (tick.label1, tick.label2)}
    return [text.get_text() for text in figure.findobj(Text) if text not in ticks]


def leaks(shown_text: str, given: set[str], answers: list[Printed]) -> list[str]:
    """Each computed number of ``shown_text`` (not in ``given``) that reveals an answer."""
    found = []
    for shown in numbers_in(shown_text):
        if shown.text.lstrip("+") in given:
            continue
        found += [f"{shown.text} reveals {answer.text}" for answer in answers
                  if reveals(shown, answer)]
    return found


def answers_of(name: str) -> list[Printed]:
    return [number for text in solution_outputs(name) for number in numbers_in(text)]


@pytest.mark.parametrize("name", sorted(EXPLORERS))
@pytest.mark.slow
def test_no_explorer_at_its_defaults_shows_a_number_its_notebooks_tasks_print(name) -> None:
    module, factory = EXPLORERS[name]
    explorer = getattr(module, factory)()
    answers = answers_of(name)
    assert len(answers) > 5, f"{name}: no solution outputs found; is the notebook executed?"
    shown = " ".join([explorer.numbers, *figure_texts(explorer.figure)])
    assert explorer.numbers and numbers_in(explorer.numbers)
    assert leaks(shown, givens(slider_values(explorer)), answers) == [], explorer.numbers


#: Views the notebook's Explore section sends the student to, before the Going further
#: tasks that compute their numbers: (notebook, slider values). At σ_p = 4.5 cm 04's
#: explorer gave proprioception's weight, 10.0 %, which its Going further 1 computes
#: (issue 23 §5).
DIRECTED_VIEWS = [("04_noisier_proprioception", {"sigma_p": 4.5})]


def explore_section(name: str) -> str:
    """The markdown of notebook ``name``'s "## Explore" cell."""
    notebook = json.loads((NOTEBOOKS / f"{name}.ipynb").read_text(encoding="utf-8"))
    return next("".join(cell["source"]) for cell in notebook["cells"]
                if cell["cell_type"] == "markdown" and "".join(cell["source"]).startswith(
                    "## Explore"))


@pytest.mark.parametrize(("name", "values"), DIRECTED_VIEWS,
                         ids=[case[0] for case in DIRECTED_VIEWS])
@pytest.mark.slow
def test_a_view_the_explore_section_asks_for_shows_no_number_a_task_prints(name, values) -> None:
    module, factory = EXPLORERS[name]
    section = explore_section(name)
    assert all(f"{value:g} cm" in section for value in values.values()), section
    explorer = getattr(module, factory)()
    for key, value in values.items():
        explorer.sliders[key].value = value
    assert explorer.values == values and explorer.numbers
    shown = " ".join([explorer.numbers, *figure_texts(explorer.figure)])
    assert leaks(shown, givens(slider_values(explorer)), answers_of(name)) == [], explorer.numbers


#: (notebook, draw function, the task's values) where the tasks' draw used to show.
TASK_VALUES = [
    ("00_background_model", background.draw_background,
     {"jerk_std": DEFAULT.process_jerk_std}, "0.29"),
    ("01_vision_only", vision.draw_vision, {"sigma_v": 1.5}, "2.04"),
    ("03_fusion", fusion.draw_fusion, {"sigma_v": 1.5, "sigma_p": 1.5}, "0.1596"),
    ("04_noisier_proprioception", noisier_proprioception.draw_noisier_proprioception,
     {"sigma_p": 4.5}, "0.3042"),
]
# 05 is not here: its tasks print no one-run MSE (its explorer's numbers line) any more.


@pytest.mark.parametrize(("name", "draw", "values", "answer"), TASK_VALUES,
                         ids=[case[0] for case in TASK_VALUES])
def test_the_check_finds_the_answers_a_view_at_the_tasks_values_and_draw_shows(
        name, draw, values, answer) -> None:
    """Drawn at the task's values on the task's noise (what the explorers showed before
    issue 15), the numbers line gives away the answer, and the check says so."""
    numbers = draw(fresh_figure(), **values)
    formats = {"jerk_std": ".0f", "sigma_v": ".1f", "sigma_p": ".2f", "delay": ".2f"}
    found = leaks(numbers, givens({key: (value, formats[key]) for key, value in values.items()}),
                  answers_of(name))
    assert any(line.startswith(f"{answer} reveals") for line in found), (numbers, found)


def test_numbers_are_read_as_printed() -> None:
    assert [n.text for n in numbers_in("σ_j = 1,396 cm/s³, MSE 0.3831 (95 % CI −0.2 to "
                                       "+4.1), 1e-05, x2 a.5")] == [
        "1,396", "0.3831", "95", "−0.2", "+4.1", "1e-05"]
    one_396, mse = numbers_in("1,396 0.3831")
    assert (one_396.value, one_396.decimals, one_396.significant) == (1396.0, 0, 4)
    assert (mse.value, mse.decimals, mse.significant) == (0.3831, 4, 4)
    assert numbers_in("300")[0].significant == 1
    assert reveals(numbers_in("0.304")[0], numbers_in("0.30")[0])
    assert not reveals(numbers_in("0.3")[0], numbers_in("0.30")[0])  # less precise
    assert not reveals(numbers_in("0.314")[0], numbers_in("0.30")[0])
    assert not reveals(numbers_in("2.04")[0], numbers_in("2")[0])      # one digit: too coarse
