"""The promise to students: in JupyterLab, moving a slider redraws the plot.

Each course notebook is opened in JupyterLab in Chromium (a copy, so autosave never
touches the committed file), its outputs are cleared and Run > Run All Cells is
clicked. The run must end with every code cell executed and no error output. Then
every slider of every explorer is moved by keyboard and by typing into its readout,
and each move must show a new picture and new numbers in the line above it; where the
notebook gives the explorer the student's filter (``filter=my_filter``, notebooks
01–05), the line must say after every move that the student's function ran. The
browser must log no error. Screenshots go to ``build/screenshots/``.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import nbformat
import pytest
from lab_driver import (
    LabServer,
    broken_output_images,
    clear_and_run_all,
    course_notebooks,
    error_outputs,
    exercise_slider,
    explorers,
    iter_sliders,
    open_notebook,
    screenshot_path,
    unexecuted_cells,
)

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]


def explorer_cells(path: Path) -> list[str]:
    """The sources of the code cells tagged ``explorer`` in the notebook file."""
    notebook = nbformat.read(path, as_version=4)
    return [cell.source for cell in notebook.cells
            if cell.cell_type == "code" and "explorer" in cell.metadata.get("tags", [])]


#: What an explorer running the student's own filter says in its numbers line.
STUDENTS_FILTER = "your my_filter"


@contextmanager
def explained(page, server: LabServer) -> Iterator[None]:
    """Add the browser's and the server's logs to any assertion failure."""
    try:
        yield
    except AssertionError as error:
        raise AssertionError(f"{error}\n{page.log}\n{server.log_tail()}") from None


@pytest.mark.parametrize("notebook", course_notebooks(), ids=lambda path: path.stem)
def test_every_slider_redraws_in_jupyterlab(lab_page, lab_server: LabServer,
                                            notebook: Path) -> None:
    page = lab_page
    with explained(page, lab_server):
        panel = open_notebook(page, lab_server, notebook.name, workspace=notebook.stem)
        clear_and_run_all(page, panel)

        problems = error_outputs(page, panel)
        assert not problems, f"{notebook.name} shows error output:\n" + "\n---\n".join(problems)
        broken = broken_output_images(page, panel)
        assert not broken, f"{notebook.name}: output images that did not load: {broken}"
        skipped = unexecuted_cells(page, panel)
        assert not skipped, f"{notebook.name}: cells not executed by Run All: {skipped}"

        views = explorers(panel)
        sources = explorer_cells(notebook)
        expected = len(sources)
        assert len(views) == expected, (
            f"{notebook.name}: {expected} cell(s) tagged 'explorer' but {len(views)} live "
            "explorer(s) with sliders on the page")
        for number, view in enumerate(views, start=1):
            assert view.image.count() == 1, (
                f"{notebook.name}, explorer {number}: expected one image, "
                f"found {view.image.count()}")
            assert view.sliders, f"{notebook.name}, explorer {number} has no slider"
            assert view.numbers.count() == 1, (
                f"{notebook.name}, explorer {number}: expected one numbers line, "
                f"found {view.numbers.count()}")
            # An explorer given the student's filter runs it on every move, and says so.
            students = "filter=" in sources[number - 1]
            for description, slider in iter_sliders(view):
                exercise_slider(view, slider,
                                f"{notebook.name}, explorer {number}, slider {description!r}")
                if students:
                    line = view.numbers.inner_text()
                    assert STUDENTS_FILTER in line.lower(), (
                        f"{notebook.name}, explorer {number}: after moving {description!r} "
                        f"the numbers line does not say it ran {STUDENTS_FILTER}: {line!r}")
            view.output.screenshot(path=screenshot_path(f"{notebook.stem}-explorer-{number}"))

        problems = error_outputs(page, panel)
        assert not problems, (f"{notebook.name} shows error output after the slider moves:\n"
                              + "\n---\n".join(problems))
        page.screenshot(path=screenshot_path(notebook.stem))
        assert not page.log, f"{notebook.name}: the browser logged errors"
