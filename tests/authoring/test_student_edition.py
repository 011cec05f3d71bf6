"""The student edition: solutions become stubs, answers become prompts, explorers stay.

Unit tests use small notebooks written into tmp_path. The same checks then run on
every notebook in ``notebooks/``, on the run's one student edition and filled edition
(``student_edition``, ``filled_edition``: tests/artefacts.py): each student notebook is
executed once per test run (up to its first stub, then its explorer cells; and its
explorers again in a fresh kernel after the first code cell only; this file's tests run
in one pytest-xdist worker, which keeps the run for the two tests of a notebook), and so
is each filled notebook. A few tests feed the checks a broken notebook, to show that they
can fail. Tests that execute a notebook are marked ``kernel``.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import nbformat
import pytest
from artefacts import FilledEdition, RunError, StudentEdition, filled_core, run_notebook
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

from lqe_helpers.authoring import errors, manifest
from lqe_helpers.authoring import student_edition as se
from lqe_helpers.authoring import student_pack as sp
from lqe_helpers.authoring import task_cells as tc

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"
REAL = sorted(path.name for path in NOTEBOOKS.glob("*.ipynb"))
KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}

SETUP = "import numpy as np\nimport matplotlib.pyplot as plt"
SOLUTION = (
    "# Task: compute the mean squared error of a 10 cm sine sampled\n"
    "#       every 0.01 s and print it in cm².\n"
    "times_secret = np.arange(0, 1, 0.01)\n"
    "error_secret = 10 * np.sin(2 * np.pi * times_secret)\n"
    "print(f'MSE = {np.mean(error_secret ** 2):.1f} cm²')"
)
SECOND_SOLUTION = "# Task: plot the error.\nplt.plot(times_secret, error_secret)\nplt.show()"
ANSWER = ("### Answer to (a)\n\n"
          "The mean squared error is half the squared amplitude: a fact about marmalade sines.")
EXPLORER = (
    "from lqe_helpers.explorers import Explorer, float_slider\n\n\n"
    "def draw(figure, *, amplitude):\n"
    "    figure.clear()\n"
    "    figure.add_subplot().plot([0, 1], [0, amplitude], label='line')\n\n\n"
    "Explorer('A line', {'amplitude': float_slider('A (cm)', 1.0, 0.0, 2.0, 0.1)}, draw)"
)


def fixture_notebook(*, with_solutions: bool = True) -> nbformat.NotebookNode:
    """A small executed-looking notebook following the tag convention."""
    solution = new_code_cell(SOLUTION, metadata={"tags": ["solution"]}, execution_count=2,
                             outputs=[new_output("stream", name="stdout", text="MSE = 50.0 cm²\n")])
    second = new_code_cell(SECOND_SOLUTION, metadata={"tags": ["solution"]})
    if not with_solutions:  # nothing marked, and nothing that looks like a task either
        solution.metadata, second.metadata = {}, {}
        for cell in (solution, second):
            cell.source = cell.source.replace("# Task:", "# Worked example:")
    notebook = new_notebook(
        cells=[
            new_markdown_cell("# A fixture notebook\n\nWhat you will learn: nothing much."),
            new_code_cell(SETUP, execution_count=1),
            new_markdown_cell("## The question\n\nHow large is the error?"),
            solution,
            second,
            new_markdown_cell(ANSWER, metadata={"tags": ["answer"]}),
            new_code_cell(EXPLORER, metadata={"tags": ["explorer", "nbval-ignore-output"]}),
        ],
        metadata={"kernelspec": KERNELSPEC, "language_info": {"name": "python"}},
    )
    notebook.metadata["widgets"] = {"application/vnd.jupyter.widget-state+json": {"state": {}}}
    return notebook


def write(notebook: nbformat.NotebookNode, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(notebook, path)
    return path


def tags(cell: nbformat.NotebookNode) -> list[str]:
    return list(cell.get("metadata", {}).get("tags", []))


def is_marked(cell: nbformat.NotebookNode) -> bool:
    return bool({tc.SOLUTION_TAG, tc.ANSWER_TAG} & set(tags(cell)))


def surviving_solution_lines(source: nbformat.NotebookNode,
                             student: nbformat.NotebookNode) -> set[str]:
    """Lines unique to marked cells of ``source`` found in ``student``.

    The parts the student edition keeps on purpose are left out: a solution's task
    comment and function signatures (and docstrings), and an answer's headings.
    """
    marked, other = set(), set()
    for cell in source.cells:
        lines = cell.source.splitlines()
        if tc.SOLUTION_TAG in tags(cell):  # the stub keeps the task and def signatures
            kept = set(tc.stub_source(cell.source).splitlines())
            lines = [line for line in lines if line not in kept]
        elif tc.ANSWER_TAG in tags(cell):
            lines = [line for line in lines if line not in tc.answer_headings(cell.source)]
        (marked if is_marked(cell) else other).update(
            line.strip() for line in lines if line.strip())
    student_lines = {line.strip() for cell in student.cells for line in cell.source.splitlines()}
    return (marked - other) & student_lines


def shingles(text: str, size: int = 8) -> set[tuple[str, ...]]:
    """Every run of ``size`` consecutive words of ``text``."""
    words = text.split()
    return {tuple(words[i:i + size]) for i in range(len(words) - size + 1)}


def surviving_answer_text(source: nbformat.NotebookNode,
                          student: nbformat.NotebookNode) -> set[str]:
    """Runs of eight words of an answer body (and nowhere else in ``source``) in ``student``."""
    answers, other = set(), set()
    for cell in source.cells:
        if tc.ANSWER_TAG in tags(cell):
            headings = tc.answer_headings(cell.source)
            answers |= shingles("\n".join(line for line in cell.source.splitlines()
                                          if line not in headings))
        else:
            other |= shingles(cell.source)
    student_text = shingles("\n".join(cell.source for cell in student.cells))
    return {" ".join(run) for run in (answers - other) & student_text}


def assert_nothing_marked_survives(source: nbformat.NotebookNode,
                                   student: nbformat.NotebookNode) -> None:
    """No solution line, no answer text, no output and no widget state in ``student``."""
    assert surviving_solution_lines(source, student) == set()
    assert surviving_answer_text(source, student) == set()
    for cell in student.cells:
        assert cell.get("outputs", []) == []
        assert cell.get("execution_count") is None
        assert "attachments" not in cell
    assert "widgets" not in student.metadata
    assert sum(tc.TASK_TAG in tags(cell) for cell in student.cells) == se.count_solutions(source)
    answers = sum(tc.ANSWER_TAG in tags(cell) for cell in source.cells)
    assert sum(tc.ANSWER_PROMPT_TAG in tags(cell) for cell in student.cells) == answers
    assert not any(is_marked(cell) for cell in student.cells)


# ---------------------------------------------------------------- unit tests


def test_task_instruction_is_the_leading_comment_block():
    assert tc.task_instruction(SOLUTION) == SOLUTION.splitlines()[:2]
    assert tc.task_instruction("# Task: one line\nx = 1\n# later comment") == ["# Task: one line"]


@pytest.mark.parametrize("source", ["x = 1", "", "# Note: not a task\nx = 1", "\n# Task: late"])
def test_task_instruction_rejects_a_cell_without_task(source):
    with pytest.raises(ValueError, match="# Task:"):
        tc.task_instruction(source)


def test_stub_is_task_then_raise():
    stub = tc.stub_source(SOLUTION)
    assert stub.splitlines() == [*SOLUTION.splitlines()[:2],
                                 f'raise NotImplementedError("{tc.STUB_MESSAGE}")']
    with pytest.raises(NotImplementedError, match="task described above"):
        exec(compile(stub, "<stub>", "exec"), {})


RAISE = f'raise NotImplementedError("{tc.STUB_MESSAGE}")'
FUNCTION_TASK = '''# Task: write my_filter(y, A, C, Q, R, z0, P0) -> estimates (n, k): eq. (5).
#       y has shape (k, m).
@staticmethod
def my_filter(y: "np.ndarray", A, C, Q, R,
              z0=(0.0, 0.0), P0={"a": 1}, key=lambda v: v[0]) -> dict[str, int]:
    """Tutorial eq. (5), one line per line.

    Returns the estimates, shape (n, k).
    """
    # Gain first: the secret order.
    def inner_secret(x):
        return x
    return inner_secret(y @ A)


async def fetch(x): return x * 2  # one-liner


def helper(a):
    \'\'\'Doc.\'\'\'; return a


estimates = my_filter(1, 2, 3, 4, 5)  # the worked call
'''


def test_stub_keeps_signatures_and_docstrings_and_raises_for_the_rest():
    stub = tc.stub_source(FUNCTION_TASK)
    assert stub.splitlines() == [
        *FUNCTION_TASK.splitlines()[:2],
        "@staticmethod",
        'def my_filter(y: "np.ndarray", A, C, Q, R,',
        '              z0=(0.0, 0.0), P0={"a": 1}, key=lambda v: v[0]) -> dict[str, int]:',
        '    """Tutorial eq. (5), one line per line.',
        "",
        "    Returns the estimates, shape (n, k).",
        '    """',
        f"    {RAISE}",
        "", "",
        "async def fetch(x):",
        f"    {RAISE}",
        "", "",
        "def helper(a):",
        "    \'\'\'Doc.\'\'\'",
        f"    {RAISE}",
        "", "",
        RAISE,
    ]
    for secret in ("secret", "inner", "worked call", "return", "x * 2", "estimates ="):
        assert secret not in stub.split("# Task:")[-1].split("\n", 2)[-1]


def test_a_cell_of_functions_only_runs_and_its_functions_say_not_written():
    source = "# Task: write twice(x) -> 2 x.\ndef twice(x):\n    # double it\n    return 2 * x\n"
    stub = tc.stub_source(source)
    assert stub == f"# Task: write twice(x) -> 2 x.\ndef twice(x):\n    {RAISE}"
    namespace: dict = {}
    exec(compile(stub, "<stub>", "exec"), namespace)  # defining it raises nothing
    with pytest.raises(NotImplementedError, match="task described above"):
        namespace["twice"](1)


@pytest.mark.parametrize("code", ["%timeit x = 1", "x = (", "if True:\n    def f():\n  pass"])
def test_unparsable_or_magic_code_is_stubbed_whole(code):
    assert tc.stub_source(f"# Task: do it.\n{code}") == f"# Task: do it.\n{RAISE}"


def test_allowed_tags_are_defined_once():
    assert tc.ALLOWED_TAGS == {"solution", "answer", "explorer", "nbval-ignore-output"}
    assert {tc.SOLUTION_TAG, tc.ANSWER_TAG, tc.EXPLORER_TAG,
            tc.IGNORE_OUTPUT_TAG} == tc.ALLOWED_TAGS


@pytest.mark.parametrize(
    ("index", "cell", "message"),
    [
        (3, new_code_cell(SOLUTION, metadata={"tags": ["Solution"]}),
         "unknown tag 'Solution' (did you mean 'solution'?)"),
        (3, new_code_cell(SOLUTION, metadata={"tags": ["soluton"]}),
         "unknown tag 'soluton' (did you mean 'solution'?)"),
        (5, new_markdown_cell(ANSWER, metadata={"tags": ["answers"]}),
         "unknown tag 'answers' (did you mean 'answer'?)"),
        (5, new_markdown_cell(ANSWER, metadata={"tags": ["answer", "remove-me"]}),
         "unknown tag 'remove-me'; the allowed tags are answer, explorer, "
         "nbval-ignore-output, solution"),
        (3, new_code_cell(SOLUTION), "holds a task instruction ('# Task:' comment, line 1) "
         "but is not tagged 'solution'"),
        (3, new_code_cell("  #task : lower case and spaced\nx = 1"), "line 1) but is not tagged"),
        # Issue 27: a '# Task:' after an import line (or any code) shipped its worked code.
        (3, new_code_cell("import numpy as np\n" + SOLUTION), "('# Task:' comment, line 2) but "
         "is not tagged 'solution'"),
        (3, new_code_cell("x = 1\n\n## task: after code\ny = x"), "line 3) but is not tagged"),
        (6, new_code_cell(EXPLORER, metadata={"tags": ["explorer"]}),
         "must also be tagged 'nbval-ignore-output'"),
        (2, new_markdown_cell("text", metadata={"tags": ["explorer", "nbval-ignore-output"]}),
         "is for code cells"),
    ],
)
def test_unknown_tags_and_untagged_tasks_are_refused_with_the_cell_named(tmp_path, index, cell,
                                                                         message):
    notebook = fixture_notebook()
    notebook.cells[index] = cell
    first_line = cell.source.strip().splitlines()[0][:60]
    with pytest.raises(ValueError) as error:
        se.student_edition(notebook, "03_misspelt")
    assert message in str(error.value)
    assert str(error.value).startswith(f"03_misspelt, cell {index} ({first_line!r}): ")
    source = write(notebook, tmp_path / "src" / "03_misspelt.ipynb")
    assert se.main(["--source", str(source.parent), "--out", str(tmp_path / "out")]) == 1
    assert not (tmp_path / "out").exists(), "a refused build writes nothing"


def test_the_pack_metadata_is_kept():
    notebook = fixture_notebook()
    notebook.metadata["lqe"] = {"question": "a", "marks": 15, "core_minutes": 45}
    student = nbformat.reads(se.student_edition(notebook, "f"), as_version=4)
    assert student.metadata["lqe"] == {"question": "a", "marks": 15, "core_minutes": 45}
    assert set(student.metadata) == {"kernelspec", "language_info", "lqe"}


@pytest.mark.parametrize(
    ("source", "prompt"),
    [
        ("Plain answer.", [tc.ANSWER_PROMPT]),
        ("## The answers\n\n### (a)\n**1.** Yes.\n# not a heading any more",
         ["## The answers", "### (a)", tc.ANSWER_PROMPT]),
        ("\n## Late heading\nText", ["## Late heading", tc.ANSWER_PROMPT]),
        ("Text first\n## Heading after text", [tc.ANSWER_PROMPT]),
    ],
)
def test_answer_prompt_keeps_only_the_leading_headings(source, prompt):
    assert tc.prompt_source(source) == "\n\n".join(prompt)


def test_student_edition_of_fixture(tmp_path):
    source = write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    [written] = se.build_student_edition(source.parent, tmp_path / "out")
    assert written == tmp_path / "out" / "01_fixture.ipynb"
    student = nbformat.read(written, as_version=4)
    nbformat.validate(student)
    original = fixture_notebook()

    # The note is inserted after the title; every other cell keeps its place.
    assert student.cells[1].source == se.STUDENT_NOTE
    del student.cells[1]
    assert len(student.cells) == len(original.cells)
    by_tag = {tuple(tags(cell)): cell for cell in student.cells}

    stubs = [cell for cell in student.cells if tc.TASK_TAG in tags(cell)]
    assert [cell.source for cell in stubs] == [tc.stub_source(SOLUTION),
                                               tc.stub_source(SECOND_SOLUTION)]
    assert by_tag[(tc.ANSWER_PROMPT_TAG,)].source == f"### Answer to (a)\n\n{tc.ANSWER_PROMPT}"
    assert by_tag[("explorer", "nbval-ignore-output")].source == EXPLORER
    for kept, before in zip(student.cells, original.cells, strict=True):
        if not is_marked(before):
            assert kept.source == before.source
            assert tags(kept) == tags(before)
    assert student.metadata["kernelspec"] == KERNELSPEC
    assert_nothing_marked_survives(original, student)
    raw = written.read_text()
    for secret in ("marmalade", "times_secret", "MSE = 50.0", "plt.plot"):
        assert secret not in raw


def test_the_leak_check_can_fail():
    """Fed the source itself as the 'student edition', the checks object."""
    source = fixture_notebook()
    assert "times_secret = np.arange(0, 1, 0.01)" in surviving_solution_lines(source, source)
    with pytest.raises(AssertionError):
        assert_nothing_marked_survives(source, source)
    student = nbformat.reads(se.student_edition(source, "f"), as_version=4)
    assert_nothing_marked_survives(source, student)
    student.cells[-1].source += "\n# The mean squared error is half the squared amplitude: a fact"
    assert "error is half the squared amplitude: a fact" in surviving_answer_text(source, student)
    with pytest.raises(AssertionError):
        assert_nothing_marked_survives(source, student)


def test_build_is_deterministic_and_leaves_the_source_alone(tmp_path):
    source = write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    digest = hashlib.sha256(source.read_bytes()).hexdigest()
    first = se.build_student_edition(source.parent, tmp_path / "a")[0].read_bytes()
    second = se.build_student_edition(source.parent, tmp_path / "b")[0].read_bytes()
    assert first == second
    assert hashlib.sha256(source.read_bytes()).hexdigest() == digest
    notebook = fixture_notebook()
    before = json.dumps(notebook, sort_keys=True)
    se.student_edition(notebook, "f")
    assert json.dumps(notebook, sort_keys=True) == before


@pytest.mark.parametrize(
    ("index", "cell", "message"),
    [
        (3, new_code_cell("x = 1", metadata={"tags": ["solution"]}), "# Task:"),
        (2, new_markdown_cell("text", metadata={"tags": ["solution"]}), "for code cells"),
        (5, new_code_cell("x = 1", metadata={"tags": ["answer"]}), "for markdown cells"),
        (6, new_code_cell("# Task: x\nx = 1", metadata={"tags": ["explorer", "solution"]}),
         "must not also be"),
        (5, new_markdown_cell("text", metadata={"tags": ["answer", "solution"]}), "both"),
    ],
)
def test_broken_convention_is_refused_with_its_place(tmp_path, index, cell, message):
    notebook = fixture_notebook()
    notebook.cells[index] = cell
    source = write(notebook, tmp_path / "src" / "02_broken.ipynb")
    with pytest.raises(ValueError, match=message) as error:
        se.build_student_edition(source.parent, tmp_path / "out")
    assert f"02_broken, cell {index}" in str(error.value)


def test_a_notebook_without_solution_cells_is_refused(tmp_path):
    write(fixture_notebook(), tmp_path / "src" / "01_fine.ipynb")
    write(fixture_notebook(with_solutions=False), tmp_path / "src" / "02_untagged.ipynb")
    out = tmp_path / "out"
    with pytest.raises(se.MissingSolutionsError, match=r"02_untagged\.ipynb: no cell is tagged"):
        se.build_student_edition(tmp_path / "src", out)
    assert not out.exists(), "a refused build must write nothing"

    with pytest.warns(se.MissingSolutionsWarning, match=r"02_untagged\.ipynb"):
        written = se.build_student_edition(tmp_path / "src", out, allow_without_solutions=True)
    assert [path.name for path in written] == ["01_fine.ipynb", "02_untagged.ipynb"]
    # Built anyway, it hands out the worked code: exactly what the refusal prevents.
    assert "times_secret" in written[1].read_text()


# ------------------------------------------- every notebook, executed once a run


@pytest.fixture(scope="session")
def sources(tmp_path_factory) -> dict[str, Path]:
    """Folders of source notebooks: the fixture and the pack's own."""
    fixture_dir = tmp_path_factory.mktemp("student_source")
    write(fixture_notebook(), fixture_dir / "01_fixture.ipynb")
    return {"fixture": fixture_dir, "notebooks": NOTEBOOKS}


@pytest.fixture(scope="session")
def editions(sources, tmp_path_factory, student_edition: StudentEdition) -> dict[str, Path]:
    """The student edition of each source folder: the fixture's, and the run's of the pack."""
    fixture_edition = tmp_path_factory.mktemp("student_fixture")
    for path in sorted(sources["fixture"].glob("*.ipynb")):
        text = se.student_edition(nbformat.read(path, as_version=4), path.stem)
        (fixture_edition / path.name).write_text(text, encoding="utf-8")
    return {"fixture": fixture_edition, "notebooks": student_edition.folder}


def run_cell(client: NotebookClient, cell: nbformat.NotebookNode,
             index: int) -> CellExecutionError | None:
    try:
        client.execute_cell(cell, index)
    except CellExecutionError as error:
        return error
    return None


class StudentRun:
    """What happened when a student notebook was executed as a student would.

    First top to bottom until a cell raises, then (same kernel) each explorer cell;
    then, in a fresh kernel, the first code cell and each explorer cell only, as the
    student note says is enough.
    """

    def __init__(self, path: Path, cwd: Path) -> None:
        self.notebook = nbformat.read(path, as_version=4)
        self.stopped_at: int | None = None
        self.stop_error: CellExecutionError | None = None
        self.explorer_errors: dict[str, str] = {}
        self.fresh_explorers: dict[int, nbformat.NotebookNode] = {}
        resources = {"metadata": {"path": str(cwd)}}
        client = NotebookClient(self.notebook, timeout=300, kernel_name="python3",
                                resources=resources)
        code = [i for i, cell in enumerate(self.notebook.cells) if cell.cell_type == "code"]
        explorers = [i for i, cell in enumerate(self.notebook.cells)
                     if tc.EXPLORER_TAG in tags(cell)]
        with client.setup_kernel():
            for index in code:
                error = run_cell(client, self.notebook.cells[index], index)
                if error is not None:
                    self.stopped_at, self.stop_error = index, error
                    break
            # Only the cells before the first stub have run: run each explorer on that.
            for index in explorers:
                error = run_cell(client, self.notebook.cells[index], index)
                if error is not None:
                    self.explorer_errors[f"cell {index}"] = f"{error.ename}: {error.evalue}"

        fresh = nbformat.from_dict(json.loads(json.dumps(self.notebook)))
        client = NotebookClient(fresh, timeout=300, kernel_name="python3", resources=resources)
        with client.setup_kernel():
            for index in code[:1] + [i for i in explorers if i != code[0]]:
                error = run_cell(client, fresh.cells[index], index)
                if error is not None:
                    where = f"cell {index}, fresh kernel, after the first code cell only"
                    self.explorer_errors[where] = f"{error.ename}: {error.evalue}"
                elif index in explorers:
                    self.fresh_explorers[index] = fresh.cells[index]


def assert_runs_until_first_stub(run: StudentRun) -> None:
    stubs = [i for i, cell in enumerate(run.notebook.cells) if tc.TASK_TAG in tags(cell)]
    if not stubs:
        assert run.stopped_at is None, run.stop_error
        return
    if run.stopped_at == stubs[0] + 1 and tc.CHECK_CALL in run.notebook.cells[
            run.stopped_at].source:
        # A stub of functions only runs; the check after it (a CheckFailed) says so.
        assert "not written yet" in run.stop_error.evalue, run.stop_error.evalue
    else:
        assert run.stopped_at == stubs[0], run.stop_error
        assert run.stop_error.ename == "NotImplementedError"
        assert tc.STUB_MESSAGE in run.stop_error.evalue
    for cell in run.notebook.cells[: stubs[0]]:
        for output in cell.get("outputs", []):
            assert output.output_type != "error"
            assert output.get("name") != "stderr", output.get("text")


def assert_explorers_work(run: StudentRun) -> None:
    assert run.explorer_errors == {}
    explorers = [i for i, cell in enumerate(run.notebook.cells) if tc.EXPLORER_TAG in tags(cell)]
    assert sorted(run.fresh_explorers) == explorers
    for cell in [run.notebook.cells[i] for i in explorers] + list(run.fresh_explorers.values()):
        shown = [output.data for output in cell.outputs if "data" in output]
        assert any("application/vnd.jupyter.widget-view+json" in data for data in shown)
        assert any("data:image/png;base64," in data.get("text/html", "") for data in shown)


@pytest.fixture(scope="session")
def student_runs(sources, editions):
    cache: dict[tuple[str, str], StudentRun] = {}

    def run(key: str, name: str) -> StudentRun:
        if (key, name) not in cache:
            cache[key, name] = StudentRun(editions[key] / name, cwd=sources[key])
        return cache[key, name]

    return run


@pytest.mark.kernel
def test_the_run_checks_can_fail(tmp_path):
    """A cell before the first stub that raises, and an explorer that needs a solution."""
    notebook = fixture_notebook()
    notebook.cells.insert(2, new_code_cell("raise KeyError('not a stub')"))
    notebook.cells[-1].source += "\nprint(error_secret)"
    path = write(nbformat.reads(se.student_edition(notebook, "bad"), as_version=4),
                 tmp_path / "bad.ipynb")
    run = StudentRun(path, cwd=tmp_path)
    assert run.stopped_at == 3  # the note comes in at 1
    assert run.stop_error.ename == "KeyError"
    with pytest.raises(AssertionError):
        assert_runs_until_first_stub(run)
    assert run.explorer_errors == {
        f"cell {index}{fresh}": "NameError: name 'error_secret' is not defined"
        for index in [len(run.notebook.cells) - 1]
        for fresh in ("", ", fresh kernel, after the first code cell only")
    }
    with pytest.raises(AssertionError):
        assert_explorers_work(run)


#: Tags under which nbval would not check a cell (or its outputs) against the source.
UNCHECKED_TAGS = {"nbval-skip", "nbval-ignore-output", "raises-exception", "skip-execution"}

CASES = [("fixture", "01_fixture.ipynb")] + [("notebooks", name) for name in REAL]
IDS = [f"{key}/{name}" for key, name in CASES]


def test_every_pack_notebook_is_checked():
    assert len(REAL) >= 7, REAL


@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
def test_source_follows_the_tag_convention(sources, key, name):
    notebook = nbformat.read(sources[key] / name, as_version=4)
    # Without solution cells `make student` refuses it: the student edition would hand
    # out the worked answers.
    se.check_has_solutions(notebook, name)
    for index, cell in enumerate(notebook.cells):
        cell_tags = set(tags(cell))
        where = f"{name}, cell {index}"
        if tc.SOLUTION_TAG in cell_tags:
            assert cell.cell_type == "code", where
            instruction = " ".join(tc.task_instruction(cell.source))
            assert len(instruction.split()) >= 4, f"{where}: the task needs a real instruction"
            assert len(tc.task_instruction(cell.source)) < len(cell.source.splitlines()), where
            # nbval must check worked solutions like any other cell.
            assert not cell_tags & UNCHECKED_TAGS, f"{where}: {cell_tags & UNCHECKED_TAGS}"
        if tc.ANSWER_TAG in cell_tags:
            assert cell.cell_type == "markdown", where
        if tc.EXPLORER_TAG in cell_tags:
            assert cell.cell_type == "code", where
            assert "nbval-ignore-output" in cell_tags, where
            assert not cell_tags & {tc.SOLUTION_TAG, tc.ANSWER_TAG}, where


@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
@pytest.mark.slow
def test_no_solution_or_answer_text_survives(sources, editions, key, name):
    source = nbformat.read(sources[key] / name, as_version=4)
    student = nbformat.read(editions[key] / name, as_version=4)
    nbformat.validate(student)
    assert student.cells[1].source == se.STUDENT_NOTE
    assert_nothing_marked_survives(source, student)


@pytest.mark.kernel
@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
def test_student_notebook_runs_until_its_first_stub(student_runs, key, name):
    assert_runs_until_first_stub(student_runs(key, name))


@pytest.mark.kernel
@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
def test_explorers_run_on_their_own_in_the_student_edition(student_runs, key, name):
    assert_explorers_work(student_runs(key, name))


# ---------------------- a student who writes the worked solutions passes every check

#: The tutorial's question notebooks: every task of their core path has a check.
QUESTION_NOTEBOOKS = [name for name in REAL if name.startswith(sp.CHECKED_PREFIXES)]


def filled_fixture(source: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """:func:`artefacts.filled_core` of a fixture notebook's student edition."""
    return filled_core(source, nbformat.reads(se.student_edition(source, "fixture"),
                                              as_version=4))


def check_cells(notebook: nbformat.NotebookNode) -> list[int]:
    """Indices of the check cells: the untagged code cell right after each task."""
    return [index + 1 for index, cell in enumerate(notebook.cells[:-1])
            if tc.TASK_TAG in tags(cell) and tc.CHECK_CALL in notebook.cells[index + 1].source
            and not tags(notebook.cells[index + 1])]


def assert_every_check_passed(notebook: nbformat.NotebookNode, error: RunError | None) -> None:
    assert error is None, f"the filled student edition stopped: {error}"
    for index in check_cells(notebook):
        cell = notebook.cells[index]
        kinds = [output.output_type for output in cell.outputs]
        printed = "".join(output.get("text", "") for output in cell.outputs)
        assert "error" not in kinds, f"check cell {index}: {cell.source}"
        assert printed.startswith("✓ "), f"check cell {index} ({cell.source}) printed {printed!r}"


@pytest.mark.kernel
def test_the_filled_edition_run_can_fail(tmp_path):
    """A wrong solution in a task makes its check fail; a right one passes."""
    from lqe_helpers import checks

    assert issubclass(checks.CheckFailed, AssertionError)
    right = "# Task: build P0 = 1e5 I₃ (cm²).\nimport numpy as np\nP0 = 1e5 * np.eye(3)"
    notebook = new_notebook(
        cells=[new_markdown_cell("# Fixture"),
               new_code_cell("from lqe_helpers import checks"),
               new_code_cell(right, metadata={"tags": ["solution"]}),
               new_code_cell("checks.check_initial_covariance(P0, 1e5)"),
               new_markdown_cell("## Going further\n\nOptional."),
               new_code_cell("raise RuntimeError('not reached: Going further is left out')")],
        metadata={"kernelspec": KERNELSPEC, "language_info": {"name": "python"}})
    filled = filled_fixture(notebook)
    assert check_cells(filled) == [4]  # the note comes in at 1
    assert_every_check_passed(filled, run_notebook(filled, tmp_path))
    notebook.cells[2].source = right.replace("1e5 * np.eye(3)", "np.sqrt(1e5) * np.eye(3)")
    filled = filled_fixture(notebook)
    error = run_notebook(filled, tmp_path)
    assert error is not None and error.ename == "CheckFailed"
    with pytest.raises(AssertionError):
        assert_every_check_passed(filled, error)


def test_the_filled_edition_holds_every_question_notebook(filled_edition: FilledEdition):
    assert filled_edition.names == tuple(QUESTION_NOTEBOOKS)
    assert len(QUESTION_NOTEBOOKS) == 5, QUESTION_NOTEBOOKS


@pytest.mark.slow
@pytest.mark.kernel
@pytest.mark.parametrize("name", QUESTION_NOTEBOOKS)
def test_worked_solutions_pass_every_check_in_the_student_edition(filled_edition: FilledEdition,
                                                                  name):
    """Core path only (up to ``## Going further``): that is where every task has a check."""
    run = filled_edition.run(name)
    assert check_cells(run.notebook), f"{name}: no task of the core path is followed by a check"
    assert_every_check_passed(run.notebook, run.error)


# ==================================================================================
# File safety of the student edition (owner: the file-safety work of issue 10). The
# tests above are about the transformation; these about what the build reads and writes.
# ==================================================================================


def _snapshot(folder: Path) -> dict[str, bytes | str]:
    """Every file (its bytes), link (its target) and folder under ``folder``."""
    return {path.relative_to(folder).as_posix():
            (f"link -> {path.readlink()}" if path.is_symlink()
             else "folder" if path.is_dir() else path.read_bytes())
            for path in sorted(folder.rglob("*"))}


def _course(tmp_path: Path) -> Path:
    """A course folder C with seven worked notebooks and a drafts/ subfolder of two."""
    course = tmp_path / "C"
    for number in range(7):
        write(fixture_notebook(), course / f"0{number}_worked.ipynb")
    for number in range(2):
        write(fixture_notebook(), course / "drafts" / f"0{number}_draft.ipynb")
    return course


def test_file_safety_bad_folders_are_refused(tmp_path):
    with pytest.raises(ValueError, match="source_dir must be an existing folder"):
        se.build_student_edition(tmp_path / "missing", tmp_path / "out")
    with pytest.raises(ValueError, match=r"at least one \.ipynb"):
        se.build_student_edition(tmp_path, tmp_path / "out")
    write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    (tmp_path / "file").write_text("a file")
    before = _snapshot(tmp_path)
    for out, message in [(tmp_path / "src" / ".." / "src", "is the source folder"),
                         (tmp_path / "src" / "student", "lies inside the source folder"),
                         (tmp_path, "contains the source folder"),
                         (tmp_path / "file", "is a file; give a folder")]:
        with pytest.raises(errors.OutputFolderError, match=message):
            se.build_student_edition(tmp_path / "src", out)
    assert _snapshot(tmp_path) == before


def test_file_safety_drafts_written_into_the_course_folder_delete_nothing(tmp_path, capsys):
    """The issue's case: --source C/drafts --out C exited 0 and deleted seven notebooks."""
    course = _course(tmp_path)
    before = _snapshot(course)
    assert se.main(["--source", str(course / "drafts"), "--out", str(course)]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (f"error: the output folder {course} contains the source folder "
                            f"{course / 'drafts'}, so a build could replace or delete source "
                            f"files; write it somewhere else\n")
    assert _snapshot(course) == before


def test_file_safety_grading_notes_and_foreign_notebooks_are_never_touched(tmp_path):
    """The issue's case: my_grading_notes.ipynb in --out was deleted."""
    write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    out = tmp_path / "out"
    out.mkdir()
    mine = {"my_grading_notes.ipynb": "grading notes", "00_renamed.ipynb": "not the tool's",
            "notes.md": "notes", "extra/old.ipynb": "old"}
    for name, text in mine.items():
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_text(text)
    written = se.build_student_edition(tmp_path / "src", out)
    assert written == [out / "01_fixture.ipynb"]
    assert {name: (out / name).read_text() for name in mine} == mine
    assert sorted(path.relative_to(out).as_posix() for path in out.rglob("*") if path.is_file()
                  ) == sorted([*mine, "01_fixture.ipynb", manifest.MANIFEST_NAME])
    # A notebook of the instructor's in the way of the build stops it; nothing changes.
    (out / "01_fixture.ipynb").unlink()
    (tmp_path / "src" / "my_grading_notes.ipynb").write_bytes(
        (tmp_path / "src" / "01_fixture.ipynb").read_bytes())
    before = _snapshot(out)
    with pytest.raises(errors.OutputFolderError,
                       match=r"my_grading_notes\.ipynb was not written by student_edition"):
        se.build_student_edition(tmp_path / "src", out)
    assert _snapshot(out) == before


def test_file_safety_a_renamed_notebooks_old_edition_goes_a_hand_edited_one_stays(tmp_path):
    write(fixture_notebook(), tmp_path / "src" / "00_old_name.ipynb")
    write(fixture_notebook(), tmp_path / "src" / "02_other.ipynb")
    out = tmp_path / "out"
    se.build_student_edition(tmp_path / "src", out)
    (out / "02_other.ipynb").write_text("edited by the instructor after the build")
    (tmp_path / "src" / "00_old_name.ipynb").rename(tmp_path / "src" / "01_new_name.ipynb")
    (tmp_path / "src" / "02_other.ipynb").rename(tmp_path / "src" / "03_other.ipynb")
    se.build_student_edition(tmp_path / "src", out)
    assert sorted(path.name for path in out.iterdir()) == [
        manifest.MANIFEST_NAME, "01_new_name.ipynb", "02_other.ipynb", "03_other.ipynb"]
    assert (out / "02_other.ipynb").read_text() == "edited by the instructor after the build"


def test_file_safety_a_symlink_in_out_is_not_written_through(tmp_path):
    """The issue's case: a link in --out to a worked notebook got its student edition."""
    course = _course(tmp_path)
    worked = course / "01_worked.ipynb"
    out = tmp_path / "out"
    out.mkdir()
    (out / "01_worked.ipynb").symlink_to(worked)
    before, course_before = _snapshot(out), _snapshot(course)
    with pytest.raises(errors.OutputFolderError, match=r"01_worked\.ipynb is a symbolic link"):
        se.build_student_edition(course, out)
    assert _snapshot(out) == before
    assert _snapshot(course) == course_before


def test_file_safety_a_failure_while_writing_changes_nothing(tmp_path, monkeypatch):
    from lqe_helpers.authoring import files

    write(fixture_notebook(), tmp_path / "src" / "01_a.ipynb")
    write(fixture_notebook(), tmp_path / "src" / "02_b.ipynb")
    out = tmp_path / "out"
    se.build_student_edition(tmp_path / "src", out)
    (tmp_path / "src" / "01_a.ipynb").write_text(
        (tmp_path / "src" / "01_a.ipynb").read_text().replace("marmalade", "jam"))
    before = _snapshot(tmp_path)
    real, calls = files._write_fd, []

    def full_disk(fd: int, data: bytes) -> None:
        calls.append(len(data))
        if len(calls) == 2:
            real(fd, data[:100])
            raise OSError(28, "No space left on device")
        real(fd, data)

    monkeypatch.setattr(files, "_write_fd", full_disk)
    with pytest.raises(errors.OutputWriteError, match="No space left on device"):
        se.build_student_edition(tmp_path / "src", out)
    assert _snapshot(tmp_path) == before


@pytest.mark.parametrize(("content", "message"), [
    ("{broken", "01_bad.ipynb is not a notebook (not valid JSON: "),
    ('{"nbformat": 4, "cells": 3}', "01_bad.ipynb is not a valid notebook: "),
])
def test_file_safety_a_file_that_is_not_a_notebook_is_one_error_line(tmp_path, capsys,
                                                                     content, message):
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "01_bad.ipynb").write_text(content)
    assert se.main(["--source", str(tmp_path / "src"), "--out", str(tmp_path / "out")]) == 1
    captured = capsys.readouterr()
    [line] = captured.err.splitlines()
    assert line.startswith("error: ")
    assert message in line, line
    assert not (tmp_path / "out").exists()


def test_file_safety_an_unknown_tag_is_one_error_line(tmp_path, capsys):
    notebook = fixture_notebook()
    notebook.cells[2].metadata["tags"] = ["Solution"]
    write(notebook, tmp_path / "src" / "01_fixture.ipynb")
    assert se.main(["--source", str(tmp_path / "src"), "--out", str(tmp_path / "out")]) == 1
    captured = capsys.readouterr()
    [line] = captured.err.splitlines()
    assert line.startswith("error: 01_fixture, cell 2 ")
    assert "'Solution'" in line
    assert not (tmp_path / "out").exists()


def test_file_safety_command_line(tmp_path, capsys):
    source = write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    out = tmp_path / "out"
    assert se.main(["--source", str(source.parent), "--out", str(out)]) == 0
    assert capsys.readouterr().out.split() == [str(out / "01_fixture.ipynb")]

    write(fixture_notebook(with_solutions=False), tmp_path / "src" / "02_untagged.ipynb")
    before = _snapshot(out)
    assert se.main(["--source", str(source.parent), "--out", str(out)]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    [line] = captured.err.splitlines()
    assert line.startswith("error: 02_untagged.ipynb: no cell is tagged 'solution'")
    assert "--allow-without-solutions" in line
    assert _snapshot(out) == before
    # Allowed: one warning line that names the flag that allowed it.
    assert se.main(["--source", str(source.parent), "--out", str(out),
                    "--allow-without-solutions"]) == 0
    captured = capsys.readouterr()
    assert len(captured.out.split()) == 2
    assert captured.err == ("warning: 02_untagged.ipynb: no cell is tagged 'solution'; built "
                            "anyway because of --allow-without-solutions, so its student "
                            "edition contains every worked answer\n")
    # Bad input: exit code 1 and one "error:" line, as for the handouts.
    assert se.main(["--source", str(tmp_path / "missing"), "--out", str(out)]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (f"error: source_dir must be an existing folder, got "
                            f"{tmp_path / 'missing'}\n")
