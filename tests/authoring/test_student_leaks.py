"""The student edition does not give the answers away.

For every notebook in ``notebooks/`` (the worked, executed notebooks) the student
edition (the run's one build, ``student_edition`` in tests/artefacts.py, as ``make
student`` builds it) is searched for two kinds of leak. "The student edition" is
everything in the student notebook: the source of every cell (markdown and code, the kept
``# Task:`` comments and check cells included) and any output (the build clears them, so
there should be none).

1. **A sentence of a worked answer.** The body of every cell tagged ``answer`` (its text
   below the headings the edition keeps on purpose) is cut into sentences: at blank
   lines, at list items and after ``.``, ``!`` or ``?`` followed by a space (not after
   an abbreviation such as "eq." or "e.g."). Markdown
   emphasis (``*``, `````), list bullets, case and runs of white space are ignored. A
   sentence of at least :data:`MIN_SENTENCE_WORDS` words that does not end in ``?`` (a
   question is not a conclusion) leaks if it appears anywhere in the student edition
   normalised the same way: for example a Summary or "What you will learn" cell that
   repeats the answer's conclusion.

2. **A result printed by a code cell.** Every number in the saved text outputs of
   every code cell but the explorers' (a cell tagged ``solution``, or a given cell that
   prints what a task computed, as the notebooks do so that a task need not print;
   printed text, and the plain-text, Markdown or HTML form of displayed results such as
   tables and figure descriptions; images are not text) is a *result* if it has at
   least three significant digits (:func:`significant_digits`: leading zeros never
   count, trailing zeros of a whole number without a decimal point do not count, so
   ``1000`` and ``0.05`` have one, ``1.26``, ``0.0421``, ``12.0`` and ``1974`` three or
   four) and its value is neither
   among the numbers of the question's text nor typed as a number literal in the code
   of a solution cell (such a number is an input the author chose, like an assumed
   σ̃_p = 13.5 cm, not a result the code computed; a literal in an untagged cell is
   not excused, since it stays in the student edition). **The question's text** is the
   tutorial question as the notebook quotes it: every markdown cell whose first line
   is a heading starting "The question" (``## The question (a) — 15 marks``). A result
   leaks if a number of the same value (``1.260`` is ``1.26``; the sign and thousands
   separators are ignored) with at least three significant digits appears anywhere in
   the student edition: a number typed into prose, an untagged cell's code, or a task
   comment.

Only the notebooks' saved outputs are read, so a notebook must have been executed
(``make notebooks``); one that was not fails here rather than pass for want of outputs.
The first tests run the detectors on small notebooks written to show that each can fail.
"""

from __future__ import annotations

import html
import io
import re
import tokenize
from decimal import Decimal
from pathlib import Path

import nbformat
import pytest
from artefacts import StudentEdition, StudentPack
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

from lqe_helpers.authoring import student_edition as se
from lqe_helpers.authoring import task_cells as tc

NOTEBOOK_DIR = Path(__file__).resolve().parents[2] / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("*.ipynb"))

#: A shorter "sentence" ("Yes.", "See Figure 2.") is not checked.
MIN_SENTENCE_WORDS = 5
#: Results need at least this many significant digits.
MIN_SIGNIFICANT_DIGITS = 3
#: First line of a markdown cell quoting the tutorial's question.
QUESTION_HEADING = re.compile(r"#{1,6}\s*the question\b", re.IGNORECASE)
#: A number: optional sign, digits with optional thousands separators, decimals, exponent.
NUMBER = re.compile(
    r"(?<![\w.])[-−+]?(?:\d{1,3}(?:,\d{3})+|\d+)(?:\.\d+)?(?:[eE][-+−]?\d+)?(?![\w])"
    r"|(?<![\w.])[-−+]?\.\d+(?![\w])")
#: A sentence does not end after these.
ABBREVIATION = re.compile(r"(?:^|\s|\()(?:eqs?|e\.g|i\.e|cf|figs?|vs|approx|etc|no)\.$")
#: Where the kept text of a displayed result lives, best first.
TEXT_MIMETYPES = ("text/markdown", "text/html", "text/plain")


def tags(cell: nbformat.NotebookNode) -> list[str]:
    return list(cell.get("metadata", {}).get("tags", []))


# ------------------------------------------------------------------------ numbers


def significant_digits(token: str) -> int:
    """Significant digits of a number as written (see the module docstring)."""
    mantissa = re.split(r"[eE]", token.replace(",", "").lstrip("-−+"))[0]
    if "." in mantissa:
        return len(mantissa.replace(".", "").lstrip("0"))
    return len(mantissa.lstrip("0").rstrip("0"))


def number_value(token: str) -> Decimal:
    """The value of a number as written, without its sign (``1.260`` → ``1.26``)."""
    return Decimal(token.replace(",", "").replace("−", "-").lstrip("-+")).normalize()


def numbers(text: str) -> list[str]:
    return NUMBER.findall(text)


def results(text: str) -> set[Decimal]:
    """Values of the numbers in ``text`` with at least three significant digits."""
    return {number_value(token) for token in numbers(text)
            if significant_digits(token) >= MIN_SIGNIFICANT_DIGITS}


def output_text(output: nbformat.NotebookNode) -> str:
    """The text an output shows: printed text, or a displayed result's best text form."""
    if output.output_type == "stream":
        return output.text
    if output.output_type == "error":
        return f"{output.ename}: {output.evalue}"
    data = output.get("data", {})
    for mimetype in TEXT_MIMETYPES:
        if mimetype in data:
            text = data[mimetype]
            text = "".join(text) if isinstance(text, list) else text
            if mimetype == "text/html":
                text = html.unescape(re.sub(r"<[^>]*>", " ", text))
            return text
    return ""


def question_text(notebook: nbformat.NotebookNode) -> str:
    """The tutorial question as the notebook quotes it (see the module docstring)."""
    return "\n".join(cell.source for cell in notebook.cells
                     if cell.cell_type == "markdown"
                     and QUESTION_HEADING.match(cell.source.lstrip()))


def code_literals(notebook: nbformat.NotebookNode) -> set[Decimal]:
    """Values of the number literals typed in solution cells' code (inputs, not results)."""
    found = set()
    for cell in notebook.cells:
        if tc.SOLUTION_TAG not in tags(cell):
            continue
        try:
            tokens = list(tokenize.generate_tokens(io.StringIO(cell.source + "\n").readline))
        except (tokenize.TokenError, SyntaxError):  # IPython syntax: no literals taken
            continue
        found |= {number_value(token.string.replace("_", "")) for token in tokens
                  if token.type == tokenize.NUMBER and NUMBER.fullmatch(token.string)}
    return found


def printed_results(notebook: nbformat.NotebookNode) -> dict[Decimal, str]:
    """Results printed by code cells (see the module docstring): value → where printed."""
    allowed = {number_value(token) for token in numbers(question_text(notebook))}
    allowed |= code_literals(notebook)
    found: dict[Decimal, str] = {}
    for index, cell in enumerate(notebook.cells):
        if cell.cell_type != "code" or tc.EXPLORER_TAG in tags(cell):
            continue
        for output in cell.get("outputs", []):
            for value in results(output_text(output)) - allowed:
                found.setdefault(value, tc.cell_place("source", index, cell))
    return found


# ---------------------------------------------------------------------- sentences


def normalise(text: str) -> str:
    """Lower case, without markdown emphasis, list bullets or runs of white space."""
    text = re.sub(r"(?m)^\s*(?:[-*+]|\d+\.)\s+", " ", text)
    text = re.sub(r"[*`]", "", text)
    return " ".join(text.lower().split())


def sentences(markdown: str) -> list[str]:
    """The sentences of a markdown text, normalised (see the module docstring)."""
    pieces = re.split(r"\n\s*\n|\n(?=\s*(?:[-*+]|\d+\.)\s)", markdown)
    found = []
    for piece in pieces:
        joined: list[str] = []
        for part in re.split(r"(?<=[.!?])\s+", normalise(piece)):
            if joined and ABBREVIATION.search(joined[-1]):
                joined[-1] += " " + part
            else:
                joined.append(part)
        found += [sentence for sentence in joined
                  if len(sentence.split()) >= MIN_SENTENCE_WORDS and not sentence.endswith("?")]
    return found


def answer_sentences(notebook: nbformat.NotebookNode) -> dict[str, str]:
    """Sentences of the worked answers: sentence → the answer cell it comes from."""
    found: dict[str, str] = {}
    for index, cell in enumerate(notebook.cells):
        if tc.ANSWER_TAG in tags(cell):
            headings = tc.answer_headings(cell.source)
            body = "\n".join(line for line in cell.source.splitlines()
                             if line.rstrip() not in headings)
            for sentence in sentences(body):
                found.setdefault(sentence, tc.cell_place("source", index, cell))
    return found


# -------------------------------------------------------------------------- leaks


def student_cells(student: nbformat.NotebookNode) -> list[tuple[str, str]]:
    """(place, text) of every cell of the student edition: its source and its outputs."""
    return [(tc.cell_place("student", index, cell),
             "\n".join([cell.source, *(output_text(o) for o in cell.get("outputs", []))]))
            for index, cell in enumerate(student.cells)]


def find_leaks(source: nbformat.NotebookNode, student: nbformat.NotebookNode) -> list[str]:
    """Every answer sentence and printed result of ``source`` found in ``student``."""
    leaks = []
    sentences_of = answer_sentences(source)
    printed = printed_results(source)
    for place, text in student_cells(student):
        flat = normalise(text)
        for sentence, origin in sentences_of.items():
            if sentence in flat:
                leaks.append(f"{place} repeats a sentence of the answer in {origin}: "
                             f"{sentence!r}")
        for value in sorted(results(text) & set(printed)):
            leaks.append(f"{place} contains {value}, printed by {printed[value]}")
    return leaks


def printed_before_the_tasks(notebook: nbformat.NotebookNode) -> list[str]:
    """Results printed later that a code cell before the first task already printed.

    The student runs the notebook from the top, so a given cell above the first task that
    prints a number a task or its given cells print later (a table of constants showing
    the σ_j a task derives, say) gives it away as surely as prose would. Only the core
    path's results count (a Going further task may print a given fact, such as the path's
    peak acceleration, beside its own numbers), and only the cells before the first task
    are held to this (later cells may repeat earlier results). The question's numbers and
    typed inputs are excepted as in :func:`printed_results`.
    """
    allowed = {number_value(token) for token in numbers(question_text(notebook))}
    allowed |= code_literals(notebook)
    first_task = next((index for index, cell in enumerate(notebook.cells)
                       if tc.SOLUTION_TAG in tags(cell)), len(notebook.cells))
    core_end = next((index for index, cell in enumerate(notebook.cells)
                     if cell.cell_type == "markdown"
                     and re.search(r"^##\s+Going further", cell.source, re.M | re.I)),
                    len(notebook.cells))
    early: dict[Decimal, str] = {}
    leaks = []
    for index, cell in enumerate(notebook.cells[:core_end]):
        if cell.cell_type != "code" or tc.EXPLORER_TAG in tags(cell):
            continue
        values = set()
        for output in cell.get("outputs", []):
            values |= results(output_text(output)) - allowed
        if index < first_task:
            for value in values:
                early.setdefault(value, tc.cell_place("source", index, cell))
        else:
            leaks += [f"{early[value]} prints {value} before the tasks; "
                      f"{tc.cell_place('source', index, cell)} computes it"
                      for value in sorted(values & set(early))]
            for value in values & set(early):
                del early[value]
    return leaks


def set_up_leaks(paths: list[Path]) -> list[str]:
    """Results a notebook prints before its first task that another notebook's core tasks
    compute (issue 23 §5: 01's set-up printed the σ_j that 00's Task 3 derives).

    A student may open any notebook first, so its set-up cells (code cells above its
    first task) must not print a core-path result of another notebook: a number that
    notebook's code cells print from its first task to its "## Going further". The
    question's numbers and typed inputs of both notebooks are excepted.
    """
    def split(notebook: nbformat.NotebookNode) -> tuple[dict, dict, set]:
        allowed = {number_value(token) for token in numbers(question_text(notebook))}
        allowed |= code_literals(notebook)
        first_task = next((index for index, cell in enumerate(notebook.cells)
                           if tc.SOLUTION_TAG in tags(cell)), len(notebook.cells))
        core_end = next((index for index, cell in enumerate(notebook.cells)
                         if cell.cell_type == "markdown"
                         and re.search(r"^##\s+Going further", cell.source, re.M | re.I)),
                        len(notebook.cells))
        early: dict[Decimal, str] = {}
        core: dict[Decimal, str] = {}
        for index, cell in enumerate(notebook.cells[:core_end]):
            if cell.cell_type != "code" or tc.EXPLORER_TAG in tags(cell):
                continue
            for output in cell.get("outputs", []):
                for value in results(output_text(output)) - allowed:
                    (early if index < first_task else core).setdefault(
                        value, tc.cell_place("source", index, cell))
        return early, core, allowed

    parts = {path.stem: split(nbformat.read(path, as_version=4)) for path in paths}
    leaks = []
    for name, (early, _, _) in parts.items():
        for other, (_, core, allowed) in parts.items():
            if other != name:
                leaks += [f"{name} {early[value]} prints {value} before its tasks; "
                          f"{other} {core[value]} computes it"
                          for value in sorted(set(early) & set(core) - allowed)]
    return leaks


def test_a_set_up_printing_another_notebooks_result_is_found(tmp_path):
    """01's set-up as it was, beside 00: it printed 00's Task 3 σ_j."""
    stub = leak_fixture()
    stub.cells[2].outputs[0].text = "σ_j = 1,396 cm/s³\n"
    setup = new_code_cell("print(sigma_j)", execution_count=1, outputs=[
        new_output("stream", name="stdout", text="jerk noise behind Q: σ_j = 1396 cm/s³\n")])
    later = leak_fixture()
    later.cells.insert(1, setup)
    nbformat.write(stub, tmp_path / "00_fixture.ipynb")
    nbformat.write(later, tmp_path / "01_fixture.ipynb")
    leaks = set_up_leaks([tmp_path / "00_fixture.ipynb", tmp_path / "01_fixture.ipynb"])
    assert [leak.split(";")[0] for leak in leaks] == [
        f"01_fixture {tc.cell_place('source', 1, setup)} prints 1396 before its tasks"]


def test_no_set_up_prints_a_result_another_notebooks_core_tasks_compute():
    leaks = set_up_leaks(NOTEBOOKS)
    assert not leaks, "\n".join(leaks)


def student_of(notebook: nbformat.NotebookNode, name: str) -> nbformat.NotebookNode:
    return nbformat.reads(se.student_edition(notebook, name), as_version=4)


# --------------------------------------------------------- the detectors can fail

SOLUTION = ("# Task: compute the MSE of the filter at σ_v = 1.5 cm over 1000 samples.\n"
            "mse = 1.2594\nprint(f'MSE = {mse:.3f} cm², ratio 6.21, n = 1000, x = 0.05')")
ANSWER = ("#### Answer to (a): does filtering help?\n\n"
          "- *Yes:* the filtered estimate is **six times** closer to the truth than vision.\n"
          "- Does it always help? Short.\n\nThe band holds 95 % of the path. Good.")
QUESTION = "## The question (a) — 15 marks\n\nAt σ_v = 1.5 cm, is the MSE below 6.21 cm²?"


def leak_fixture(*extra: nbformat.NotebookNode) -> nbformat.NotebookNode:
    solution = new_code_cell(SOLUTION, metadata={"tags": ["solution"]}, execution_count=1,
                             outputs=[new_output("stream", name="stdout",
                                                 text="MSE = 1.259 cm², ratio 6.21, "
                                                      "n = 1000, x = 0.05\n")])
    return new_notebook(cells=[
        new_markdown_cell("# Fixture\n\nHow well does the filter do?"),
        new_markdown_cell(QUESTION), solution,
        new_markdown_cell(ANSWER, metadata={"tags": ["answer"]}), *extra])


@pytest.mark.parametrize(("token", "digits"), [
    ("1000", 1), ("0.05", 1), ("1.26", 3), ("0.0421", 3), ("12.0", 3), ("1974", 4),
    ("1,974", 4), ("0.100", 3), ("-3.13", 3), ("1.5e+05", 2), ("2.04e-3", 3), ("0", 0),
    ("100.", 3), (".125", 3)])
def test_significant_digits(token, digits):
    assert significant_digits(token) == digits


def test_numbers_are_found_as_written_and_compared_by_value():
    assert numbers("P0 = diag(1e5), x1 = 3, K = [0.177, 1.73] at 1,396 cm/s³; v1.2.3") == [
        "1e5", "3", "0.177", "1.73", "1,396"]
    assert results("1.260 and −1.26 and 1,396.0 and 1.5") == {Decimal("1.26"),
                                                             Decimal("1396")}


def test_sentences_ignore_markdown_questions_and_short_ones():
    assert sentences(ANSWER.split("\n\n", 1)[1]) == [
        "yes: the filtered estimate is six times closer to the truth than vision.",
        "the band holds 95 % of the path."]


def test_a_clean_student_edition_has_no_leak():
    notebook = leak_fixture(new_markdown_cell("## Summary\n\nDoes filtering help, and why?"))
    assert printed_results(notebook) == {Decimal("1.259"): tc.cell_place("source", 2,
                                                                         notebook.cells[2])}
    assert find_leaks(notebook, student_of(notebook, "clean")) == []


@pytest.mark.parametrize(("cell", "expected"), [
    (new_markdown_cell("## Summary\n\n* Yes: the filtered estimate is six times closer to\n"
                       "  the truth than **vision**."), "repeats a sentence of the answer"),
    (new_markdown_cell("What you will learn: the MSE comes out at 1.2590 cm²."),
     "contains 1.259, printed by source, cell 2"),
    (new_code_cell("expected = 1.259  # untagged code gives it away too"), "contains 1.259"),
])
def test_a_leak_is_found_and_placed(cell, expected):
    notebook = leak_fixture(cell)
    leaks = find_leaks(notebook, student_of(notebook, "leaky"))
    assert len(leaks) == 1
    assert leaks[0].startswith("student, cell 5 (")
    assert expected in leaks[0]


def test_a_result_a_given_cell_prints_after_the_task_leaks_if_typed_before_it():
    """Bookkeeping moved out of a task (a given cell printing a ratio of the task's MSEs)
    still prints a result; a number typed before the task may not give it away."""
    given = new_code_cell("print(f'{100 * 0.3831 / 0.6442:.1f} %')", execution_count=2,
                          outputs=[new_output("stream", name="stdout", text="59.5 %\n")])
    notebook = leak_fixture(given)
    notebook.cells.insert(1, new_markdown_cell("Filtering keeps 59.5 % of the error."))
    leaks = find_leaks(notebook, student_of(notebook, "given"))
    assert [leak.split(" contains ")[1].split(",")[0] for leak in leaks] == ["59.5"]


def test_a_result_a_given_cell_prints_for_a_task_leaks_too():
    """A task need not print: a given cell after its check prints what it computed."""
    given = new_code_cell("print(f'mean MSE {mse:.4f} cm²')", execution_count=2,
                          outputs=[new_output("stream", name="stdout",
                                              text="mean MSE 2.3456 cm²\n")])
    notebook = leak_fixture(given, new_markdown_cell("## Summary\n\nWhy is it 2.3456 cm²?"))
    leaks = find_leaks(notebook, student_of(notebook, "given"))
    assert leaks == [f"{tc.cell_place('student', 6, notebook.cells[5])} contains 2.3456, "
                     f"printed by {tc.cell_place('source', 4, notebook.cells[4])}"]


def test_a_number_in_a_task_comment_leaks_and_one_from_the_question_does_not():
    notebook = leak_fixture(new_code_cell(
        "# Task: check that your MSE is 1.259 cm² and below 6.21 cm².\nx = 1",
        metadata={"tags": ["solution"]}))
    leaks = find_leaks(notebook, student_of(notebook, "task"))
    assert leaks == [f"{tc.cell_place('student', 5, notebook.cells[4])} contains 1.259, "
                     f"printed by {tc.cell_place('source', 2, notebook.cells[2])}"]


# ------------------------------------------------------------- the pack's notebooks


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_the_student_edition_gives_no_answer_away(student_edition: StudentEdition, path):
    source = nbformat.read(path, as_version=4)
    assert any(cell.get("execution_count") for cell in source.cells
               if cell.cell_type == "code"), (
        f"{path.name} has not been executed: its printed results are unknown "
        f"(run `make notebooks`)")
    student = nbformat.read(student_edition.folder / path.name, as_version=4)
    leaks = find_leaks(source, student)
    assert not leaks, f"{len(leaks)} leak(s) in the student edition:\n" + "\n".join(leaks)


def test_a_given_cell_that_prints_a_tasks_result_before_it_is_found():
    table = new_code_cell("print('constants: MSE 1.259 cm²')", execution_count=1,
                          outputs=[new_output("stream", name="stdout",
                                              text="constants: MSE 1.259 cm²\n")])
    notebook = leak_fixture()
    notebook.cells.insert(1, table)
    assert printed_before_the_tasks(notebook) == [
        f"{tc.cell_place('source', 1, table)} prints 1.259 before the tasks; "
        f"{tc.cell_place('source', 3, notebook.cells[3])} computes it"]
    assert printed_before_the_tasks(leak_fixture()) == []


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_no_cell_prints_a_tasks_result_before_the_task(path):
    leaks = printed_before_the_tasks(nbformat.read(path, as_version=4))
    assert not leaks, "\n".join(leaks)


def test_abbreviations_do_not_end_a_sentence():
    assert sentences("The last line of eq. (5) updates P, e.g. after the gain. Then it ends.") == [
        "the last line of eq. (5) updates p, e.g. after the gain."]


def test_a_number_typed_in_code_is_an_input_not_a_result():
    notebook = leak_fixture(new_markdown_cell("Assume σ̃_p = 13.5 cm and 1.259 cm²."))
    notebook.cells[2].source += "\nassumed = 13.5"
    notebook.cells[2].outputs[0].text += "assumed 13.5 cm\n"
    leaks = find_leaks(notebook, student_of(notebook, "inputs"))
    assert [leak.split(" contains ")[1].split(",")[0] for leak in leaks] == ["1.259"]


# ------------------------------------------------------------- the pack's own texts


def texts_leaks(texts: dict[str, str], sources: list[Path]) -> list[str]:
    """Where ``texts`` (name → Markdown) repeat a result or an answer of any notebook.

    The pack's README and STUDENT-PACK.md come before every task, so any result a
    code cell prints (:func:`printed_results`, excepting the question's own numbers
    and typed inputs) or any sentence of a worked answer leaks there.
    """
    found = []
    for path in sources:
        notebook = nbformat.read(path, as_version=4)
        printed = printed_results(notebook)
        answers = answer_sentences(notebook)
        for name, text in texts.items():
            for value in sorted(results(text) & set(printed)):
                found.append(f"{name} contains {value}, printed by {path.stem}: "
                             f"{printed[value]}")
            flat = normalise(text)
            found += [f"{name} repeats a sentence of {path.stem}'s answer {where}: "
                      f"{sentence!r}" for sentence, where in answers.items()
                      if sentence in flat]
    return found


def test_a_result_in_the_packs_readme_is_found(tmp_path):
    notebook = leak_fixture()
    source = tmp_path / "01_fixture.ipynb"
    nbformat.write(notebook, source)
    leaks = texts_leaks({"README.md": "Filtering brings the MSE to 1.259 cm².",
                         "notes": "Yes: the filtered estimate is six times closer to the "
                                  "truth than vision."}, [source])
    assert [leak.split(",")[0] for leak in leaks] == [
        "README.md contains 1.259", "notes repeats a sentence of 01_fixture's answer source"]


@pytest.mark.slow
def test_the_packs_own_texts_give_no_answer_away(student_pack: StudentPack):
    texts = {name: (student_pack.folder / name).read_text("utf-8")
             for name in ("README.md", "STUDENT-PACK.md")}
    leaks = texts_leaks(texts, NOTEBOOKS)
    assert not leaks, "\n".join(leaks)
