"""Slider latency in a real browser: key press on a slider → new picture shown.

Run: ``.venv/bin/python benchmarks/bench_browser.py`` (needs Chromium, e.g. Debian's
``chromium`` package, and Playwright for Python; prints a reason and exits 0 without).

For every explorer of the pack, a one-cell notebook showing it is opened in
JupyterLab in headless Chromium (the same server and helpers as ``tests/browser``)
and run. Then the handle of its first slider is pressed Right and Left in turn (one
step), then End and Home (end to end of the range). The time from the key press to
the explorer's image holding a new, loaded picture is measured in the page
(``performance.now()`` at the key press, the image's ``load`` event). It covers the
whole round trip: the widget message to the kernel, the redraw, the PNG back over
the websocket and its decoding. The median per explorer and kind of move is
printed; there is no pass/fail (issue 12's target: <= 120 ms on a quiet 2-core
machine).
"""

from __future__ import annotations

import shutil
import statistics
import sys
import tempfile
from pathlib import Path

import nbformat

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "browser"))

# The shared helpers live beside the browser tests.
import lab_driver
from bench_widgets import EXPLORERS  # (notebook, module, factory) of every explorer
from lab_driver import (
    CHROMIUM_ARGS,
    REPO_ROOT,
    LabServer,
    clear_and_run_all,
    explorers,
    open_notebook,
)

#: Key presses timed per explorer (after two untimed ones that warm the cache).
PRESSES = 10
WARM_UP = 2
TARGET_MS = 120.0
#: Longest wait (ms) for JupyterLab's page and widgets to appear.
PAGE_TIMEOUT_MS = 180_000

#: In the page: press-to-picture time (ms) of one key press on the slider handle.
#: Resolves when the image's src has changed and the new picture has loaded.
_TIMED_PRESS_JS = """
([handle, image, key]) => new Promise((resolve, reject) => {
    const before = image.src;
    const start = performance.now();
    const done = () => {
        if (image.src !== before && image.complete && image.naturalWidth > 0) {
            observer.disconnect();
            image.removeEventListener("load", done);
            resolve(performance.now() - start);
        }
    };
    const observer = new MutationObserver(done);
    observer.observe(image, {attributes: true, attributeFilter: ["src"]});
    image.addEventListener("load", done);
    setTimeout(() => { observer.disconnect(); reject(new Error("no new picture in 30 s")); },
               30000);
    handle.focus();
    handle.dispatchEvent(new KeyboardEvent("keydown", {key, bubbles: true}));
})
"""


def find_chromium() -> str | None:
    """Path of a Chromium executable, or None."""
    for name in ("chromium", "chromium-browser"):
        found = shutil.which(name)
        if found:
            return found
    return "/usr/bin/chromium" if Path("/usr/bin/chromium").is_file() else None


def write_notebooks(root: Path) -> list[Path]:
    """One notebook per explorer, each a single cell displaying it."""
    paths = []
    for number, (_, module, factory) in enumerate(EXPLORERS):
        source = f"from {module} import {factory}\n\n{factory}()"
        notebook = nbformat.v4.new_notebook(
            cells=[nbformat.v4.new_code_cell(source)],
            metadata={"kernelspec": {"name": "python3", "display_name": "Python 3 (ipykernel)",
                                     "language": "python"}})
        path = root / f"bench_{number}.ipynb"
        nbformat.write(notebook, path)
        paths.append(path)
    return paths


#: The two kinds of move timed: one slider step (the usual nudge) and end to end of the
#: range (axis ranges may change there, which repaints the whole figure).
MOVES = {"one step": ("ArrowRight", "ArrowLeft"), "end to end": ("End", "Home")}


def time_presses(page, panel, keys: tuple[str, str]) -> list[float]:
    """Press-to-picture times (ms) of the first slider of the notebook's explorer.

    The two ``keys`` are pressed in turn, so the slider goes back and forth.
    """
    (view,) = explorers(panel)
    handle = view.sliders[0].locator(".noUi-handle").element_handle()
    image = view.image.element_handle()
    times = []
    for press in range(WARM_UP + PRESSES):
        key = keys[press % 2]
        elapsed = page.evaluate(_TIMED_PRESS_JS, [handle, image, key])
        if press >= WARM_UP:
            times.append(float(elapsed))
    return times


def main() -> int:
    chromium = find_chromium()
    try:
        from playwright.sync_api import sync_playwright
    except ImportError as error:
        print(f"browser benchmark not run: Playwright for Python is missing ({error})")
        return 0
    if chromium is None:
        print("browser benchmark not run: no Chromium executable (install Debian's 'chromium')")
        return 0
    # A benchmark may run on a busy machine: wait longer for pages than the tests do.
    lab_driver.UI_MS = max(lab_driver.UI_MS, PAGE_TIMEOUT_MS)
    with tempfile.TemporaryDirectory(prefix="lqe-bench-browser-") as scratch:
        root, state = Path(scratch) / "root", Path(scratch) / "state"
        root.mkdir()
        state.mkdir()
        notebooks = write_notebooks(root)
        server = LabServer.start(root, state, repo_root=REPO_ROOT)
        try:
            with sync_playwright() as playwright:
                browser = playwright.chromium.launch(
                    executable_path=chromium, headless=True, args=list(CHROMIUM_ARGS))
                try:
                    print(f"Slider key press -> new picture shown in JupyterLab (Chromium), "
                          f"median of {PRESSES} presses (target <= {TARGET_MS:.0f} ms on a "
                          f"quiet 2-core machine; no pass/fail)")
                    for (name, _, _), notebook in zip(EXPLORERS, notebooks, strict=True):
                        context = browser.new_context(viewport={"width": 1400, "height": 1000})
                        try:
                            page = context.new_page()
                            panel = open_notebook(page, server, notebook.name,
                                                  workspace=notebook.stem)
                            clear_and_run_all(page, panel)
                            times = {move: time_presses(page, panel, keys)
                                     for move, keys in MOVES.items()}
                        finally:
                            context.close()
                            server.shutdown_kernels()
                        print(f"  {name:27s} " + "; ".join(
                            f"{move}: {statistics.median(t):6.1f} ms (min {min(t):.1f}, "
                            f"max {max(t):.1f})" for move, t in times.items()))
                finally:
                    browser.close()
        finally:
            server.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
