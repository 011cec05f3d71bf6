"""The handouts are accessible offline: typeset maths, described figures, axe-core clean.

The handouts of ``notebooks/`` (local MathJax, both variants) are the run's one build,
shared with every handout test (``handouts_build``, tests/artefacts.py), and every page is
opened from disk in Chromium with the network cut, at 200 % zoom in the
sense of WCAG 1.4.10 (a 640 CSS px wide viewport, two device pixels per CSS pixel).
Once MathJax has finished, each page is checked for:

- maths: no text a reader sees still holds LaTeX (``$$``, ``\\mathbf``, ``\\begin``…),
  also on the native-MathML path MathJax takes in Firefox (Firefox refuses web fonts
  from ``file:`` URLs, so the pages send it to MathML; Chromium's MathML Core is a
  subset of Firefox's MathML, so what renders here renders there);
- figures: every ``<img>`` has a specific alt text (not empty, not nbconvert's
  "No description has been provided for this image", not a word like "png");
- axe-core (all rules, none disabled): no serious or critical violation;
- structure: a page language, one ``h1``, headings that never skip a level going
  down, link text that says where the link goes;
- reflow: no horizontal scrolling of the page, no line of text past the viewport
  (code blocks, tables and wide equations scroll in their own box).

The index and the page navigation are also driven by keyboard: Tab reaches each link
with a visible focus ring, Enter follows it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from artefacts import HandoutsBuild
from lab_driver import course_notebooks, screenshot_path
from offline_pages import (
    FIREFOX_USER_AGENT,
    ZOOM_200_SCALE,
    ZOOM_200_VIEWPORT,
    offline_page,
)

from lqe_helpers.authoring.handout_pages import GENERIC_ALT
from lqe_helpers.authoring.handouts import PROSE_DIR

pytestmark = [pytest.mark.browser, pytest.mark.timeout(1800)]

#: Bound of MathJax's typesetting of one page, ms (a page has up to ~200 equations).
TYPESET_MS = 180_000
#: Alt texts that say nothing about the figure.
GENERIC_ALTS = {GENERIC_ALT.lower(), "", "image", "figure", "png", "plot", "graph", "chart",
                "picture", "output", "img"}
#: Link texts that do not say where the link goes.
GENERIC_LINK_TEXTS = {"here", "click here", "link", "more", "this", "this page", "¶", "read more"}
#: Text a reader should never see once the maths is typeset.
RAW_LATEX = re.compile(r"\$\$|\\(?:begin|end|mathbf|boldsymbol|frac|tfrac|hat|sigma|mathcal|"
                       r"operatorname|tag|left|right|qquad|text)\b|\\[()\[\]]")

_WAIT_FOR_MATHJAX = "() => new Promise((r) => MathJax.Hub.Register.StartupHook('End', r))"
_OUTPUT_JAX = "() => MathJax.Hub.outputJax['jax/mml'][0].id"

_INSPECT = r"""
() => {
  const shown = (node) => {
    const element = node.parentElement;
    if (!element || element.closest('script, style, pre, code, annotation, annotation-xml,'
                                     + ' .MJX_Assistive_MathML')) return false;
    return element.checkVisibility ? element.checkVisibility() : true;
  };
  const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  const texts = [];
  for (let node = walker.nextNode(); node; node = walker.nextNode()) {
    if (node.textContent.trim() && shown(node)) texts.push(node.textContent);
  }
  const width = window.innerWidth;
  const scrolls = (element) => {
    for (let e = element.parentElement; e; e = e.parentElement) {
      const style = getComputedStyle(e);
      if (['auto', 'scroll'].includes(style.overflowX) && e !== document.documentElement
          && e !== document.body) return true;
    }
    return false;
  };
  const textBlocks = document.querySelectorAll(
    'p, li, h1, h2, h3, h4, h5, h6, figcaption, blockquote, nav a, dt, dd');
  return {
    lang: document.documentElement.getAttribute('lang'),
    texts: texts,
    math: document.querySelectorAll('.MathJax, .MathJax_Display, .MathJax_MathML, math').length,
    images: Array.from(document.images).map((img) => ({
      alt: img.getAttribute('alt'),
      where: (img.closest('.jp-Cell') || {}).id || img.closest('figure, main, body').tagName,
    })),
    headings: Array.from(document.querySelectorAll('h1, h2, h3, h4, h5, h6')).map(
      (h) => [Number(h.tagName[1]), h.textContent.trim().slice(0, 60)]),
    links: Array.from(document.querySelectorAll('a[href]')).map((a) => ({
      text: (a.getAttribute('aria-label') || a.textContent).replace(/\s+/g, ' ').trim(),
      href: a.getAttribute('href'),
    })),
    pageOverflow: document.documentElement.scrollWidth - width,
    wideText: Array.from(textBlocks).filter((e) => !scrolls(e)
      && e.getBoundingClientRect().right > width + 1).map(
      (e) => `${e.tagName}: ${e.textContent.trim().slice(0, 50)}`),
  };
}
"""


@dataclass
class Audit:
    """What one handout page showed, offline, at 200 % zoom."""

    name: str
    output_jax: str
    lang: str | None
    raw_latex: list[str]
    math: int
    images: list[dict]
    headings: list[list]
    links: list[dict]
    page_overflow: int
    wide_text: list[str]
    violations: list[str] = field(default_factory=list)
    blocked: list[str] = field(default_factory=list)


def raw_latex(texts: list[str]) -> list[str]:
    """The visible text fragments that still hold LaTeX source."""
    return [" ".join(text.split())[:80] for text in texts if RAW_LATEX.search(text)]


def audit_page(browser, path: Path, root: Path, *, user_agent: str | None = None,
               axe: bool = True) -> Audit:
    """Open ``path`` offline at 200 % zoom, wait for MathJax, inspect it (and run axe)."""
    from axe_playwright_python.sync_playwright import Axe

    blocked: list[str] = []
    name = path.relative_to(root).as_posix()
    with offline_page(browser, path, viewport=ZOOM_200_VIEWPORT,
                      device_scale_factor=ZOOM_200_SCALE, user_agent=user_agent,
                      blocked=blocked) as page:
        page.set_default_timeout(TYPESET_MS)
        page.wait_for_function("() => window.MathJax && MathJax.isReady === true")
        page.evaluate(_WAIT_FOR_MATHJAX)
        output_jax = page.evaluate(_OUTPUT_JAX)
        found = page.evaluate(_INSPECT)
        violations = []
        if axe:
            results = Axe().run(page)
            violations = [
                f"{rule['id']} ({rule['impact']}): {rule['help']} — "
                f"{len(rule['nodes'])} element(s), e.g. {rule['nodes'][0]['target']}"
                for rule in results.response["violations"]
                if rule["impact"] in ("serious", "critical")]
            page.screenshot(path=screenshot_path(
                "a11y-" + name.replace("/", "-").removesuffix(".html")))
    return Audit(name, output_jax, found["lang"], raw_latex(found["texts"]), found["math"],
                 found["images"], found["headings"], found["links"], found["pageOverflow"],
                 found["wideText"], violations, blocked)


@pytest.fixture(scope="session")
def handouts_dir(chromium_executable: str, handouts_build: HandoutsBuild) -> Path:
    out_dir = handouts_build.folder  # built with the default: MathJax copied into the folder
    assert (out_dir / "mathjax" / "MathJax.js").is_file()
    return out_dir


@pytest.fixture(scope="session")
def handout_files(handouts_dir: Path) -> list[Path]:
    pages = sorted([*handouts_dir.glob("*.html"), *(handouts_dir / PROSE_DIR).glob("*.html")])
    stems = {path.stem for path in course_notebooks()}
    for folder in (handouts_dir, handouts_dir / PROSE_DIR):
        assert {path.stem for path in pages if path.parent == folder} == stems | {"index"}
    return pages


@pytest.fixture(scope="session")
def audits(browser, handouts_dir: Path, handout_files: list[Path]) -> list[Audit]:
    return [audit_page(browser, path, handouts_dir) for path in handout_files]


def report(problems: dict[str, list]) -> str:
    return "\n".join(f"{name}:\n" + "\n".join(f"  {item}" for item in items)
                     for name, items in problems.items() if items)


def test_every_equation_is_typeset_offline(audits: list[Audit]) -> None:
    for audit in audits:
        assert audit.output_jax == "HTML-CSS", audit.name
        assert audit.blocked == [], f"{audit.name} tried the network: {audit.blocked}"
    assert not report({audit.name: audit.raw_latex for audit in audits}), (
        "LaTeX source visible after MathJax ran offline:\n"
        + report({audit.name: audit.raw_latex for audit in audits}))
    notebooks = [audit for audit in audits if not audit.name.endswith("index.html")]
    assert all(audit.math > 0 for audit in notebooks), [
        audit.name for audit in notebooks if audit.math == 0]


def test_every_equation_is_typeset_on_firefoxs_native_mathml_path(
        browser, handouts_dir: Path, handout_files: list[Path]) -> None:
    problems = {}
    for path in handout_files:
        audit = audit_page(browser, path, handouts_dir, user_agent=FIREFOX_USER_AGENT,
                           axe=False)
        assert audit.output_jax == "NativeMML", audit.name
        problems[audit.name] = audit.raw_latex
    assert not report(problems), "LaTeX visible on the MathML path:\n" + report(problems)


def test_every_image_has_a_specific_description(audits: list[Audit]) -> None:
    problems = {audit.name: [f"{image['where']}: alt={image['alt']!r}"
                             for image in audit.images
                             if (image["alt"] or "").strip().lower() in GENERIC_ALTS
                             or len((image["alt"] or "").split()) < 3]
                for audit in audits}
    assert not report(problems), "images without a specific alt text:\n" + report(problems)
    notebooks = [audit for audit in audits if not audit.name.endswith("index.html")]
    assert all(audit.images for audit in notebooks)


def test_axe_finds_no_serious_or_critical_violation(audits: list[Audit]) -> None:
    problems = {audit.name: audit.violations for audit in audits}
    assert not report(problems), "axe-core violations:\n" + report(problems)


def test_language_one_h1_and_headings_in_order(audits: list[Audit]) -> None:
    problems = {}
    for audit in audits:
        found = []
        if audit.lang != "en":
            found.append(f"page language is {audit.lang!r}")
        levels = [level for level, _ in audit.headings]
        if levels.count(1) != 1 or (levels and levels[0] != 1):
            found.append(f"{levels.count(1)} h1 element(s); the first heading is "
                         f"{audit.headings[:1]}")
        found += [f"h{level} {text!r} follows h{before}"
                  for (before, _), (level, text) in zip(audit.headings, audit.headings[1:],
                                                        strict=False)
                  if level > before + 1]
        problems[audit.name] = found
    assert not report(problems), "page structure:\n" + report(problems)


def test_link_text_says_where_the_link_goes(audits: list[Audit]) -> None:
    problems = {audit.name: [f"{link['text']!r} → {link['href']}" for link in audit.links
                             if link["text"].lower().strip(" .:→←") in GENERIC_LINK_TEXTS
                             or link["text"] == link["href"]]
                for audit in audits}
    assert not report(problems), "links whose text says nothing:\n" + report(problems)


def test_text_reflows_at_200_percent_zoom(audits: list[Audit]) -> None:
    problems = {audit.name: ([f"the page scrolls sideways by {audit.page_overflow} px"]
                             if audit.page_overflow > 0 else []) + audit.wide_text
                for audit in audits}
    assert not report(problems), "text that does not reflow at 640 CSS px:\n" + report(problems)


def _tab_to(page, href: str, limit: int = 60) -> dict:
    """Press Tab until the link to ``href`` has focus; its focus style, or fail."""
    seen = []
    for _ in range(limit):
        page.keyboard.press("Tab")
        focused = page.evaluate("""() => {
          const e = document.activeElement;
          const style = getComputedStyle(e);
          return {tag: e.tagName, href: e.getAttribute('href'),
                  outline: style.outlineStyle, width: parseFloat(style.outlineWidth),
                  visible: e.matches(':focus-visible')};
        }""")
        seen.append(focused["href"] or focused["tag"])
        if focused["href"] == href:
            return focused
    raise AssertionError(f"Tab never reached the link to {href}; focus went to {seen}")


@pytest.mark.parametrize("variant", ["", PROSE_DIR])
def test_index_and_navigation_work_by_keyboard(browser, handouts_dir: Path,
                                               variant: str) -> None:
    folder = handouts_dir / variant
    first, second = (path.name for path in sorted(folder.glob("[0-9][0-9]_*.html"))[:2])
    with offline_page(browser, folder / "index.html") as page:
        focused = _tab_to(page, first)
        assert focused["visible"] and focused["outline"] != "none" and focused["width"] >= 2, (
            f"no visible focus ring on the index link: {focused}")
        page.keyboard.press("Enter")
        page.wait_for_url(f"**/{first}")
        focused = _tab_to(page, second)  # the top navigation's "Next" link
        assert focused["visible"] and focused["outline"] != "none", focused
        page.keyboard.press("Enter")
        page.wait_for_url(f"**/{second}")
        _tab_to(page, "index.html")
        page.keyboard.press("Enter")
        page.wait_for_url("**/index.html")
