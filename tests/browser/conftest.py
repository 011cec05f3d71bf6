"""Fixtures of the browser suite: Chromium, a JupyterLab server, pages, screenshots.

The suite needs a Chromium executable (Debian package ``chromium``). Without one it
is skipped with the reason; with ``LQE_REQUIRE_BROWSER=1`` (set by ``.ci/run``) a
missing browser is a failure instead, so CI can never skip it silently. Set
``LQE_CHROMIUM`` to use a Chromium other than the one on ``PATH``. Playwright never
downloads a browser here.

Run only these tests with ``pytest tests/browser``; leave them out with
``-m "not browser"``.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import nbformat
import pytest
from lab_driver import (
    CHROMIUM_ARGS,
    HARNESS_DIR,
    NOTEBOOK_DIR,
    REPO_ROOT,
    LabServer,
    PageLog,
    screenshot_path,
)

REQUIRE_BROWSER = "LQE_REQUIRE_BROWSER"
CHROMIUM_ENV = "LQE_CHROMIUM"


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "browser: drives JupyterLab or the handouts in Chromium (tests/browser)")


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]):
    """Keep each phase's report on the item, so fixtures can tell a failure."""
    report = yield
    setattr(item, f"report_{report.when}", report)
    return report


def find_chromium() -> str | None:
    """Path of a Chromium executable, or None."""
    configured = os.environ.get(CHROMIUM_ENV)
    if configured:
        return configured if Path(configured).is_file() else None
    for name in ("chromium", "chromium-browser"):
        found = shutil.which(name)
        if found:
            return found
    return "/usr/bin/chromium" if Path("/usr/bin/chromium").is_file() else None


def _unavailable(reason: str) -> None:
    """Skip (locally) or fail (when the browser is required) with ``reason``."""
    if os.environ.get(REQUIRE_BROWSER) == "1":
        pytest.fail(f"{reason}, and {REQUIRE_BROWSER}=1 requires the browser tests to run. "
                    f"Install Debian's 'chromium' package (or set {CHROMIUM_ENV}).",
                    pytrace=False)
    pytest.skip(f"browser tests skipped: {reason} (install Debian's 'chromium' package or set "
                f"{CHROMIUM_ENV}; CI sets {REQUIRE_BROWSER}=1 to make this a failure)")


@pytest.fixture(scope="session")
def chromium_executable() -> str:
    executable = find_chromium()
    if executable is None:
        _unavailable("no Chromium executable found"
                     + (f" at {CHROMIUM_ENV}={os.environ[CHROMIUM_ENV]}"
                        if os.environ.get(CHROMIUM_ENV) else " on PATH"))
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError as error:
        _unavailable(f"Playwright for Python is not installed ({error})")
    return executable


@pytest.fixture(scope="session")
def browser(chromium_executable: str):
    """Headless Chromium, shared by the session; closed in every outcome."""
    from playwright.sync_api import sync_playwright

    playwright = sync_playwright().start()
    try:
        chromium = playwright.chromium.launch(
            executable_path=chromium_executable, headless=True, args=list(CHROMIUM_ARGS),
            timeout=60_000)
        try:
            yield chromium
        finally:
            chromium.close()
    finally:
        playwright.stop()


def write_harness_notebook(path: Path) -> None:
    """A notebook that checks the harness: a live explorer, two broken ones, an error.

    The live explorer shows its values in its numbers line, as the course explorers
    do. The dead explorer's drawing ignores its slider, so its image never changes; the
    frozen explorer redraws its figure but always shows the same numbers line; the
    cell after it raises; the last cell never runs.
    """
    live = '''import numpy as np
from lqe_helpers.explorers import Explorer, float_slider, log_slider


def draw(figure, *, amplitude, variance):
    figure.clear()
    ax = figure.add_subplot()
    t = np.linspace(0.0, 1.0, 50)
    ax.plot(t, amplitude * np.sin(2 * np.pi * t) + np.log10(variance), label="curve")
    ax.set_ylim(-12, 12)
    return f"a = {amplitude:.2f} cm, P0 = {variance:.3g} cm²"


Explorer("live", {"amplitude": float_slider("a (cm)", 1.0, 0.0, 10.0, 0.5),
                  "variance": log_slider("P0 (cm²)", 1.0, 0.01, 100.0)}, draw)'''
    dead = '''def draw_nothing_new(figure, *, ignored):
    figure.clear()
    figure.add_subplot().plot([0, 1], [0, 1])


Explorer("dead", {"ignored": float_slider("ignored (cm)", 1.0, 0.0, 2.0, 0.5)},
         draw_nothing_new)'''
    frozen = '''def draw_stale_numbers(figure, *, slope):
    figure.clear()
    figure.add_subplot().plot([0, 1], [0, slope])
    return "slope = 1.00"


Explorer("frozen", {"slope": float_slider("slope", 1.0, 0.0, 2.0, 0.5)}, draw_stale_numbers)'''
    notebook = nbformat.v4.new_notebook(
        cells=[
            nbformat.v4.new_markdown_cell("# Harness self-test"),
            nbformat.v4.new_code_cell(live, metadata={"tags": ["explorer"]}),
            nbformat.v4.new_code_cell(dead, metadata={"tags": ["explorer"]}),
            nbformat.v4.new_code_cell(frozen, metadata={"tags": ["explorer"]}),
            nbformat.v4.new_code_cell('raise RuntimeError("deliberate failure")'),
            nbformat.v4.new_code_cell('print("never runs")'),
        ],
        metadata={"kernelspec": {"name": "python3", "display_name": "Python 3 (ipykernel)",
                                 "language": "python"}},
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(notebook, path)


@pytest.fixture(scope="session")
def lab_server(chromium_executable: str, tmp_path_factory: pytest.TempPathFactory):
    """JupyterLab serving a throwaway copy of ``notebooks/`` (plus the harness notebook)."""
    root = tmp_path_factory.mktemp("lab-root")
    if NOTEBOOK_DIR.is_dir():
        shutil.copytree(NOTEBOOK_DIR, root, dirs_exist_ok=True,
                        ignore=shutil.ignore_patterns(".ipynb_checkpoints", "__pycache__"))
    write_harness_notebook(root / HARNESS_DIR / "selftest.ipynb")
    server = LabServer.start(root, tmp_path_factory.mktemp("lab-state"), repo_root=REPO_ROOT)
    try:
        yield server
    finally:
        server.stop()


def _failed(item: pytest.Item) -> bool:
    return any(getattr(getattr(item, f"report_{when}", None), "failed", False)
               for when in ("setup", "call"))


@pytest.fixture
def lab_page(request: pytest.FixtureRequest, browser, lab_server) -> Iterator[object]:
    """A fresh browser page for JupyterLab; on failure a screenshot is saved.

    Afterwards the page is closed and every kernel is shut down, whatever happened.
    """
    failure_shot = screenshot_path(f"FAILED-{request.node.name}")
    failure_shot.unlink(missing_ok=True)
    context = browser.new_context(viewport={"width": 1400, "height": 1000})
    try:
        page = context.new_page()
        page.log = PageLog(page)
        yield page
        if _failed(request.node):
            page.screenshot(path=failure_shot)
    finally:
        try:
            context.close()
        finally:
            lab_server.shutdown_kernels()
