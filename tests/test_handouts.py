"""HTML handouts: one offline page per notebook, figures embedded, explorers static.

The handouts of a small fixture folder and of ``notebooks/`` are each built once per
test session (every notebook executed fresh once); the tests parse the pages.
"""

from __future__ import annotations

import base64
import hashlib
import re
from pathlib import Path

import nbformat
import pytest
from bs4 import BeautifulSoup
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

from lqe_helpers import handouts
from lqe_helpers.student_edition import EXPLORER_TAG

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"
REAL = sorted(path.stem for path in NOTEBOOKS.glob("*.ipynb"))
KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
IMAGE_TYPES = ("image/png", "image/jpeg", "image/svg+xml")

# A 1×1 PNG for a markdown image that must be embedded.
PIXEL = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNk+M9QDwADhgGAWjR9awAAAABJRU5ErkJggg=="
)
MATH_INLINE = r"P(k+1) = F P F^\top + G \sigma^2 G^\top"
MATH_DISPLAY = r"\hat z(k+1 \mid k) = A \hat z(k \mid k) < 1"
CELLS = [
    new_markdown_cell(f"# Fixture handout\n\nPrediction: ${MATH_INLINE}$.\n\n$${MATH_DISPLAY}$$\n\n"
                      "![a pixel](pixel.png)"),
    new_code_cell("import matplotlib.pyplot as plt\nimport numpy as np"),
    new_code_cell("fig, ax = plt.subplots()\nax.plot(np.arange(3), label='truth')\nplt.show()\n"
                  "print('printed result 0.383')", metadata={"tags": ["solution"]}),
    new_code_cell("print('hidden helper text')", metadata={"tags": ["remove-cell"]}),
    new_code_cell(
        "from lqe_helpers.explorer import Explorer, float_slider\n\n\n"
        "def draw(figure, *, a):\n"
        "    figure.clear()\n"
        "    figure.add_subplot().plot([0, 1], [0, a], label='line')\n\n\n"
        "Explorer('A line', {'a': float_slider('a (cm)', 1.0, 0.0, 2.0, 0.1)}, draw)",
        metadata={"tags": ["explorer", "nbval-ignore-output"]},
    ),
]


def write_fixture(folder: Path, name: str = "01_fixture", cells=CELLS) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "pixel.png").write_bytes(PIXEL)
    path = folder / f"{name}.ipynb"
    nbformat.write(new_notebook(cells=list(cells), metadata={"kernelspec": KERNELSPEC}), path)
    return path


def soup(path: Path) -> BeautifulSoup:
    return BeautifulSoup(path.read_text(encoding="utf-8"), "html.parser")


def output_figures(notebook: nbformat.NotebookNode) -> int:
    """How many figure outputs (any image mimetype) the notebook's cells hold."""
    return sum(
        any(kind in output.get("data", {}) for kind in IMAGE_TYPES)
        for cell in notebook.cells
        for output in cell.get("outputs", [])
    )


def math_in(notebook: nbformat.NotebookNode) -> list[str]:
    """The LaTeX source of every $...$ / $$...$$ span in the markdown cells."""
    spans = []
    for cell in notebook.cells:
        if cell.cell_type == "markdown":
            spans += re.findall(r"\$\$(.+?)\$\$", cell.source, flags=re.S)
            spans += re.findall(r"(?<!\$)\$([^$\n]+)\$(?!\$)", cell.source)
    return spans


def squash(text: str) -> str:
    return " ".join(text.split())


def assert_offline(page: BeautifulSoup, mathjax_url: str) -> None:
    """Figures embedded; the only remote resource is MathJax, loaded without blocking."""
    images = page.find_all("img")
    for image in images:
        assert image["src"].startswith("data:image/"), image["src"][:80]
    for script in page.find_all("script", src=True):
        assert script["src"] == mathjax_url, script["src"]
        assert script.has_attr("async")
    for tag in page.find_all(["link", "iframe", "embed", "object", "source", "video", "audio"]):
        for attribute in ("href", "src", "data"):
            assert not str(tag.get(attribute, "")).startswith(("http:", "https:", "//")), tag
    for style in page.find_all("style"):
        css = style.get_text()
        assert not re.search(r"@import|url\(\s*['\"]?(https?:)?//", css), css[:80]


def assert_no_error_or_widget(page: BeautifulSoup) -> None:
    html = str(page)
    assert page.select('[data-mime-type="application/vnd.jupyter.stderr"]') == []
    assert "Traceback" not in page.get_text()
    assert WIDGET_VIEW not in html
    assert "widget-state" not in html
    for text in ("Loading widgets", "Interactive explorer:", "VBox(", "FloatSlider("):
        assert text not in page.get_text()


# ---------------------------------------------------------------- the fixture


@pytest.fixture(scope="session")
def fixture_build(tmp_path_factory):
    source = tmp_path_factory.mktemp("handout_source")
    write_fixture(source, "01_fixture")
    write_fixture(source, "02_fixture_again")
    before = {path.name: hashlib.sha256(path.read_bytes()).digest() for path in source.iterdir()}
    out = tmp_path_factory.mktemp("handouts")
    written = handouts.build_handouts(source, out)
    after = {path.name: hashlib.sha256(path.read_bytes()).digest() for path in source.iterdir()}
    assert after == before, "building handouts must not touch the source folder"
    return out, written


def test_fixture_pages_and_layout(fixture_build):
    out, written = fixture_build
    assert written == [out / "01_fixture.html", out / "02_fixture_again.html", out / "index.html",
                       out / "prose" / "01_fixture.html", out / "prose" / "02_fixture_again.html",
                       out / "prose" / "index.html"]
    assert all(path.is_file() for path in written)


@pytest.mark.parametrize("variant", ["", "prose/"])
def test_fixture_page_content(fixture_build, variant):
    out, _ = fixture_build
    page = soup(out / variant / "01_fixture.html")
    assert_offline(page, handouts.DEFAULT_MATHJAX_URL)
    assert_no_error_or_widget(page)
    assert page.title.get_text() == "Fixture handout"
    text = squash(page.get_text())

    # Three embedded images: the markdown pixel, the matplotlib figure, the explorer.
    sources = [image["src"] for image in page.find_all("img")]
    assert len(sources) == 3
    assert f"data:image/png;base64,{base64.b64encode(PIXEL).decode()}" in sources
    [explorer] = page.select("figure.lqe-explorer")
    assert explorer.img["src"].startswith("data:image/png;base64,")
    assert "JupyterLab" in explorer.figcaption.get_text()

    # LaTeX survives as readable text for when MathJax cannot load.
    assert squash(MATH_INLINE) in text
    assert squash(MATH_DISPLAY) in text
    assert "printed result 0.383" in text
    assert "hidden helper text" not in text  # remove-cell tag honoured

    code_cells = page.select(".jp-CodeCell .jp-InputArea")
    if variant:
        assert code_cells == []
        assert "import numpy" not in text
        assert "In [" not in text
    else:
        assert len(code_cells) == 3
        assert "import numpy as np" in text


@pytest.mark.parametrize("variant", ["", "prose/"])
def test_fixture_index_and_navigation(fixture_build, variant):
    out, _ = fixture_build
    index = soup(out / variant / "index.html")
    pages = ["01_fixture.html", "02_fixture_again.html"]
    assert [a["href"] for a in index.select("ol a")] == pages
    other = "../index.html" if variant else "prose/index.html"
    assert [a["href"] for a in index.select("p a")] == [other]
    first = soup(out / variant / pages[0])
    assert [a["href"] for a in first.select("nav.lqe-nav")[0].find_all("a")] == [
        "index.html", pages[1]]
    second = soup(out / variant / pages[1])
    assert [a["href"] for a in second.select("nav.lqe-nav")[0].find_all("a")] == [
        pages[0], "index.html"]


def test_without_mathjax_there_is_no_script_at_all(tmp_path):
    write_fixture(tmp_path / "src", cells=CELLS[:1])
    written = handouts.build_handouts(tmp_path / "src", tmp_path / "out", mathjax_url="")
    for path in written:
        assert soup(path).find_all("script", src=True) == []


def test_a_notebook_that_raises_stops_the_build(tmp_path):
    write_fixture(tmp_path / "src", "03_broken", [new_code_cell("1 / 0")])
    expected = r"03_broken\.ipynb: a cell raised ZeroDivisionError"
    with pytest.raises(handouts.HandoutBuildError, match=expected):
        handouts.build_handouts(tmp_path / "src", tmp_path / "out")


def test_an_allowed_error_still_stops_the_build(tmp_path):
    cell = new_code_cell("raise KeyError('boom')", metadata={"tags": ["raises-exception"]})
    write_fixture(tmp_path / "src", "04_shows_error", [cell])
    with pytest.raises(handouts.HandoutBuildError, match="cell 0: KeyError"):
        handouts.build_handouts(tmp_path / "src", tmp_path / "out")


def test_bad_folders_are_refused(tmp_path):
    with pytest.raises(ValueError, match=r"at least one \.ipynb"):
        handouts.build_handouts(tmp_path, tmp_path / "out")
    write_fixture(tmp_path / "src", cells=CELLS[:1])
    with pytest.raises(ValueError, match="out_dir must differ"):
        handouts.build_handouts(tmp_path / "src", tmp_path / "src")


def test_exporter_never_picks_the_widget_view():
    exporter = handouts.handout_exporter()
    assert WIDGET_VIEW not in exporter.config.NbConvertBase.display_data_priority
    bundle = {WIDGET_VIEW: {"model_id": "x", "version_major": 2, "version_minor": 0},
              "text/html": "<p>static</p>", "text/plain": "Explorer"}
    notebook = new_notebook(cells=[new_code_cell("e", outputs=[nbformat.v4.new_output(
        "display_data", data=bundle)])])
    # Even with widget state present the static view is chosen.
    notebook.metadata["widgets"] = {"application/vnd.jupyter.widget-state+json": {
        "state": {"x": {}}, "version_major": 2, "version_minor": 0}}
    html, _ = exporter.from_notebook_node(notebook, {"metadata": {"name": "w"}})
    assert "<p>static</p>" in html
    assert 'type="application/vnd.jupyter.widget-view+json"' not in html
    assert "unpkg" not in html


def test_notebook_title_falls_back_to_the_file_name():
    notebook = new_notebook(cells=[new_markdown_cell("no heading"),
                                   new_markdown_cell("## A sub heading\n# Main")])
    assert handouts.notebook_title(notebook, "x") == "Main"
    assert handouts.notebook_title(new_notebook(
        cells=[new_markdown_cell("### Only a sub heading")]), "x") == "Only a sub heading"
    assert handouts.notebook_title(new_notebook(), "05_name") == "05_name"


# --------------------------------------------------------- the pack's notebooks


@pytest.fixture(scope="session")
def pack_build(tmp_path_factory):
    if not REAL:
        pytest.skip("no notebooks in notebooks/")
    out = tmp_path_factory.mktemp("pack_handouts")
    return out, handouts.build_handouts(NOTEBOOKS, out)


def test_every_notebook_has_both_pages_and_an_index(pack_build):
    out, written = pack_build
    expected = [out / f"{stem}.html" for stem in REAL] + [out / "index.html"]
    expected += [out / "prose" / path.name for path in expected]
    assert written == expected
    for variant in ("", "prose/"):
        index = soup(out / variant / "index.html")
        assert [a["href"] for a in index.select("ol a")] == [f"{stem}.html" for stem in REAL]


@pytest.mark.parametrize("variant", ["", "prose/"])
@pytest.mark.parametrize("stem", REAL)
def test_pack_page(pack_build, stem, variant):
    out, _ = pack_build
    page = soup(out / variant / f"{stem}.html")
    source = nbformat.read(NOTEBOOKS / f"{stem}.ipynb", as_version=4)
    assert_offline(page, handouts.DEFAULT_MATHJAX_URL)
    assert_no_error_or_widget(page)

    # Every figure of the committed notebook is in the page (explorers included).
    explorers = sum(EXPLORER_TAG in cell.metadata.get("tags", []) for cell in source.cells)
    in_outputs = [image for image in page.find_all("img")
                  if image.find_parent(class_="jp-OutputArea-output")]
    assert len(in_outputs) >= max(output_figures(source), explorers)
    statics = page.select("figure.lqe-explorer")
    assert len(statics) == explorers
    for figure in statics:
        assert "JupyterLab" in figure.figcaption.get_text()

    text = squash(page.get_text())
    for span in math_in(source):
        assert squash(span) in text, span
    if variant:
        assert page.select(".jp-CodeCell .jp-InputArea") == []
