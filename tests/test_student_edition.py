"""The student edition: solutions become stubs, answers become prompts, explorers stay.

Unit tests use small notebooks written into tmp_path. The same checks then run on
every notebook in ``notebooks/``: each student notebook is executed once per test
session (up to its first stub, then its explorer cells; and its explorers again in a
fresh kernel after the first code cell only) and the results are shared. A few
tests feed the checks a broken notebook, to show that they can fail.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

from lqe_helpers.authoring import student_edition as se

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
ANSWER = ("### Answer to (a)\n\n"
          "The mean squared error is half the squared amplitude: a fact about marmalade sines.")
EXPLORER = (
    "from lqe_helpers.explorer import Explorer, float_slider\n\n\n"
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
    if not with_solutions:
        solution.metadata, second.metadata = {}, {}
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
    return bool({se.SOLUTION_TAG, se.ANSWER_TAG} & set(tags(cell)))


def surviving_solution_lines(source: nbformat.NotebookNode,
                             student: nbformat.NotebookNode) -> set[str]:
    """Lines unique to marked cells of ``source`` found in ``student``.

    The parts the student edition keeps on purpose are left out: a solution's task
    comment and an answer's headings.
    """
    marked, other = set(), set()
    for cell in source.cells:
        lines = cell.source.splitlines()
        if se.SOLUTION_TAG in tags(cell):
            lines = lines[len(se.task_instruction(cell.source)):]
        elif se.ANSWER_TAG in tags(cell):
            lines = [line for line in lines if line not in se.answer_headings(cell.source)]
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
        if se.ANSWER_TAG in tags(cell):
            headings = se.answer_headings(cell.source)
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
    assert sum(se.TASK_TAG in tags(cell) for cell in student.cells) == se.count_solutions(source)
    answers = sum(se.ANSWER_TAG in tags(cell) for cell in source.cells)
    assert sum(se.ANSWER_PROMPT_TAG in tags(cell) for cell in student.cells) == answers
    assert not any(is_marked(cell) for cell in student.cells)


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


@pytest.mark.parametrize(
    ("source", "prompt"),
    [
        ("Plain answer.", [se.ANSWER_PROMPT]),
        ("## The answers\n\n### (a)\n**1.** Yes.\n# not a heading any more",
         ["## The answers", "### (a)", se.ANSWER_PROMPT]),
        ("\n## Late heading\nText", ["## Late heading", se.ANSWER_PROMPT]),
        ("Text first\n## Heading after text", [se.ANSWER_PROMPT]),
    ],
)
def test_answer_prompt_keeps_only_the_leading_headings(source, prompt):
    assert se.prompt_source(source) == "\n\n".join(prompt)


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
    assert by_tag[(se.ANSWER_PROMPT_TAG,)].source == f"### Answer to (a)\n\n{se.ANSWER_PROMPT}"
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


def test_bad_folders_are_refused(tmp_path):
    with pytest.raises(ValueError, match="source_dir must be an existing folder"):
        se.build_student_edition(tmp_path / "missing", tmp_path / "out")
    with pytest.raises(ValueError, match=r"at least one \.ipynb"):
        se.build_student_edition(tmp_path, tmp_path / "out")
    write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    with pytest.raises(ValueError, match="out_dir must differ from source_dir"):
        se.build_student_edition(tmp_path / "src", tmp_path / "src" / ".." / "src")


def test_stale_notebooks_are_removed_and_nothing_else(tmp_path):
    write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    out = tmp_path / "out"
    stale = out / "00_renamed.ipynb"
    kept = [out / "notes.md", out / "00_renamed.html", out / "extra" / "old.ipynb"]
    for path in [stale, *kept]:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("from before")

    # A refused build deletes nothing either.
    write(fixture_notebook(with_solutions=False), tmp_path / "src" / "02_untagged.ipynb")
    with pytest.raises(se.MissingSolutionsError):
        se.build_student_edition(tmp_path / "src", out)
    assert stale.read_text() == "from before"

    (tmp_path / "src" / "02_untagged.ipynb").unlink()
    written = se.build_student_edition(tmp_path / "src", out)
    assert written == [out / "01_fixture.ipynb"]
    assert not stale.exists()
    assert all(path.read_text() == "from before" for path in kept)
    assert sorted(path for path in out.rglob("*") if path.is_file()) == sorted([*written, *kept])


def test_command_line(tmp_path, capsys):
    source = write(fixture_notebook(), tmp_path / "src" / "01_fixture.ipynb")
    out = tmp_path / "out"
    assert se.main(["--source", str(source.parent), "--out", str(out)]) == 0
    assert capsys.readouterr().out.split() == [str(out / "01_fixture.ipynb")]

    write(fixture_notebook(with_solutions=False), tmp_path / "src" / "02_untagged.ipynb")
    assert se.main(["--source", str(source.parent), "--out", str(out)]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "02_untagged.ipynb: no cell is tagged 'solution'" in captured.err
    with pytest.warns(se.MissingSolutionsWarning):
        assert se.main(["--source", str(source.parent), "--out", str(out),
                        "--allow-without-solutions"]) == 0
    assert len(capsys.readouterr().out.split()) == 2
    # Bad input: exit code 1 and one "error:" line, as for the handouts.
    assert se.main(["--source", str(tmp_path / "missing"), "--out", str(out)]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (f"error: source_dir must be an existing folder, got "
                            f"{tmp_path / 'missing'}\n")


# ------------------------------------------- every notebook, executed once a session


@pytest.fixture(scope="session")
def sources(tmp_path_factory) -> dict[str, Path]:
    """Folders of source notebooks: the fixture and the pack's own."""
    fixture_dir = tmp_path_factory.mktemp("student_source")
    write(fixture_notebook(), fixture_dir / "01_fixture.ipynb")
    return {"fixture": fixture_dir, "notebooks": NOTEBOOKS}


@pytest.fixture(scope="session")
def editions(sources, tmp_path_factory) -> dict[str, Path]:
    """The student edition of each source folder, notebook by notebook.

    Built one notebook at a time (not with build_student_edition, which refuses a
    folder holding a notebook without solution cells) so that each notebook's tests
    report on that notebook alone.
    """
    built = {}
    for key, folder in sources.items():
        built[key] = tmp_path_factory.mktemp(f"student_{key}")
        for path in sorted(folder.glob("*.ipynb")):
            text = se.student_edition(nbformat.read(path, as_version=4), path.stem)
            (built[key] / path.name).write_text(text, encoding="utf-8")
    return built


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
                     if se.EXPLORER_TAG in tags(cell)]
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


def assert_explorers_work(run: StudentRun) -> None:
    assert run.explorer_errors == {}
    explorers = [i for i, cell in enumerate(run.notebook.cells) if se.EXPLORER_TAG in tags(cell)]
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
        if se.SOLUTION_TAG in cell_tags:
            assert cell.cell_type == "code", where
            instruction = " ".join(se.task_instruction(cell.source))
            assert len(instruction.split()) >= 4, f"{where}: the task needs a real instruction"
            assert len(se.task_instruction(cell.source)) < len(cell.source.splitlines()), where
            # nbval must check worked solutions like any other cell.
            assert not cell_tags & UNCHECKED_TAGS, f"{where}: {cell_tags & UNCHECKED_TAGS}"
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
    nbformat.validate(student)
    assert student.cells[1].source == se.STUDENT_NOTE
    assert_nothing_marked_survives(source, student)


@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
def test_student_notebook_runs_until_its_first_stub(student_runs, key, name):
    assert_runs_until_first_stub(student_runs(key, name))


@pytest.mark.parametrize(("key", "name"), CASES, ids=IDS)
def test_explorers_run_on_their_own_in_the_student_edition(student_runs, key, name):
    assert_explorers_work(student_runs(key, name))
