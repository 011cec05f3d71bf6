"""The HTML handouts work offline: every image loads with the network cut.

The handouts of ``notebooks/`` (with code, and the prose variant) are the run's one
build, shared with every handout test (``handouts_build``, tests/artefacts.py), and each
page is opened from disk in Chromium with no network. Every image must load, nothing but
the MathJax script the pages are built with (loaded asynchronously; the pages can do
without it) may try to reach the network, and every link to a local page must exist.
"""

from __future__ import annotations

from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest
from artefacts import HandoutsBuild
from lab_driver import course_notebooks, screenshot_path
from offline_pages import OfflinePage, open_offline

from lqe_helpers.authoring.handouts import build_handouts

pytestmark = [pytest.mark.browser, pytest.mark.timeout(600)]


@pytest.fixture(scope="session")
def handout_pages(chromium_executable: str, handouts_build: HandoutsBuild) -> list[Path]:
    """Every page of the run's handouts (built with the default, local MathJax)."""
    found = sorted(handouts_build.folder.rglob("*.html"))
    assert sorted(handouts_build.pages) == found, (
        "build_handouts did not list every page it wrote")
    return found


def describe(page: OfflinePage, root: Path) -> str:
    lines = [f"{page.path.relative_to(root)}:"]
    lines += [f"  image not loaded: src={image['src']!r} alt={image['alt']!r}"
              for image in page.broken_images]
    return "\n".join(lines)


def test_every_handout_image_loads_offline(browser, handout_pages: list[Path]) -> None:
    root = handout_pages[0].parent
    pages = [open_offline(browser, path, screenshot_path(
                 "handout-" + "-".join(path.relative_to(root).with_suffix("").parts)))
             for path in handout_pages]
    stems = {path.stem for path in course_notebooks()}
    assert {page.path.stem for page in pages} >= stems | {"index"}, "a notebook has no handout"

    broken = [describe(page, root) for page in pages if page.broken_images]
    assert not broken, "images that do not load offline:\n" + "\n".join(broken)

    for page in pages:
        if page.path.stem in stems:
            assert page.images, f"{page.path.relative_to(root)} shows no image at all"
        # Nothing leaves the machine: MathJax is the local copy beside the pages.
        assert page.blocked == [], (
            f"{page.path.relative_to(root)} tries the network for: {page.blocked}")
        missing = [str(link) for link in page.local_links if not link.is_file()]
        assert not missing, f"{page.path.relative_to(root)} links to missing pages: {missing}"


# Handouts of notebooks named with spaces and non-ASCII letters: the index links to them
# URL-quoted, and clicking each link (offline, from disk) opens that page.
SPACED_NAMES = ["01 first page", "02 café ΔΣ", "03 #hash?"]


@pytest.mark.kernel
def test_pages_named_with_spaces_and_accents_open_from_the_index(browser, tmp_path: Path
                                                                ) -> None:
    import nbformat
    from nbformat.v4 import new_markdown_cell, new_notebook

    source = tmp_path / "src"
    source.mkdir()
    for name in SPACED_NAMES:
        notebook = new_notebook(cells=[new_markdown_cell(f"# Page {name}\n\nText.")],
                                metadata={"kernelspec": {"name": "python3",
                                                         "display_name": "Python 3",
                                                         "language": "python"}})
        nbformat.write(notebook, source / f"{name}.ipynb")
    out = tmp_path / "out"
    build_handouts(source, out, mathjax_url="")
    context = browser.new_context(offline=True)
    try:
        page = context.new_page()
        for folder in (out, out / "prose"):
            for name in SPACED_NAMES:
                page.goto((folder / "index.html").as_uri(), wait_until="load")
                page.get_by_role("link", name=f"Page {name}", exact=True).click()
                page.wait_for_load_state("load")
                opened = Path(unquote(urlsplit(page.url).path))
                assert opened == folder / f"{name}.html", page.url
                assert f"Page {name}" in page.locator("h1").first.inner_text()
    finally:
        context.close()
