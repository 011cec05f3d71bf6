"""Open a local HTML file in Chromium with the network cut and inspect what loaded."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from playwright.sync_api import Browser, Page, Route

#: Bound of a page load, ms.
LOAD_MS = 30_000

# Every <img>, made eager (a lazy image off screen would not load) and decoded: decode()
# settles once the image has loaded or failed, so no fixed wait is needed.
_IMAGES_JS = """
async () => Promise.all(Array.from(document.images).map(async (img) => {
  img.loading = 'eager';
  let decoded = true;
  try { await img.decode(); } catch (error) { decoded = false; }
  return {
    src: (img.getAttribute('src') || '').slice(0, 100),
    alt: img.alt,
    loaded: decoded && img.complete && img.naturalWidth > 0,
  };
}))
"""

_LOCAL_LINKS_JS = """
() => Array.from(document.querySelectorAll('a[href]'))
  .map(a => a.href).filter(href => href.startsWith('file:'))
"""


@dataclass
class OfflinePage:
    """What a page showed with no network."""

    path: Path
    images: list[dict[str, object]]
    #: Requests that tried to leave the machine, as "resource-type URL".
    blocked: list[str] = field(default_factory=list)
    #: ``file:`` links on the page (fragment and query removed).
    local_links: list[Path] = field(default_factory=list)

    @property
    def broken_images(self) -> list[dict[str, object]]:
        return [image for image in self.images if not image["loaded"]]


def open_offline(browser: Browser, path: Path, screenshot: Path | None = None) -> OfflinePage:
    """Load ``path`` (file://) with the network cut; report its images and links.

    If ``screenshot`` is given, the top of the page is saved there as a PNG.
    """
    from urllib.parse import unquote, urlsplit

    blocked: list[str] = []

    def cut(route: Route) -> None:
        request = route.request
        if request.url.startswith(("http:", "https:", "ws:", "wss:", "ftp:")):
            blocked.append(f"{request.resource_type} {request.url}")
            route.abort("internetdisconnected")
        else:
            route.continue_()

    context = browser.new_context(offline=True, viewport={"width": 1200, "height": 900})
    try:
        context.route("**/*", cut)
        page = context.new_page()
        page.goto(path.resolve().as_uri(), wait_until="load", timeout=LOAD_MS)
        images = page.evaluate(_IMAGES_JS)
        links = [Path(unquote(urlsplit(href).path)) for href in page.evaluate(_LOCAL_LINKS_JS)]
        if screenshot is not None:
            page.screenshot(path=screenshot)
    finally:
        context.close()
    return OfflinePage(path, images, blocked, links)


#: WCAG 1.4.10 reflow: 1280 CSS px at 200 % zoom is a 640 CSS px wide viewport, drawn
#: with two device pixels per CSS pixel.
ZOOM_200_VIEWPORT = {"width": 640, "height": 800}
ZOOM_200_SCALE = 2
#: A Firefox user agent: MathJax then takes the path it takes in Firefox (native MathML).
FIREFOX_USER_AGENT = "Mozilla/5.0 (X11; Linux x86_64; rv:128.0) Gecko/20100101 Firefox/128.0"


@contextmanager
def offline_page(browser: Browser, path: Path, *, viewport: dict[str, int] | None = None,
                 device_scale_factor: float = 1, user_agent: str | None = None,
                 blocked: list[str] | None = None) -> Iterator[Page]:
    """``path`` (file://) loaded in a fresh context with the network cut; closed after.

    Requests that try to leave the machine are refused and, if ``blocked`` is given,
    recorded there as "resource-type URL".
    """
    extra = {"user_agent": user_agent} if user_agent else {}
    context = browser.new_context(offline=True, viewport=viewport or {"width": 1200,
                                                                      "height": 900},
                                  device_scale_factor=device_scale_factor, **extra)

    def cut(route: Route) -> None:
        request = route.request
        if request.url.startswith(("http:", "https:", "ws:", "wss:", "ftp:")):
            if blocked is not None:
                blocked.append(f"{request.resource_type} {request.url}")
            route.abort("internetdisconnected")
        else:
            route.continue_()

    try:
        context.route("**/*", cut)
        page = context.new_page()
        # Not "load": that waits for every script MathJax adds (fonts, its output code);
        # a caller waits for what it needs (MathJax's end of typesetting, say).
        page.goto(path.resolve().as_uri(), wait_until="domcontentloaded", timeout=LOAD_MS)
        yield page
    finally:
        context.close()
