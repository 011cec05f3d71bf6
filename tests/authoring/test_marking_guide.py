"""The instructor's marking guide, built from the worked notebooks by ``make student``."""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

from lqe_helpers import checks
from lqe_helpers.authoring import marking_guide as mg
from lqe_helpers.authoring import task_cells as tc

ROOT = Path(__file__).resolve().parents[2]
KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
TASK = ("# Task: compute the fused MSE after the burn-in (cm²) with metrics.mse\n"
        "#       and print it.\nmse = metrics.mse(estimate, truth)\nprint(f'{mse:.3f}')")
CHECK = "checks.check_steady_state(forecast, coverage)"
ANSWER = ("#### Answer to (c): does fusion help?\n\n"
          "- Yes: the fused MSE is below vision's, every paired interval above zero.\n"
          "- Two equal senses act as one at σ/√2.")
FIGURE_TASK = "# Task: draw the sweep of σ_p.\nshow_figure(sweep(), 'MSE against σ_p')"


def guide_fixture(**metadata) -> nbformat.NotebookNode:
    figure = new_output("display_data", data={"image/png": "iVBORw0KGgo=",
                                              "text/plain": "MSE against σ_p, 0.3–100 cm"},
                        metadata={"image/png": {"alt": "MSE against σ_p, 0.3–100 cm"}})
    return new_notebook(
        cells=[
            new_markdown_cell("# 03 · Fixture"),
            new_code_cell("from lqe_helpers import checks", execution_count=1),
            new_markdown_cell("## The question (c) — 25 marks\n\nDoes fusion help?"),
            new_code_cell(TASK, metadata={"tags": ["solution"]}, execution_count=2,
                          outputs=[new_output("stream", name="stdout", text="0.351\n")]),
            new_code_cell(CHECK, execution_count=3, outputs=[new_output(
                "stream", name="stdout", text="✓ the MSE 0.351 cm² is right\n")]),
            new_markdown_cell(ANSWER, metadata={"tags": ["answer"]}),
            new_markdown_cell("## Going further (optional)\n\nMore."),
            new_code_cell(FIGURE_TASK, metadata={"tags": ["solution"]}, execution_count=4,
                          outputs=[figure, new_output("execute_result", execution_count=4,
                                                      data={"text/markdown": "| a | b |\n"
                                                                             "|---|---|\n"
                                                                             "| 1.5 | 0.42 |"})]),
            new_markdown_cell("#### Why?\nBecause the weights are 1/σ².",
                              metadata={"tags": ["answer"]}),
        ],
        metadata={"kernelspec": KERNELSPEC, "language_info": {"name": "python"},
                  "lqe": {"question": "c", "marks": 25, "core_minutes": 45, **metadata}},
    )


def write(notebook: nbformat.NotebookNode, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(notebook, path)
    return path


def test_the_tutorials_marks_are_in_one_place():
    assert mg.QUESTION_MARKS == {"a": 15, "b": 15, "c": 25, "d": 15, "e": 30}
    assert sum(mg.QUESTION_MARKS.values()) == 100


@pytest.mark.parametrize(("metadata", "name", "expected"), [
    ({"question": "c", "marks": 25}, "09_x.ipynb", ("c", 25)),
    ({}, "05_delay.ipynb", ("e", 30)),
    ({"question": "bonus", "marks": 0}, "06_b.ipynb", ("bonus", 0)),
    ({}, "00_background.ipynb", ("background", 0)),
])
def test_question_and_marks_from_metadata_or_the_fallback(metadata, name, expected):
    notebook = new_notebook(metadata={"lqe": metadata} if metadata else {})
    assert mg.question_and_marks(notebook, name) == expected


@pytest.mark.parametrize(("metadata", "message"), [
    ({"question": "c", "marks": 20}, "lqe.marks is 20 for question 'c', but the tutorial "
                                     "gives it 25"),
    ({"question": "bonus", "marks": 5}, "gives it 0"),
])
def test_marks_other_than_the_tutorials_are_refused(metadata, message):
    with pytest.raises(ValueError, match=message):
        mg.question_and_marks(new_notebook(metadata={"lqe": metadata}), "03_x.ipynb")
    with pytest.raises(ValueError, match="no question in its metadata"):
        mg.question_and_marks(new_notebook(), "x.ipynb")


def stated_numbers(text: str) -> set[float]:
    return {float(number) for number in re.findall(r"\d+(?:\.\d+)?(?:e[-+]?\d+)?", text)}


def test_the_tolerance_comes_from_the_check_itself():
    tolerance = mg.check_tolerance(CHECK)
    assert tolerance.startswith("relative") and checks.MSE_RTOL in stated_numbers(tolerance)
    assert mg.check_tolerance("checks.check_filter(my_filter)") == (
        f"relative {checks.FUNCTION_RTOL:g} (`checks.FUNCTION_RTOL`)")
    with pytest.raises(ValueError, match=r"check_nothing, which lqe_helpers\.checks does not"):
        mg.check_tolerance("checks.check_nothing(x)")
    with pytest.raises(ValueError, match=r"must call checks\.check_"):
        mg.check_tolerance("print(x)")


@pytest.mark.parametrize("name", sorted(name for name in dir(checks)
                                        if name.startswith("check_")))
def test_every_check_states_its_tolerance(name):
    assert "none stated" not in mg.check_tolerance(f"checks.{name}(x)")


def test_guide_of_a_notebook(tmp_path):
    source = write(guide_fixture(), tmp_path / "src" / "03_fixture.ipynb")
    path = mg.build_marking_guide(source.parent, tmp_path / "guide")
    assert path == tmp_path / "guide" / mg.GUIDE_NAME
    text = path.read_text("utf-8")
    assert "**For instructors only: do not hand out.**" in text
    assert "| (c) | 25 | `03_fixture.ipynb` | 45 min | 1 (1) | 2 |" in text
    assert "| **Total** | **25** |" in text
    core, further = text.split("### Going further (optional, no marks)")
    assert ("#### Task: compute the fused MSE after the burn-in (cm²) with metrics.mse "
            "and print it.") in core
    assert f"- **Check:** `{CHECK}`" in core
    assert f"- **Tolerance:** {mg.check_tolerance(CHECK)}\n" in core
    assert "- **The check printed:** ✓ the MSE 0.351 cm² is right" in core
    assert "```text\n0.351\n```" in core
    assert "#### Written answer: Answer to (c): does fusion help?" in core
    assert "> - Yes: the fused MSE is below vision's, every paired interval above zero." in core
    assert "#### Task: draw the sweep of σ_p." in further
    assert "- **Check:** none follows this task" in further
    assert "*Figure:* MSE against σ_p, 0.3–100 cm" in further
    assert "| 1.5 | 0.42 |" in further
    assert "> Because the weights are 1/σ²." in further
    assert "iVBORw0KGgo" not in text


def test_guide_is_the_same_every_time_and_the_command_line(tmp_path, capsys):
    source = write(guide_fixture(), tmp_path / "src" / "03_fixture.ipynb")
    out = tmp_path / "guide"
    assert mg.main(["--source", str(source.parent), "--out", str(out)]) == 0
    assert capsys.readouterr().out == f"{out / mg.GUIDE_NAME}\n"
    first = (out / mg.GUIDE_NAME).read_bytes()
    assert mg.main(["--source", str(source.parent), "--out", str(out)]) == 0
    assert (out / mg.GUIDE_NAME).read_bytes() == first
    assert mg.main(["--source", str(tmp_path / "missing"), "--out", str(out)]) == 1
    assert capsys.readouterr().err.startswith("error: source_dir must be an existing folder")


@pytest.mark.parametrize(("change", "message"), [
    (lambda nb: [cell.update(execution_count=None, outputs=[]) for cell in nb.cells
                 if cell.cell_type == "code"], "has not been executed"),
    (lambda nb: nb.cells[3].outputs.append(new_output("error", ename="KeyError", evalue="x",
                                                      traceback=[])),
     r"cell 3 \('# Task: compute.*saved an error \(KeyError: x\)"),
    (lambda nb: nb.cells[4].update(source="checks.check_everything(mse)"),
     "does not define"),
    (lambda nb: nb.metadata["lqe"].update(marks=30), "the tutorial gives it 25"),
    (lambda nb: nb.metadata.update(lqe=["c", 25]),  # issue 27: it said only AttributeError
     r"^03_fixture\.ipynb: its metadata 'lqe' must be a mapping, such as \{\"question\": "
     r"\"a\", \"marks\": 15, \"core_minutes\": 45\}, got list \['c', 25\]$"),
])
def test_a_notebook_that_cannot_give_a_guide_is_refused(tmp_path, change, message):
    notebook = guide_fixture()
    change(notebook)
    source = write(notebook, tmp_path / "src" / "03_fixture.ipynb")
    with pytest.raises(ValueError, match=message):
        mg.build_marking_guide(source.parent, tmp_path / "guide")
    assert not (tmp_path / "guide").exists()


def test_guide_of_the_packs_notebooks(tmp_path):
    text = mg.build_marking_guide(ROOT / "notebooks", tmp_path / "guide").read_text("utf-8")
    assert "| **Total** | **100** |" in text
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        notebook = nbformat.read(path, as_version=4)
        assert f"`{path.name}`" in text
        for cell in notebook.cells:
            tags = cell.metadata.get("tags", [])
            if tc.SOLUTION_TAG in tags:
                first = tc.task_instruction(cell.source)[0].removeprefix(tc.TASK_PREFIX).strip()
                assert f"#### Task: {first}" in text
            if tc.ANSWER_TAG in tags:
                heading = " ".join(line.lstrip("#").strip()
                                   for line in tc.answer_headings(cell.source))
                assert f"#### Written answer: {heading or '(no heading)'}" in text
