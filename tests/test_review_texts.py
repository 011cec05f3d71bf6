"""Issue 23 §5: the science review's corrections to the notebooks' prose stay made.

Each test reads the committed notebooks. Where the prose states a count or a bound, the
test also reads the output of the cell that prints it, so the sentence and the printed
number cannot drift apart; tests/test_science_numbers.py recomputes the numbers.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from lqe_helpers.scenario import DEFAULT

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"


def cells(name: str) -> list[dict]:
    return json.loads((NOTEBOOKS / f"{name}.ipynb").read_text(encoding="utf-8"))["cells"]


def source(cell: dict) -> str:
    return "".join(cell["source"])


def output(cell: dict) -> str:
    return "".join("".join(out.get("text", "")) for out in cell.get("outputs", []))


def markdown_starting(name: str, heading: str) -> str:
    """The markdown cell of notebook ``name`` whose source starts with ``heading``."""
    found = [source(cell) for cell in cells(name)
             if cell["cell_type"] == "markdown" and source(cell).startswith(heading)]
    assert len(found) == 1, (name, heading, len(found))
    return found[0]


def printed_by(name: str, code: str) -> str:
    """The output of the one code cell of notebook ``name`` whose source contains ``code``."""
    found = [output(cell) for cell in cells(name)
             if cell["cell_type"] == "code" and code in source(cell)]
    assert len(found) == 1, (name, code, len(found))
    return found[0]


def test_03_the_prediction_is_a_cue_whose_reliability_is_the_inverse_of_p() -> None:
    text = markdown_starting("03_fusion", "#### Do the shares follow the rule?")
    assert "reliability is\n$\\mathbf P$." not in text
    assert "reliability is $\\mathbf P^{-1}$" in text


def test_00_the_innovation_is_e_as_in_notebook_01() -> None:
    text = markdown_starting("00_background_model", "### E · Choosing σ_j")
    assert "\\nu" not in text and "$e_j = y_j" in text


def test_00_the_readings_can_be_enough_and_the_ranges_are_refined_and_printed() -> None:
    text = markdown_starting("00_background_model", "#### E · Can an observer choose σ_j")
    assert "never needed" not in text and "can be enough" in text
    printed = printed_by("00_background_model", "choice.by_likelihood_per_run")
    picks = re.search(r"one run's pick ([-+]\d+) to ([-+]\d+) %, the NIS's choice ([-+]\d+) %",
                      printed)
    assert picks, printed
    low, high, nis = (int(value) for value in picks.groups())
    assert -10 < low and high < 10 and nis < -10     # "within a tenth", "more than a tenth"


def test_01_every_run_is_said_only_because_the_count_says_so() -> None:
    text = markdown_starting("01_vision_only", "### Answer to (a)")
    assert "almost every run" not in text and "every run" in text
    printed = printed_by("01_vision_only", "filtered MSE below the raw one in")
    runs = DEFAULT.mc_runs
    assert printed.count(f"below the raw one in {runs} of {runs} runs") == 2, printed


def test_01_the_nis_answer_names_the_noise_notebook_04_misjudges() -> None:
    text = markdown_starting("01_vision_only", "#### How sure is the filter")
    assert "misjudged $\\sigma_v$" not in text and "$\\sigma_p$" in text


def test_01_refers_to_notebook_00s_parts_by_their_headings() -> None:
    text = markdown_starting("01_vision_only", "### 5. In the nervous system")
    assert "(part 4)" not in text and "(Going further D)" in text
    heading = markdown_starting("00_background_model", "### D ·")
    assert "\\sigma_j^2\\Delta t" in heading


def test_01_the_model_of_motion_answer_says_what_the_review_found() -> None:
    text = markdown_starting("01_vision_only", "#### What does the model of motion buy?")
    assert "averages as hard" not in text
    for printed_in, code in (("noise parts", "smoother_noise"),
                             ("tuned on the truth", "fixed_gain.tune_fixed_gain")):
        assert printed_by("01_vision_only", code), printed_in
    assert "true path" in text and "fixed linear filter" in text


def test_02_the_late_difference_is_bounded_by_a_printed_fraction() -> None:
    text = markdown_starting("02_initial_covariance", "### Answer to (b)")
    assert "no longer differ measurably" not in text and "$10^{-5}$" in text
    assert "(below 1e-05)" in printed_by("02_initial_covariance", "late_difference")
