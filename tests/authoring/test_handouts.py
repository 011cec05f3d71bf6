"""HTML handouts: one offline page per notebook, figures embedded, explorers static.

The handouts of a small fixture folder are built once per test session, and those of
``notebooks/`` once per test run (the ``handouts_build`` artefact of tests/artefacts.py,
shared with the browser tests); the tests parse the pages. The page checks are plain
functions; a few tests feed them broken HTML to show that they can fail. Tests that build
handouts execute notebooks: they are marked ``kernel``.
"""

from __future__ import annotations

import base64
import errno
import hashlib
import re
from collections import Counter
from pathlib import Path
from urllib.parse import unquote, urlsplit

import nbformat
import pytest
import soupsieve
from bs4 import BeautifulSoup
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

from lqe_helpers.authoring import files, handout_pages, handouts
from lqe_helpers.authoring.errors import OutputFolderError, OutputWriteError
from lqe_helpers.authoring.manifest import MANIFEST_NAME
from lqe_helpers.authoring.notebook_io import read_notebook
from lqe_helpers.authoring.task_cells import EXPLORER_TAG

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"
REAL = sorted(path.stem for path in NOTEBOOKS.glob("*.ipynb"))
KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
IMAGE_TYPES = ("image/png", "image/jpeg", "image/svg+xml")
REMOVE_TAGS = {"remove-cell"}
# What a page shows of a code cell's input (the prose variant shows none of it).
CODE_INPUT = ".jp-CodeCell .jp-InputArea, .jp-InputPrompt, .jp-OutputPrompt"

# A 1×1 PNG for a markdown image that must be embedded.
PIXEL = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNk+M9QDwADhgGAWjR9awAAAABJRU5ErkJggg=="
)
MATH_INLINE = r"P(k+1) = F P F^\top + G \sigma^2 G^\top"
MATH_DISPLAY = r"\hat z(k+1 \mid k) = A \hat z(k \mid k) < 1"
CELLS = [
    new_markdown_cell(f"# Fixture handout\n\nPrediction: ${MATH_INLINE}$.\n\n$${MATH_DISPLAY}$$\n\n"
                      "![a pixel](pixel.png)\n\nNext: [the other page](02_fixture_again.ipynb#Top),"
                      " [elsewhere](99_not_built.ipynb)."),
    new_code_cell("import matplotlib.pyplot as plt\nimport numpy as np"),
    new_code_cell("fig, ax = plt.subplots()\nax.plot(np.arange(3), label='truth')\nplt.show()\n"
                  "print('printed result 0.383')", metadata={"tags": ["solution"]},
                  outputs=[new_output("stream", name="stdout", text="stale output of a past run")]),
    new_code_cell("print('hidden helper text')", metadata={"tags": ["remove-cell"]}),
    new_code_cell(
        "from lqe_helpers.explorers import Explorer, float_slider\n\n\n"
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


def tags(cell: nbformat.NotebookNode) -> set[str]:
    return set(cell.get("metadata", {}).get("tags", []))


def output_figures(notebook: nbformat.NotebookNode) -> int:
    """How many figure outputs (any image mimetype) the notebook's cells hold."""
    return sum(
        any(kind in output.get("data", {}) for kind in IMAGE_TYPES)
        for cell in notebook.cells
        for output in cell.get("outputs", [])
    )


def delimited_math(text: str) -> list[str]:
    """Every ``$$...$$`` and ``$...$`` span of ``text`` (delimiters kept, spaces squashed)."""
    text = " ".join(text.split())
    return (re.findall(r"\$\$.+?\$\$", text)
            + re.findall(r"(?<!\$)\$[^$]+\$(?!\$)", re.sub(r"\$\$.+?\$\$", " ", text)))


def math_in(notebook: nbformat.NotebookNode) -> Counter:
    """How often each LaTeX span (with its delimiters) occurs in the markdown cells."""
    return Counter(span for cell in notebook.cells if cell.cell_type == "markdown"
                   for span in delimited_math(cell.source))


def squash(text: str) -> str:
    return " ".join(text.split())


def local_mathjax(variant: str) -> str:
    """The src of the local MathJax script on a page of ``variant`` ("" or "prose/")."""
    return handout_pages.mathjax_url(variant.count("/"))


def assert_offline(page: BeautifulSoup, mathjax_url: str) -> None:
    """Figures embedded; the one script is the local MathJax ``mathjax_url``, async."""
    images = page.find_all("img")
    for image in images:
        assert image["src"].startswith("data:image/"), image["src"][:80]
    for script in page.find_all("script", src=True):
        assert script["src"] == mathjax_url, script["src"]
        assert script.has_attr("async")
    for tag in page.find_all(["link", "iframe", "embed", "object", "source", "video", "audio",
                              "image", "use"]):
        for attribute in ("href", "src", "data", "xlink:href"):
            assert not str(tag.get(attribute, "")).startswith(("http:", "https:", "//")), tag
    for style in [*page.find_all("style"), *page.find_all(style=True)]:
        css = style.get_text() if style.name == "style" else style["style"]
        assert not re.search(r"@import|url\(\s*['\"]?(https?:)?//", css), css[:80]


def assert_no_error_or_widget(page: BeautifulSoup) -> None:
    html = str(page)
    assert page.select('[data-mime-type="application/vnd.jupyter.stderr"]') == []
    assert page.select(".jp-OutputArea-output.jp-mod-error, .output_error") == []
    assert "Traceback" not in page.get_text()
    assert WIDGET_VIEW not in html
    assert "widget-state" not in html
    for text in ("Loading widgets", "Interactive explorer:", "VBox(", "FloatSlider(",
                 "Error displaying widget", "model not found"):
        assert text not in page.get_text()


# Declarations that take an element (and its text) off the screen.
_HIDING = re.compile(r"(?<![-\w])(?:display\s*:\s*none|visibility\s*:\s*hidden|"
                     r"(?:font-size|opacity)\s*:\s*0(?![.\d]))")
_INVISIBLE_PARENTS = {"script", "style", "template", "noscript", "head", "title", "textarea"}


def hidden_elements(page: BeautifulSoup) -> list:
    """Elements that the page's own CSS or attributes hide (states such as :hover aside)."""
    hidden = [element for element in page.find_all(True)
              if element.has_attr("hidden") or element.get("aria-hidden") == "true"
              or _HIDING.search(element.get("style", ""))]
    for style in page.find_all("style"):
        for selectors, body in re.findall(r"([^{}]+)\{([^{}]*)\}", style.get_text()):
            if not _HIDING.search(body):
                continue
            for selector in selectors.split(","):
                try:
                    hidden += page.select(selector.strip())
                except (soupsieve.SelectorSyntaxError, NotImplementedError):
                    continue  # a pseudo-element (::before): generated content, not the page's
    return hidden


def visible_math(page: BeautifulSoup) -> Counter:
    """The LaTeX spans in text nodes that no tag, attribute or CSS rule keeps off the screen."""
    hidden = {id(element) for element in hidden_elements(page)}
    found = Counter()
    for node in page.find_all(string=True):
        if not any(parent.name in _INVISIBLE_PARENTS or id(parent) in hidden
                   for parent in node.parents):
            found.update(delimited_math(node))
    return found


def assert_visible_math(page: BeautifulSoup, expected: Counter) -> None:
    """Every LaTeX span of the source is on the page as visible text, as often as in the source.

    This is what a reader sees when MathJax cannot load: the LaTeX source as text.
    """
    assert expected, "no equation to look for"
    missing = expected - visible_math(page)
    assert not missing, f"LaTeX not visible as text: {sorted(missing)[:5]}"


def assert_local_links_resolve(page: BeautifulSoup, folder: Path) -> None:
    """Every link to a file next to the page points at a file that exists."""
    for anchor in page.find_all("a", href=True):
        parts = urlsplit(anchor["href"])
        if parts.scheme or parts.netloc or not parts.path:
            continue  # remote, or a fragment within the page
        assert (folder / unquote(parts.path)).is_file(), anchor["href"]


def code_lines(notebook: nbformat.NotebookNode) -> set[str]:
    """Distinctive code lines of the notebook: long, and not quoted in any markdown cell."""
    prose = "\n".join(cell.source for cell in notebook.cells if cell.cell_type == "markdown")
    return {line.strip() for cell in notebook.cells if cell.cell_type == "code"
            and not tags(cell) & REMOVE_TAGS for line in cell.source.splitlines()
            if len(line.strip()) >= 20 and line.strip() not in prose}


# ------------------------------------------------- the checks themselves can fail


def html(body: str, head: str = "") -> BeautifulSoup:
    return BeautifulSoup(f"<html><head>{head}</head><body>{body}</body></html>", "html.parser")


@pytest.mark.parametrize("body", [
    '<p>$x$</p><img src="figure.png">',
    '<img src="https://example.org/figure.png">',
    '<link rel="stylesheet" href="https://example.org/a.css">',
    '<style>@import url("https://fonts.example.org/a.css");</style>',
    '<script src="https://example.org/other.js" async></script>',
    '<script src="https://cdn.example/mathjax.js"></script>',
])
def test_the_offline_check_can_fail(body):
    with pytest.raises(AssertionError):
        assert_offline(html(body), "https://cdn.example/mathjax.js")


@pytest.mark.parametrize("body", [
    '<div data-mime-type="application/vnd.jupyter.stderr">warning</div>',
    "<pre>Traceback (most recent call last)</pre>",
    f'<script type="{WIDGET_VIEW}">{{"model_id": "x"}}</script>',
    "<pre>VBox(children=(FloatSlider(value=1.0),))</pre>",
])
def test_the_error_and_widget_check_can_fail(body):
    with pytest.raises(AssertionError):
        assert_no_error_or_widget(html(body))


@pytest.mark.parametrize(("body", "head"), [
    ("<p>no math here</p>", ""),
    ('<div class="m"><p>$x^2$</p></div>', "<style>.m p { color: red; display: none }</style>"),
    ('<div class="a"><p>$x^2$</p></div>', "<style>@media screen {.b, .a {visibility:hidden}}"
                                          "</style>"),
    ("<p hidden>$x^2$</p>", ""),
    ('<p style="font-size: 0">$x^2$</p>', ""),
    ('<script type="math/tex">$x^2$</script>', ""),
    ("<p>x^2</p>", "<title>$x^2$</title>"),
])
def test_the_visible_math_check_can_fail(body, head):
    expected = Counter({"$x^2$": 1})
    with pytest.raises(AssertionError):
        assert_visible_math(html(body, head), expected)
    shown = html("<main><p>$x^2$</p></main>", "<title>$x^2$</title><style>p:hover {display: none}"
                 "</style>")
    assert visible_math(shown) == expected
    assert_visible_math(shown, expected)
    with pytest.raises(AssertionError):
        assert_visible_math(shown, Counter({"$x^2$": 2}))


def test_the_link_check_can_fail(tmp_path):
    (tmp_path / "a.html").write_text("")
    assert_local_links_resolve(html('<a href="a.html#x">a</a><a href="#y">y</a>'
                                    '<a href="https://example.org">e</a>'), tmp_path)
    with pytest.raises(AssertionError):
        assert_local_links_resolve(html('<a href="b.ipynb">b</a>'), tmp_path)


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


@pytest.mark.kernel
def test_fixture_pages_and_layout(fixture_build):
    out, written = fixture_build
    assert written == [out / "01_fixture.html", out / "02_fixture_again.html", out / "index.html",
                       out / "prose" / "01_fixture.html", out / "prose" / "02_fixture_again.html",
                       out / "prose" / "index.html"]
    mathjax = out / handout_pages.MATHJAX_DIR
    assert mathjax.is_dir() and (mathjax / "MathJax.js").is_file()
    rest = [path for path in out.rglob("*") if mathjax not in path.parents and path != mathjax]
    assert sorted(rest) == sorted([*written, out / "prose", out / MANIFEST_NAME])


@pytest.mark.kernel
@pytest.mark.parametrize("variant", ["", "prose/"])
def test_fixture_page_content(fixture_build, variant):
    out, _ = fixture_build
    page = soup(out / variant / "01_fixture.html")
    assert_offline(page, local_mathjax(variant))
    assert_no_error_or_widget(page)
    assert page.title.get_text() == "Fixture handout"
    text = squash(page.get_text())

    # Three embedded images: the markdown pixel, the matplotlib figure, the explorer.
    sources = [image["src"] for image in page.find_all("img")]
    assert len(sources) == 3
    assert f"data:image/png;base64,{base64.b64encode(PIXEL).decode()}" in sources
    [explorer] = page.select("figure.lqe-explorer")
    assert explorer.img["src"].startswith("data:image/png;base64,")
    assert "default values" in explorer.figcaption.get_text()
    assert "JupyterLab" in explorer.figcaption.get_text()

    # LaTeX survives as visible text for when MathJax cannot load.
    assert_visible_math(page, Counter({f"${MATH_INLINE}$": 1, f"$${MATH_DISPLAY}$$": 1}))
    assert visible_math(page) == math_in(new_notebook(cells=CELLS))
    # Executed afresh: the new output, not the one saved in the notebook.
    assert "printed result 0.383" in text
    assert "stale output" not in text
    assert "hidden helper text" not in text  # remove-cell tag honoured
    # A link to a notebook that has a page goes to the page; any other is left alone.
    hrefs = [a["href"] for a in page.select(".jp-MarkdownCell a")
             if "anchor-link" not in a.get("class", [])]
    assert hrefs == ["02_fixture_again.html#Top", "99_not_built.ipynb"]

    code_cells = page.select(".jp-CodeCell .jp-InputArea")
    if variant:
        assert page.select(CODE_INPUT) == []
        assert "import numpy" not in text
        assert "In [" not in text
    else:
        assert len(code_cells) == 3
        assert "import numpy as np" in text


@pytest.mark.kernel
@pytest.mark.parametrize("variant", ["", "prose/"])
def test_fixture_index_and_navigation(fixture_build, variant):
    out, _ = fixture_build
    index = soup(out / variant / "index.html")
    pages = ["01_fixture.html", "02_fixture_again.html"]
    assert [a["href"] for a in index.select("ol a")] == pages
    assert [a.get_text() for a in index.select("ol a")] == ["Fixture handout"] * 2
    other = "../index.html" if variant else "prose/index.html"
    assert [a["href"] for a in index.select("p a")] == [other]
    first = soup(out / variant / pages[0])
    assert [a["href"] for a in first.select("nav.lqe-nav")[0].find_all("a")] == [
        "index.html", pages[1]]
    second = soup(out / variant / pages[1])
    assert [a["href"] for a in second.select("nav.lqe-nav")[0].find_all("a")] == [
        pages[0], "index.html"]
    assert_local_links_resolve(index, out / variant)


@pytest.mark.kernel
def test_without_mathjax_there_is_no_script_at_all(tmp_path):
    write_fixture(tmp_path / "src", cells=CELLS[:1])
    written = handouts.build_handouts(tmp_path / "src", tmp_path / "out", mathjax_url="")
    for path in written:
        assert soup(path).find_all("script", src=True) == []
    assert_visible_math(soup(written[0]), Counter({f"${MATH_INLINE}$": 1,
                                                    f"$${MATH_DISPLAY}$$": 1}))


BROKEN = [new_markdown_cell("# Broken"), new_code_cell("x = 1"),
          new_code_cell("def ratio():\n    return x / 0\n\n\nratio()"),
          new_code_cell("print('after the error')")]


@pytest.mark.kernel
def test_a_notebook_that_raises_stops_the_build_naming_the_cell(tmp_path):
    write_fixture(tmp_path / "src", "03_broken", BROKEN)
    out = tmp_path / "out"
    (out / "prose").mkdir(parents=True)
    (out / "01_old.html").write_text("old page")
    (out / "prose" / "01_old.html").write_text("old page")
    before = sorted(out.rglob("*"))
    with pytest.raises(handouts.HandoutBuildError) as error:
        handouts.build_handouts(tmp_path / "src", out)
    message = str(error.value)
    assert ("03_broken.ipynb shows error output(s): cell 2: ZeroDivisionError: division by zero"
            in message)
    # The traceback, as plain text, down to the line that raised.
    traceback = message.split("Traceback of the first, cell 2:\n", 1)[1]
    assert "ZeroDivisionError" in traceback
    assert "ratio()" in traceback
    assert re.search(r"-+> 2\s+return x / 0", traceback), traceback
    assert "\x1b[" not in message
    assert sorted(out.rglob("*")) == before, "a failed build must write and delete nothing"


@pytest.mark.kernel
def test_an_allowed_error_still_stops_the_build(tmp_path):
    cell = new_code_cell("raise KeyError('boom')", metadata={"tags": ["raises-exception"]})
    write_fixture(tmp_path / "src", "04_shows_error", [cell])
    with pytest.raises(handouts.HandoutBuildError, match="cell 0: KeyError"):
        handouts.build_handouts(tmp_path / "src", tmp_path / "out")


@pytest.mark.kernel
def test_a_bare_widget_stops_the_build(tmp_path):
    cells = [new_code_cell("import ipywidgets\nipywidgets.IntSlider(description='n')")]
    write_fixture(tmp_path / "src", "05_bare_widget", cells)
    with pytest.raises(handouts.HandoutBuildError, match=r"no static view.*cell 0: IntSlider"):
        handouts.build_handouts(tmp_path / "src", tmp_path / "out")


@pytest.mark.kernel
def test_stderr_is_reported(tmp_path):
    cells = [new_code_cell("import sys\nprint('careful: deprecated', file=sys.stderr)")]
    write_fixture(tmp_path / "src", "06_warns", cells)
    with pytest.warns(handouts.HandoutWarning, match=r"06_warns\.ipynb.*cell 0: careful"):
        handouts.build_handouts(tmp_path / "src", tmp_path / "out")


@pytest.mark.parametrize(("data", "fault"), [
    ("not base64 at all!", "its data is not base64 text"),
    ("", "it is empty (0 bytes)"),
    (base64.b64encode(b"GIF89a" + bytes(30)).decode(), "its 36 bytes are not a PNG"),
    (base64.b64encode(PIXEL[:-12]).decode(), "its 58 bytes are not a valid PNG (truncated"),
    (base64.b64encode(PIXEL[:-8] + b"\0\0\0\0" + PIXEL[-4:]).decode(),
     "its 70 bytes are not a valid PNG (broken PNG file"),
])
def test_a_broken_png_output_stops_the_build_naming_notebook_and_cell(tmp_path, monkeypatch,
                                                                      capsys, data, fault):
    """Issue 27: an image/png output that is no PNG passed the build (a broken picture)."""
    broken = new_output("display_data", data={"image/png": data, "text/plain": "<Figure>"},
                        metadata={"image/png": {"alt": "A figure."}})
    cells = [new_markdown_cell("# Broken"), new_code_cell("show()", outputs=[broken])]
    path = write_fixture(tmp_path / "src", "01_broken", cells)
    monkeypatch.setattr(handouts, "execute_notebook",
                        lambda path, timeout=None, allow_errors=False: read_notebook(path))
    assert handouts.main(["--source", str(tmp_path / "src"), "--out", str(tmp_path / "out"),
                          "--mathjax-url", ""]) == 1
    [line] = capsys.readouterr().err.splitlines()
    assert line.startswith(f"error: {path} shows image/png output(s) that are not a valid "
                           f"PNG, which its page could not show: cell 1: {fault}"), line
    assert not (tmp_path / "out").exists()


def test_bad_folders_are_refused_before_any_notebook_runs(tmp_path, monkeypatch):
    with pytest.raises(ValueError, match=r"at least one \.ipynb"):
        handouts.build_handouts(tmp_path, tmp_path / "out")
    source = tmp_path / "C" / "drafts"
    write_fixture(source, cells=CELLS[:1])
    (tmp_path / "file").write_text("a file")
    before = snapshot(tmp_path)
    monkeypatch.setattr(handouts, "execute_notebook", fail_if_called)
    for out, message in [(source, "is the source folder"),
                         (source / "pages", "lies inside the source folder"),
                         (tmp_path / "C", "contains the source folder"),
                         (tmp_path / "file", "is a file; give a folder")]:
        with pytest.raises(OutputFolderError, match=message):
            handouts.build_handouts(source, out)
    assert snapshot(tmp_path) == before


def fail_if_called(*args, **kwargs):
    raise AssertionError("a notebook was executed although the output folder was refused")


def snapshot(folder: Path) -> dict[str, bytes | str]:
    """Every file (its bytes), link (its target) and folder under ``folder``."""
    return {path.relative_to(folder).as_posix():
            (f"link -> {path.readlink()}" if path.is_symlink()
             else "folder" if path.is_dir() else path.read_bytes())
            for path in sorted(folder.rglob("*"))}


@pytest.mark.kernel
def test_a_rebuild_replaces_only_its_own_pages(tmp_path):
    """The issue's case: course_home.html kept, the stale page of a renamed notebook gone."""
    source, out = tmp_path / "src", tmp_path / "out"
    old = write_fixture(source, "00_renamed", cells=CELLS[:1])
    handouts.build_handouts(source, out, mathjax_url="")
    mine = {out / "course_home.html": "the instructor's own page",
            out / "prose" / "style.css": "mine", out / "extra" / "page.html": "mine",
            out / "00_renamed.ipynb": "mine"}
    for path, text in mine.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    old.rename(source / "01_fixture.ipynb")
    written = handouts.build_handouts(source, out, mathjax_url="")
    assert [path.relative_to(out).as_posix() for path in written] == [
        "01_fixture.html", "index.html", "prose/01_fixture.html", "prose/index.html"]
    assert all(path.read_text() == text for path, text in mine.items())
    assert sorted(path for path in out.rglob("*") if path.is_file()) == sorted(
        [*written, *mine, out / MANIFEST_NAME])  # both 00_renamed.html pages are gone


def test_an_index_it_did_not_write_stops_the_build(tmp_path, monkeypatch):
    """The issue's case: an instructor's index.html is never overwritten."""
    write_fixture(tmp_path / "src", cells=CELLS[:1])
    out = tmp_path / "out"
    (out / "prose").mkdir(parents=True)
    (out / "index.html").write_text("the instructor's index")
    (out / "course_home.html").write_text("the instructor's own page")
    before = snapshot(out)
    monkeypatch.setattr(handouts, "execute_notebook", fail_if_called)
    with pytest.raises(OutputFolderError, match=r"index\.html was not written by handouts"):
        handouts.build_handouts(tmp_path / "src", out)
    assert snapshot(out) == before


@pytest.mark.kernel
def test_a_full_disk_while_writing_pages_changes_nothing(tmp_path, monkeypatch):
    write_fixture(tmp_path / "src", cells=CELLS[:1])
    out = tmp_path / "out"
    handouts.build_handouts(tmp_path / "src", out, mathjax_url="")
    (out / "course_home.html").write_text("mine")
    before = snapshot(tmp_path)
    real = files._write_fd
    calls = []

    def full_disk(fd: int, data: bytes) -> None:
        calls.append(len(data))
        if len(calls) == 3:  # the third page: half of it, then the disk is full
            real(fd, data[:len(data) // 2])
            raise OSError(errno.ENOSPC, "No space left on device")
        real(fd, data)

    monkeypatch.setattr(files, "_write_fd", full_disk)
    with pytest.raises(OutputWriteError, match="No space left on device"):
        handouts.build_handouts(tmp_path / "src", out, mathjax_url="x.js")
    assert len(calls) == 3
    assert snapshot(tmp_path) == before


@pytest.mark.kernel
def test_names_with_spaces_and_accents_link_from_the_index(tmp_path):
    source = tmp_path / "src"
    names = ["01 first page", "02 café ΔΣ", "03 #hash?"]
    for name in names:
        write_fixture(source, name, cells=[new_markdown_cell(f"# Page {name}")])
    out = tmp_path / "out"
    written = handouts.build_handouts(source, out, mathjax_url="")
    assert {path.name for path in written} == {f"{name}.html" for name in names} | {"index.html"}
    for folder in (out, out / "prose"):
        index = soup(folder / "index.html")
        hrefs = [anchor["href"] for anchor in index.select("main a[href], body a[href]")
                 if anchor["href"].endswith(".html") and "index" not in anchor["href"]]
        assert hrefs == ["01%20first%20page.html", "02%20caf%C3%A9%20%CE%94%CE%A3.html",
                         "03%20%23hash%3F.html"]
        assert_local_links_resolve(index, folder)
        # The pages' previous/next links too.
        assert_local_links_resolve(soup(folder / "02 café ΔΣ.html"), folder)
    assert handouts.Page("02 café ΔΣ", "t").href == "02%20caf%C3%A9%20%CE%94%CE%A3.html"


@pytest.mark.kernel
def test_command_line(tmp_path, capsys):
    write_fixture(tmp_path / "src", cells=CELLS[:1])
    out = tmp_path / "out"
    assert handouts.main(["--source", str(tmp_path / "src"), "--out", str(out),
                          "--mathjax-url", ""]) == 0
    assert capsys.readouterr().out.split() == [
        str(out / name) for name in ("01_fixture.html", "index.html", "prose/01_fixture.html",
                                     "prose/index.html")]
    write_fixture(tmp_path / "src", "02_broken", BROKEN)
    before = snapshot(out)
    assert handouts.main(["--source", str(tmp_path / "src"), "--out", str(out)]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    [line] = captured.err.splitlines()
    assert line.startswith(f"error: {tmp_path / 'src' / '02_broken.ipynb'} shows error "
                           "output(s): cell 2: ZeroDivisionError: division by zero")
    assert line.endswith(" (--verbose shows the rest)")
    assert snapshot(out) == before
    # --verbose adds the traceback, down to the line that raised.
    assert handouts.main(["--source", str(tmp_path / "src"), "--out", str(out),
                          "--verbose"]) == 1
    assert "return x / 0" in capsys.readouterr().err
    # Bad input: the same exit code and one "error:" line, no usage message.
    assert handouts.main(["--source", str(tmp_path / "missing"), "--out", str(out)]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (f"error: source_dir must be an existing folder, got "
                            f"{tmp_path / 'missing'}\n")


@pytest.mark.slow
@pytest.mark.kernel
def test_a_cell_past_the_time_limit_is_one_error_line(tmp_path, capsys):
    cells = [new_code_cell("import time\nwhile True:\n    time.sleep(0.1)")]
    write_fixture(tmp_path / "src", "01_endless", cells)
    assert handouts.main(["--source", str(tmp_path / "src"), "--out", str(tmp_path / "out"),
                          "--timeout", "2"]) == 1
    [line] = capsys.readouterr().err.splitlines()
    assert line.startswith(f"error: {tmp_path / 'src' / '01_endless.ipynb'}: cell 0 (import "
                           f"time) ran longer than the time limit of 2 s per cell (--timeout)")
    assert not (tmp_path / "out").exists()


def test_help_states_the_default_time_limit(capsys):
    with pytest.raises(SystemExit):
        handouts.main(["--help"])
    assert "(default: 300)" in " ".join(capsys.readouterr().out.split())


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
    html_text, _ = exporter.from_notebook_node(notebook, {"metadata": {"name": "w"}})
    assert "<p>static</p>" in html_text
    assert 'type="application/vnd.jupyter.widget-view+json"' not in html_text
    assert "unpkg" not in html_text


def test_notebook_title_falls_back_to_the_file_name():
    notebook = new_notebook(cells=[new_markdown_cell("no heading"),
                                   new_markdown_cell("## A sub heading\n# Main")])
    assert handouts.notebook_title(notebook, "x") == "Main"
    assert handouts.notebook_title(new_notebook(
        cells=[new_markdown_cell("### Only a sub heading")]), "x") == "Only a sub heading"
    assert handouts.notebook_title(new_notebook(), "05_name") == "05_name"


# --------------------------------------------------------- the pack's notebooks


def test_every_pack_notebook_is_checked():
    assert len(REAL) >= 7, REAL


def test_every_notebook_has_both_pages_and_an_index(handouts_build):
    out, written = handouts_build.folder, list(handouts_build.pages)
    expected = [out / f"{stem}.html" for stem in REAL] + [out / "index.html"]
    expected += [out / "prose" / path.name for path in expected]
    assert written == expected
    for variant in ("", "prose/"):
        index = soup(out / variant / "index.html")
        assert [a["href"] for a in index.select("ol a")] == [f"{stem}.html" for stem in REAL]
        titles = [soup(out / variant / f"{stem}.html").title.get_text() for stem in REAL]
        assert [a.get_text() for a in index.select("ol a")] == titles
        assert_offline(index, local_mathjax(variant))
        assert_local_links_resolve(index, out / variant)


@pytest.mark.parametrize("variant", ["", "prose/"])
@pytest.mark.parametrize("stem", REAL)
def test_pack_page(handouts_build, stem, variant):
    out = handouts_build.folder
    page = soup(out / variant / f"{stem}.html")
    source = nbformat.read(NOTEBOOKS / f"{stem}.ipynb", as_version=4)
    assert_offline(page, local_mathjax(variant))
    assert_no_error_or_widget(page)
    assert_local_links_resolve(page, out / variant)

    # Every figure of the committed notebook is in the page (explorers included).
    explorers = sum(EXPLORER_TAG in tags(cell) for cell in source.cells)
    in_outputs = [image for image in page.find_all("img")
                  if image.find_parent(class_="jp-OutputArea-output")]
    assert in_outputs, "a notebook page without a single figure"
    assert len(in_outputs) >= max(output_figures(source), explorers)
    statics = page.select("figure.lqe-explorer")
    assert len(statics) == explorers
    for figure in statics:
        assert figure.img["src"].startswith("data:image/png;base64,")
        assert "JupyterLab" in figure.figcaption.get_text()

    # The equations' LaTeX is on the page as visible text (what shows without MathJax).
    assert_visible_math(page, math_in(source))

    text = page.get_text()
    shown_code = [line for line in code_lines(source) if line in text]
    if variant:
        assert page.select(CODE_INPUT) == []
        assert shown_code == []
    else:
        code_cells = [cell for cell in source.cells
                      if cell.cell_type == "code" and not tags(cell) & REMOVE_TAGS]
        assert len(page.select(".jp-CodeCell .jp-InputArea")) == len(code_cells)
        assert sorted(shown_code) == sorted(code_lines(source))
