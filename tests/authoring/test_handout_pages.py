"""Handout page rendering: local MathJax, figure descriptions, accessible markup.

The browser side (typeset maths offline, axe-core, keyboard, reflow) is in
``tests/browser/test_handouts_a11y.py``; these tests check what can be read from the HTML.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import matplotlib
import nbformat
import pytest
from bs4 import BeautifulSoup
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

from lqe_helpers.authoring import handout_pages
from lqe_helpers.plotting import figure_bundle

matplotlib.use("Agg")
import matplotlib.pyplot as plt

DESCRIPTION = 'Position against time, 0–10 s: true path & "noisy" vision <σ_v = 1.5 cm>'
PIXEL = ("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8DwHwAFBQIAX8jx0gAAAA"
         "BJRU5ErkJggg==")


@dataclass(frozen=True)
class Link:
    href: str
    title: str


def render(cells, *, code: bool = True, mathjax_url: str = "", nav=None) -> BeautifulSoup:
    exporter = handout_pages.handout_exporter(code=code, mathjax_url=mathjax_url)
    resources = {"metadata": {"name": "page"}}
    if nav is not None:
        resources["lqe_nav"] = nav
    html, _ = exporter.from_notebook_node(new_notebook(cells=cells), resources)
    return BeautifulSoup(html, "html.parser")


def png_output(metadata: dict | None = None) -> nbformat.NotebookNode:
    return new_output("display_data", data={"image/png": PIXEL, "text/plain": "<Figure>"},
                      metadata=metadata or {})


# --- MathJax copy ---------------------------------------------------------------------

def test_mathjax_copy_holds_every_part_the_pages_load():
    files = handout_pages.mathjax_files()
    assert "MathJax.js" in files
    assert f"config/{handout_pages.MATHJAX_CONFIG_NAME}.js" in files
    assert "LICENSE" in files
    # The HTML-CSS output's STIX-Web font: its data (JavaScript) and its web fonts.
    assert any(name.startswith("jax/output/HTML-CSS/fonts/STIX-Web/") for name in files)
    assert any(name.endswith(".woff") for name in files)
    for part in handout_pages.MATHJAX_PARTS:
        assert part in files or any(name.startswith(part + "/") for name in files), part
    for name, path in files.items():
        assert path.is_file()
        assert path.as_posix().endswith("/" + name)
    # The configuration loads its output jax from inside the combined file: no file
    # the copy leaves out may be named by it except those checked in the browser suite.
    size = sum(path.stat().st_size for path in files.values())
    assert 1_000_000 < size < 2_500_000, f"MathJax copy is {size} bytes"


def test_mathjax_copy_is_placed_under_its_folder():
    copy = handout_pages.mathjax_copy()
    assert set(copy) == {f"mathjax/{name}" for name in handout_pages.mathjax_files()}
    assert copy["mathjax/MathJax.js"].startswith(b"/*")


def test_a_mathjax_copy_missing_a_part_is_refused(tmp_path):
    (tmp_path / "MathJax.js").write_text("x")
    with pytest.raises(FileNotFoundError, match="LICENSE"):
        handout_pages.mathjax_files(tmp_path)


@pytest.mark.parametrize(("depth", "url"), [
    (0, "mathjax/MathJax.js?config=TeX-AMS-MML_HTMLorMML-full"),
    (1, "../mathjax/MathJax.js?config=TeX-AMS-MML_HTMLorMML-full"),
])
def test_mathjax_url_is_relative_to_the_page(depth, url):
    assert handout_pages.mathjax_url(depth) == url


@pytest.mark.parametrize("depth", [-1, 1.0, True, "0"])
def test_mathjax_url_refuses_a_bad_depth(depth):
    with pytest.raises(ValueError, match=r"depth must be a whole number >= 0, got"):
        handout_pages.mathjax_url(depth)


def test_page_loads_the_local_mathjax_with_its_configuration_first():
    url = handout_pages.mathjax_url(1)
    page = render([new_markdown_cell("# T\n\n$$x^2$$")], mathjax_url=url)
    scripts = page.find_all("script")
    [loader] = [script for script in scripts if script.get("src")]
    assert loader["src"] == url
    assert loader.has_attr("async")
    configs = [script for script in scripts if script.get("type") == "text/x-mathjax-config"]
    assert len(configs) == 1
    assert scripts.index(configs[0]) < scripts.index(loader)
    config = configs[0].get_text()
    assert '"HTML-CSS"' in config and 'webFont: "STIX-Web"' in config
    assert 'Firefox: "MML"' in config  # Firefox refuses file: web fonts: native MathML
    assert "autoNumber" in config


def test_without_mathjax_the_page_has_no_script():
    page = render([new_markdown_cell("# T\n\n$x$")])
    assert page.find_all("script", src=True) == []
    assert page.find_all("script", type="text/x-mathjax-config") == []


# --- figures ---------------------------------------------------------------------------

def test_a_described_png_gets_its_description_as_alt():
    cell = new_code_cell("show", outputs=[png_output({"image/png": {"alt": DESCRIPTION}})])
    [image] = render([new_markdown_cell("# T"), cell]).find_all("img")
    assert image["alt"] == DESCRIPTION
    assert image["src"] == f"data:image/png;base64,{PIXEL}"


def test_an_undescribed_png_gets_only_nbconverts_generic_alt_and_is_listed():
    cells = [new_markdown_cell("# T"), new_code_cell("plt.show()", outputs=[png_output()]),
             new_code_cell("x", outputs=[png_output({"image/png": {"alt": "   "}})])]
    images = render(cells).find_all("img")
    # What the browser audit refuses as generic; the build warns with the cells.
    assert [image["alt"] for image in images] == [handout_pages.GENERIC_ALT] * 2
    assert handout_pages.undescribed_figures(new_notebook(cells=cells)) == ["cell 1", "cell 2"]


def test_show_figure_bundle_reaches_the_page_through_its_html_img():
    figure, axes = plt.subplots(figsize=(2, 1))
    axes.plot([0, 1], [0, 1])
    data, metadata = figure_bundle(figure, DESCRIPTION)
    plt.close(figure)
    output = new_output("display_data", data=data, metadata=metadata)
    cells = [new_markdown_cell("# T"), new_code_cell("show", outputs=[output])]
    page = render(cells, code=False)
    [image] = page.find_all("img")
    assert image["alt"] == DESCRIPTION
    assert image["src"] == "data:image/png;base64," + data["image/png"]
    assert handout_pages.undescribed_figures(new_notebook(cells=cells)) == []
    assert handout_pages.figure_description(output) == DESCRIPTION


def test_figure_description_reads_the_mimetype_then_the_top_level_alt():
    assert handout_pages.figure_description(png_output({"alt": " top "})) == "top"
    assert handout_pages.figure_description(png_output()) is None
    text_only = new_output("display_data", data={"text/plain": "x"})
    assert handout_pages.figure_description(text_only) is None


# --- markup ----------------------------------------------------------------------------

def test_page_language_no_pilcrow_links_and_one_h1():
    page = render([new_markdown_cell("# Title\n\n## Part\n\ntext")])
    assert page.html["lang"] == "en"
    assert page.select("a.anchor-link") == []
    assert "¶" not in page.get_text()
    assert len(page.find_all("h1")) == 1


def test_navigation_says_where_each_link_goes_and_labels_each_landmark():
    nav = {"index": "index.html", "previous": Link("01_a.html", "Vision only"),
           "next": Link("03_c.html", "Fusion")}
    page = render([new_markdown_cell("# T")], nav=nav)
    navs = page.find_all("nav")
    assert [element["aria-label"] for element in navs] == [
        "Handout pages (top)", "Handout pages (bottom)"]
    main = page.find("main")
    assert navs[0].find_next("main") is main  # the top links come before the content
    texts = [" ".join(a.get_text().split()) for a in navs[0].find_all("a")]
    assert texts == ["← Previous: Vision only", "All handout pages", "Next: Fusion →"]


def _relative_luminance(colour: str) -> float:
    """WCAG 2.1 relative luminance of ``#rrggbb`` (or ``#rgb``)."""
    digits = colour.lstrip("#")
    if len(digits) == 3:
        digits = "".join(2 * digit for digit in digits)
    channels = [int(digits[index:index + 2], 16) / 255 for index in (0, 2, 4)]
    linear = [value / 12.92 if value <= 0.04045 else ((value + 0.055) / 1.055) ** 2.4
              for value in channels]
    return 0.2126 * linear[0] + 0.7152 * linear[1] + 0.0722 * linear[2]


def _contrast(first: str, second: str) -> float:
    high, low = sorted([_relative_luminance(first), _relative_luminance(second)], reverse=True)
    return (high + 0.05) / (low + 0.05)


def test_contrast_helper_matches_known_ratios():
    assert _contrast("#000000", "#ffffff") == pytest.approx(21.0)
    assert _contrast("#777777", "#ffffff") == pytest.approx(4.48, abs=0.01)
    assert _contrast("#408080", "#f5f5f5") == pytest.approx(4.17, abs=0.01)  # axe's figure


def test_every_text_colour_meets_aa_on_page_and_code_backgrounds():
    css = next(style.get_text() for style in render([new_markdown_cell("# T")])
               .find_all("style") if "lqe-nav" in style.get_text())
    colours = dict(re.findall(r"--(jp-[\w-]+):\s*(#[0-9a-fA-F]{3,6});", css))
    assert colours["jp-cell-editor-background"] == "#f5f5f5"
    text_colours = {name: value for name, value in colours.items()
                    if "background" not in name}
    assert len(text_colours) >= 20
    for name, value in text_colours.items():
        for background in ("#ffffff", colours["jp-cell-editor-background"]):
            assert _contrast(value, background) >= 4.5, (name, value, background)
    # Inactive prompts are not faded below those colours.
    assert "--jp-cell-prompt-not-active-opacity: 1;" in css


def test_our_css_comes_after_the_lab_theme():
    styles = [style.get_text() for style in render([new_markdown_cell("# T")])
              .find_all("style")]
    ours = next(index for index, text in enumerate(styles) if "lqe-nav" in text)
    theme = max(index for index, text in enumerate(styles) if "--jp-mirror-editor" in text
                and index != ours)
    assert ours > theme
