"""The student edition: solutions become stubs, answers become prompts, explorers stay.

Unit tests use small notebooks written into tmp_path. The same checks then run on
every notebook in ``notebooks/``: each student notebook is executed once per test
session (up to its first stub, then its explorer cells) and the results are shared.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

from lqe_helpers import student_edition as se

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"
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
ANSWER = "The mean squared error is half the squared amplitude: a fact about marmalade sines."
EXPLORER = (
    "from lqe_helpers.explorer import Explorer, float_slider\n\n\n"
    "def draw(figure, *, amplitude):\n"
    "    figure.clear()\n"
    "    figure.add_subplot().plot([0, 1], [0, amplitude], label='line')\n\n\n"
    "Explorer('A line', {'amplitude': float_slider('A (cm)', 1.0, 0.0, 2.0, 0.1)}, draw)"
)


def fixture_notebook() -> nbformat.NotebookNode:
    """A small executed-looking notebook following the tag convention."""
    solution = new_code_cell(SOLUTION, metadata={"tags": ["solution"]}, execution_count=2,
                             outputs=[new_output("stream", name="stdout", text="MSE = 50.0 cm²\n")])
    notebook = new_notebook(
        cells=[
            new_markdown_cell("# A fixture notebook\n\nWhat you will learn: nothing much."),
            new_code_cell(SETUP, execution_count=1),
            new_markdown_cell("## The question\n\nHow large is the error?"),
            solution,
            new_code_cell(SECOND_SOLUTION, metadata={"tags": ["solution"]}),
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
    return bool({se.SOLUTION_TAG, se.ANSWER_TAG} & set(tags(cell)))


def surviving_solution_lines(source: nbformat.NotebookNode,
                             student: nbformat.NotebookNode) -> set[str]:
    """Lines unique to marked cells of ``source`` (task comments aside) found in ``student``."""
    marked, other = set(), set()
    for cell in source.cells:
        lines = cell.source.splitlines()
        if se.SOLUTION_TAG in tags(cell):
            lines = lines[len(se.task_instruction(cell.source)):]
        (marked if is_marked(cell) else other).update(
            line.strip() for line in lines if line.strip())
    student_lines = {line.strip() for cell in student.cells for line in cell.source.splitlines()}
    return (marked - other) & student_lines


# ---------------------------------------------------------------- unit tests


def test_task_instruction_is_the_leading_comment_block():
    assert se.task_instruction(SOLUTION) == SOLUTION.splitlines()[:2]
    assert se.task_instruction("# Task: one line\nx = 1\n# later comment") == ["# Task: one line"]


@pytest.mark.parametrize("source", ["x = 1", "", "# Note: not a task\nx = 1", "\n# Task: late"])
def test_task_instruction_rejects_a_cell_without_task(source):
    with pytest.raises(ValueError, match="# Task:"):
        se.task_instruction(source)


def test_stub_is_task_then_raise():
    stub = se.stub_source(SOLUTION)
    assert stub.splitlines() == [*SOLUTION.splitlines()[:2],
                                 f'raise NotImplementedError("{se.STUB_MESSAGE}")']
    with pytest.raises(NotImplementedError, match="task described above"):
        exec(compile(stub, "<stub>", "exec"), {})


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

    stubs = [cell for cell in student.cells if se.TASK_TAG in tags(cell)]
    assert [cell.source for cell in stubs] == [se.stub_source(SOLUTION),
                                               se.stub_source(SECOND_SOLUTION)]
    assert by_tag[(se.ANSWER_PROMPT_TAG,)].source == se.ANSWER_PROMPT
    assert by_tag[("explorer", "nbval-ignore-output")].source == EXPLORER
    for kept, before in zip(student.cells, original.cells, strict=True):
        if not is_marked(before):
            assert kept.source == before.source
            assert tags(kept) == tags(before)
    assert not any(is_marked(cell) for cell in student.cells)

    for cell in student.cells:
        if cell.cell_type == "code":
            assert cell.outputs == []
            assert cell.execution_count is None
    assert "widgets" not in student.metadata
    assert student.metadata["kernelspec"] == KERNELSPEC
    assert surviving_solution_lines(original, student) == set()
    assert "marmalade" not in written.read_text()


def test_build_is_deterministic_and_leaves_the_source_alone(tmp_path):
    source = write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    digest = hashlib.sha256(source.read_bytes()).hexdigest()
    first = se.build_student_edition(source.parent, tmp_path / "a")[0].read_bytes()
    second = se.build_student_edition(source.parent, tmp_path / "b")[0].read_bytes()
    assert first == second
    assert hashlib.sha256(source.read_bytes()).hexdigest() == digest


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


def test_bad_folders_are_refused(tmp_path):
    with pytest.raises(ValueError, match="source_dir must be an existing folder"):
        se.build_student_edition(tmp_path / "missing", tmp_path / "out")
    with pytest.raises(ValueError, match=r"at least one \.ipynb"):
        se.build_student_edition(tmp_path, tmp_path / "out")
    write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    with pytest.raises(ValueError, match="out_dir must differ from source_dir"):
        se.build_student_edition(tmp_path / "src", tmp_path / "src" / ".." / "src")


def test_command_line(tmp_path, capsys):
    source = write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    out = tmp_path / "out"
    assert se.main(["--source", str(source.parent), "--out", str(out)]) == 0
    assert capsys.readouterr().out.split() == [str(out / "01_fixture.ipynb")]


# ------------------------------------------- every notebook, executed once a session


@pytest.fixture(scope="session")
def sources(tmp_path_factory) -> dict[str, Path]:
    """Folders of source notebooks: the fixture and the pack's own."""
    fixture_dir = tmp_path_factory.mktemp("student_source")
    write(fixture_notebook(), fixture_dir / "01_fixture.ipynb")
    return {"fixture": fixture_dir, "notebooks": NOTEBOOKS}


@pytest.fixture(scope="session")
def editions(sources, tmp_path_factory) -> dict[str, Path]:
    """The student edition of each source folder, built once."""
    built = {}
    for key, folder in sources.items():
        if any(folder.glob("*.ipynb")):
            built[key] = tmp_path_factory.mktemp(f"student_{key}")
            se.build_student_edition(folder, built[key])
    return built


class StudentRun:
    """What happened when a student notebook was executed, top to bottom then explorers."""

    def __init__(self, path: Path, cwd: Path) -> None:
        self.notebook = nbformat.read(path, as_version=4)
        self.stopped_at: int | None = None
        self.stop_error: CellExecutionError | None = None
        self.explorer_errors: dict[int, str] = {}
        client = NotebookClient(self.notebook, timeout=300, kernel_name="python3",
                                resources={"metadata": {"path": str(cwd)}})
        with client.setup_kernel():
            for index, cell in enumerate(self.notebook.cells):
                if cell.cell_type != "code":
                    continue
                try:
                    client.execute_cell(cell, index)
                except CellExecutionError as error:
                    self.stopped_at, self.stop_error = index, error
                    break
            # Only the cells before the first stub have run: run each explorer on that.
            for index, cell in enumerate(self.notebook.cells):
                if se.EXPLORER_TAG in tags(cell):
                    try:
                        client.execute_cell(cell, index)
                    except CellExecutionError as error:
                        self.explorer_errors[index] = f"{error.ename}: {error.evalue}"


@pytest.fixture(scope="session")
def student_runs(sources, editions):
    cache: dict[tuple[str, str], StudentRun] = {}

    def run(key: str, name: str) -> StudentRun:
        if (key, name) not in cache:
            cache[key, name] = StudentRun(editions[key] / name, cwd=sources[key])
        return cache[key, name]

    return run


CASES = [("fixture", "01_fixture.ipynb")] + [("notebooks", name) for name in REAL]
IDS = [f"{key}/{name}" for key, name in CASES]


@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
def test_source_follows_the_tag_convention(sources, key, name):
    notebook = nbformat.read(sources[key] / name, as_version=4)
    for index, cell in enumerate(notebook.cells):
        cell_tags = set(tags(cell))
        where = f"{name}, cell {index}"
        if se.SOLUTION_TAG in cell_tags:
            assert cell.cell_type == "code", where
            instruction = " ".join(se.task_instruction(cell.source))
            assert len(instruction.split()) >= 4, f"{where}: the task needs a real instruction"
            assert len(se.task_instruction(cell.source)) < len(cell.source.splitlines()), where
        if se.ANSWER_TAG in cell_tags:
            assert cell.cell_type == "markdown", where
        if se.EXPLORER_TAG in cell_tags:
            assert cell.cell_type == "code", where
            assert "nbval-ignore-output" in cell_tags, where
            assert not cell_tags & {se.SOLUTION_TAG, se.ANSWER_TAG}, where


@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
def test_no_solution_or_answer_text_survives(sources, editions, key, name):
    source = nbformat.read(sources[key] / name, as_version=4)
    student = nbformat.read(editions[key] / name, as_version=4)
    assert surviving_solution_lines(source, student) == set()
    text = "\n".join(cell.source for cell in student.cells)
    for cell in source.cells:
        if se.ANSWER_TAG in tags(cell):
            for line in cell.source.splitlines():
                if len(line.strip()) >= 20:
                    assert line.strip() not in text
    for cell in student.cells:
        assert cell.get("outputs", []) == []
        assert cell.get("execution_count") is None
    assert "widgets" not in student.metadata
    solutions = sum(se.SOLUTION_TAG in tags(cell) for cell in source.cells)
    assert sum(se.TASK_TAG in tags(cell) for cell in student.cells) == solutions
    answers = sum(se.ANSWER_TAG in tags(cell) for cell in source.cells)
    assert sum(se.ANSWER_PROMPT_TAG in tags(cell) for cell in student.cells) == answers


@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
def test_student_notebook_runs_until_its_first_stub(student_runs, key, name):
    run = student_runs(key, name)
    stubs = [i for i, cell in enumerate(run.notebook.cells) if se.TASK_TAG in tags(cell)]
    if not stubs:
        assert run.stopped_at is None, run.stop_error
        return
    assert run.stopped_at == stubs[0], run.stop_error
    assert run.stop_error.ename == "NotImplementedError"
    assert se.STUB_MESSAGE in run.stop_error.evalue
    for cell in run.notebook.cells[: stubs[0]]:
        for output in cell.get("outputs", []):
            assert output.output_type != "error"
            assert output.get("name") != "stderr", output.get("text")


@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
def test_explorers_run_on_their_own_in_the_student_edition(student_runs, key, name):
    run = student_runs(key, name)
    assert run.explorer_errors == {}
    for cell in run.notebook.cells:
        if se.EXPLORER_TAG in tags(cell):
            shown = [output.data for output in cell.outputs if "data" in output]
            assert any("application/vnd.jupyter.widget-view+json" in data for data in shown)
            assert any("data:image/png;base64," in data.get("text/html", "") for data in shown)
