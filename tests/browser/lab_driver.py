"""Drive a JupyterLab server and its pages for the browser tests.

Two halves:

- :class:`LabServer` starts ``jupyter lab`` from this interpreter on 127.0.0.1 with a
  random port, a random token and its own config, runtime, data and settings folders
  (so a developer's own Jupyter settings never leak in), and stops it, and every kernel
  it started, in every outcome.
- The page functions act on a JupyterLab page the way a student does (menus, slider
  keyboard, slider readout) and wait on conditions in the page, each with a bound.

Nothing here sleeps to synchronise: every wait polls a condition until a deadline.
"""

from __future__ import annotations

import json
import os
import re
import secrets
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import quote

if TYPE_CHECKING:  # Playwright is imported where it is used: the module loads without it.
    from playwright.sync_api import Locator, Page

REPO_ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK_DIR = REPO_ROOT / "notebooks"
SCREENSHOT_DIR = REPO_ROOT / "build" / "screenshots"
#: Folder (in the served copy) of the notebook that checks the harness itself.
HARNESS_DIR = "_harness"

#: Chromium flags: no sandbox (CI runs as root in a container), no GPU, and no
#: background traffic (an offline machine would otherwise see a flood of refused
#: connections).
CHROMIUM_ARGS = (
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
)

# Bounds of the waits (ms for the page, s for the server). Generous for a slow 2-core
# CI machine; a healthy run takes a small fraction of each.
SERVER_START_S = 90.0
SERVER_STOP_S = 20.0
KERNEL_READY_MS = 90_000
RUN_ALL_MS = 180_000
REDRAW_MS = 30_000
UI_MS = 30_000

#: Where the browser's console errors and uncaught exceptions are kept for messages.
MAX_LOG_LINES = 60


def course_notebooks() -> list[Path]:
    """The course notebooks, in order (``notebooks/NN_name.ipynb``)."""
    return sorted(NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb"))


def screenshot_path(name: str) -> Path:
    """``build/screenshots/<name>.png`` (folder created; name made file-safe)."""
    SCREENSHOT_DIR.mkdir(parents=True, exist_ok=True)
    return SCREENSHOT_DIR / (re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("_") + ".png")


# --------------------------------------------------------------------------- server


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _child_pids(pid: int) -> list[int]:
    """Direct children of ``pid`` (Linux /proc; empty where that is unavailable)."""
    children: list[int] = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            children += [int(word) for word in (task / "children").read_text().split()]
        except OSError:
            continue
    return children


@dataclass
class LabServer:
    """A running ``jupyter lab`` process serving ``root``.

    Use :meth:`start` to create one and :meth:`stop` (idempotent) to end it.
    """

    root: Path
    state_dir: Path
    port: int
    token: str
    process: subprocess.Popen[bytes]
    log_path: Path
    _log_file: object = field(repr=False, default=None)

    @property
    def base_url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    @classmethod
    def start(cls, root: Path, state_dir: Path, *, repo_root: Path) -> LabServer:
        """Start JupyterLab on ``root`` and return once ``/api/status`` answers.

        Parameters
        ----------
        root : Path
            Folder served (a throwaway copy of the notebooks, so autosave never
            touches the committed files).
        state_dir : Path
            Empty folder for Jupyter's config, runtime, data, settings and workspaces,
            IPython's profile and matplotlib's cache.
        repo_root : Path
            Put first on the kernels' ``PYTHONPATH`` so they import this checkout's
            ``lqe_helpers``.
        """
        folders = {name: state_dir / name for name in (
            "config", "runtime", "data", "ipython", "matplotlib",
            "lab-settings", "lab-workspaces")}
        for folder in folders.values():
            folder.mkdir(parents=True, exist_ok=True)
        # Silence the news prompt: it covers part of the page and would fetch a feed.
        notification = (folders["lab-settings"] / "@jupyterlab" / "apputils-extension"
                        / "notification.jupyterlab-settings")
        notification.parent.mkdir(parents=True, exist_ok=True)
        notification.write_text(json.dumps({"fetchNews": "false", "checkForUpdates": False}))

        env = {key: value for key, value in os.environ.items()
               if not key.startswith(("JUPYTER", "IPYTHON", "MPL"))}
        env.update({
            "JUPYTER_CONFIG_DIR": str(folders["config"]),
            "JUPYTER_RUNTIME_DIR": str(folders["runtime"]),
            # User-level data (kernelspecs, extensions) stays out; the venv's data
            # path, which holds the ipywidgets lab extension, is still searched.
            "JUPYTER_DATA_DIR": str(folders["data"]),
            "JUPYTERLAB_SETTINGS_DIR": str(folders["lab-settings"]),
            "JUPYTERLAB_WORKSPACES_DIR": str(folders["lab-workspaces"]),
            "IPYTHONDIR": str(folders["ipython"]),
            "MPLCONFIGDIR": str(folders["matplotlib"]),
            "PYTHONPATH": os.pathsep.join(
                [str(repo_root), *filter(None, [os.environ.get("PYTHONPATH")])]),
            "PYDEVD_DISABLE_FILE_VALIDATION": "1",
        })
        port, token = free_port(), secrets.token_hex(24)
        command = [
            sys.executable, "-m", "jupyterlab",
            "--no-browser",
            "--ip=127.0.0.1",
            f"--port={port}",
            "--ServerApp.port_retries=0",
            f"--IdentityProvider.token={token}",
            f"--ServerApp.root_dir={root}",
            f"--LabApp.user_settings_dir={folders['lab-settings']}",
            f"--LabApp.workspaces_dir={folders['lab-workspaces']}",
            "--LabApp.news_url=None",
            "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
            "--LabApp.extension_manager=readonly",
            "--ServerApp.terminals_enabled=False",
            # A safety net should this test process die without its finalizers: the
            # server culls idle kernels and then shuts itself down.
            "--MappingKernelManager.cull_idle_timeout=600",
            "--MappingKernelManager.cull_interval=60",
            "--ServerApp.shutdown_no_activity_timeout=900",
        ]
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            command.append("--ServerApp.allow_root=True")  # CI containers run as root
        log_path = state_dir / "jupyterlab.log"
        log_file = log_path.open("wb")
        process = subprocess.Popen(
            command, cwd=root, env=env, stdin=subprocess.DEVNULL, stdout=log_file,
            stderr=subprocess.STDOUT, start_new_session=True)
        server = cls(root, state_dir, port, token, process, log_path, log_file)
        try:
            server._wait_until_up()
        except BaseException:
            server.stop()
            raise
        return server

    def _wait_until_up(self) -> None:
        deadline = time.monotonic() + SERVER_START_S
        while True:
            if self.process.poll() is not None:
                raise RuntimeError(
                    f"jupyter lab exited with code {self.process.returncode} before it "
                    f"answered.\n{self.log_tail()}")
            try:
                self.api("GET", "/api/status", timeout=2.0)
                return
            except (OSError, urllib.error.URLError):
                if time.monotonic() > deadline:
                    raise TimeoutError(
                        f"jupyter lab did not answer /api/status within {SERVER_START_S:.0f} s"
                        f"\n{self.log_tail()}") from None
                time.sleep(0.1)  # polling interval of a condition, not a synchronisation

    def url(self, path: str, **query: str) -> str:
        """Absolute URL of ``path`` on this server, with the token."""
        params = "&".join([*(f"{key}={value}" if value else key for key, value in query.items()),
                           f"token={self.token}"])
        return f"{self.base_url}{path}?{params}"

    def notebook_url(self, notebook: str, workspace: str) -> str:
        """URL opening ``notebook`` (relative to the root) in a fresh, named workspace."""
        return self.url(f"/lab/workspaces/{quote(workspace)}/tree/{quote(notebook)}", reset="")

    def api(self, method: str, path: str, timeout: float = 10.0) -> object:
        """Call the REST API; returns the decoded JSON body (or None if empty)."""
        request = urllib.request.Request(
            self.base_url + path, method=method,
            headers={"Authorization": f"token {self.token}"},
            data=b"" if method in ("POST", "PUT", "PATCH") else None)
        with urllib.request.urlopen(request, timeout=timeout) as response:
            body = response.read()
        return json.loads(body) if body else None

    def shutdown_kernels(self) -> None:
        """Shut down every running kernel (each notebook test leaves one behind)."""
        if self.process.poll() is not None:
            return
        for kernel in self.api("GET", "/api/kernels") or []:
            try:
                self.api("DELETE", f"/api/kernels/{kernel['id']}", timeout=30.0)
            except urllib.error.HTTPError as error:
                if error.code != 404:  # already gone is fine
                    raise

    def stop(self) -> None:
        """Stop the server and its kernels: politely, then by force. Idempotent.

        Whatever goes wrong on the polite path (the API refuses or answers something
        other than JSON, the server does not exit in time, the wait is interrupted),
        the server and its kernels are killed before this returns.
        """
        try:
            if self.process.poll() is None:
                try:
                    self.shutdown_kernels()
                    self.api("POST", "/api/shutdown", timeout=5.0)
                except Exception:  # any failure of the polite path: fall back to a signal
                    self.process.terminate()
                try:
                    self.process.wait(timeout=SERVER_STOP_S)
                except subprocess.TimeoutExpired:
                    pass  # killed below
        finally:
            try:
                if self.process.poll() is None:
                    self._kill()
            finally:
                if self._log_file is not None:
                    self._log_file.close()
                    self._log_file = None

    def _kill(self) -> None:
        """SIGKILL the server's kernels (in their own sessions, so by id), then the server."""
        for pid in _child_pids(self.process.pid):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        self.process.kill()
        self.process.wait(timeout=SERVER_STOP_S)

    def log_tail(self, lines: int = MAX_LOG_LINES) -> str:
        """The last ``lines`` lines of the server's (and its kernels') output."""
        try:
            text = self.log_path.read_text(errors="replace")
        except OSError:
            return "(no server log)"
        return "--- jupyter lab log (tail) ---\n" + "\n".join(text.splitlines()[-lines:])


# ----------------------------------------------------------------------------- page


class PageLog:
    """Console errors and uncaught exceptions of a page, for failure messages."""

    def __init__(self, page: Page) -> None:
        self.console_errors: list[str] = []
        self.page_errors: list[str] = []
        page.on("console", self._on_console)
        page.on("pageerror", lambda error: self.page_errors.append(str(error)))

    def _on_console(self, message) -> None:
        if message.type == "error":
            self.console_errors.append(message.text)

    def __bool__(self) -> bool:
        return bool(self.console_errors or self.page_errors)

    def __str__(self) -> str:
        lines = [f"page error: {text}" for text in self.page_errors]
        lines += [f"console error: {text}" for text in self.console_errors]
        return "--- browser log ---\n" + ("\n".join(lines[-MAX_LOG_LINES:]) or "(empty)")


_NOTEBOOK = ".jp-NotebookPanel"

_KERNEL_READY_JS = """
(panel) => {
  const dialog = document.querySelector('.jp-Dialog');
  if (dialog) return 'dialog: ' + dialog.innerText.slice(0, 300);
  const indicator = panel.querySelector('.jp-Notebook-ExecutionIndicator');
  const name = panel.querySelector('.jp-KernelName');
  const kernel = name ? name.textContent.trim() : '';
  // Before a session exists the indicator already says idle next to "No Kernel".
  if (!indicator || indicator.dataset.status !== 'idle' || !kernel || kernel === 'No Kernel')
    return false;
  return 'ready';
}
"""

_CLEARED_JS = """
(panel) => panel.querySelectorAll('.jp-CodeCell .jp-OutputArea-output').length === 0
  && Array.from(panel.querySelectorAll('.jp-CodeCell .jp-InputPrompt'))
       .every(p => p.textContent.trim() === '[ ]:')
"""

_RUN_FINISHED_JS = """
(panel) => {
  const dialog = document.querySelector('.jp-Dialog');
  if (dialog) return 'dialog: ' + dialog.innerText.slice(0, 300);
  const indicator = panel.querySelector('.jp-Notebook-ExecutionIndicator');
  if (!indicator || indicator.dataset.status !== 'idle') return false;
  const prompts = Array.from(panel.querySelectorAll('.jp-CodeCell .jp-InputPrompt'))
    .map(p => p.textContent.trim());
  if (prompts.some(p => p.includes('*'))) return false;
  // Run All stops at a cell that raises; the cells after it keep an empty prompt.
  const failed = panel.querySelector(
    '.jp-OutputArea-output[data-mime-type="application/vnd.jupyter.stderr"]');
  return (prompts.every(p => /^\\[\\d+\\]:$/.test(p)) || failed) ? 'finished' : false;
}
"""

_PROBLEMS_JS = """
(panel) => {
  const found = [];
  for (const output of panel.querySelectorAll('.jp-OutputArea-output')) {
    const text = (output.innerText || '').trim();
    if (output.dataset.mimeType === 'application/vnd.jupyter.stderr'
        || output.querySelector('.jupyter-widgets-error-widget')
        || text.startsWith('Error displaying widget'))
      found.push(text.slice(0, 3000));
  }
  return found;
}
"""

_BROKEN_IMAGES_JS = """
(panel) => Array.from(panel.querySelectorAll('.jp-OutputArea-output img'))
  .filter(img => !(img.complete && img.naturalWidth > 0))
  .map(img => (img.getAttribute('src') || '').slice(0, 80))
"""

_UNEXECUTED_JS = """
(panel) => Array.from(panel.querySelectorAll('.jp-CodeCell')).flatMap((cell, index) => {
  const prompt = cell.querySelector('.jp-InputPrompt');
  if (prompt && /^\\[\\d+\\]:$/.test(prompt.textContent.trim())) return [];
  const editor = cell.querySelector('.jp-InputArea-editor');
  return [`code cell ${index + 1}: ${(editor ? editor.innerText : '').trim().slice(0, 80)}`];
})
"""

# Digest of the bytes an <img> currently shows (the widget's blob: URL), so "the plot
# changed" means different PNG bytes, not just a re-rendered element.
_IMAGE_STATE_JS = """
async (img) => {
  if (!img.src || !img.complete || img.naturalWidth === 0)
    return {src: img.src, loaded: false, digest: ''};
  const bytes = await (await fetch(img.src)).arrayBuffer();
  const digest = Array.from(new Uint8Array(await crypto.subtle.digest('SHA-256', bytes)))
    .map(b => b.toString(16).padStart(2, '0')).join('');
  return {src: img.src, loaded: true, digest: digest};
}
"""

_IMAGE_REPLACED_JS = """
([img, old]) => img.src !== old && img.complete && img.naturalWidth > 0
"""

_TEXT_IS_JS = """
([element, expected]) => element.textContent.trim() === expected
"""


def notebook_panel(page: Page) -> Locator:
    """The (one) open notebook."""
    return page.locator(_NOTEBOOK)


def _playwright_timeout() -> type[Exception]:
    from playwright.sync_api import TimeoutError as PlaywrightTimeoutError

    return PlaywrightTimeoutError


def _wait(page: Page, script: str, panel: Locator, timeout_ms: float, what: str) -> str:
    handle = panel.element_handle(timeout=timeout_ms)
    try:
        result = page.wait_for_function(script, arg=handle, timeout=timeout_ms).json_value()
    except _playwright_timeout():
        raise AssertionError(f"timed out after {timeout_ms / 1000:.0f} s waiting for {what}") \
            from None
    if isinstance(result, str) and result.startswith("dialog:"):
        raise AssertionError(f"a dialog blocked the page while waiting for {what}: {result}")
    return result


def open_notebook(page: Page, server: LabServer, notebook: str, workspace: str) -> Locator:
    """Open ``notebook`` in a fresh workspace and wait until its kernel is idle."""
    page.goto(server.notebook_url(notebook, workspace), timeout=UI_MS)
    panel = notebook_panel(page)
    panel.wait_for(state="visible", timeout=KERNEL_READY_MS)
    _wait(page, _KERNEL_READY_JS, panel, KERNEL_READY_MS, f"the kernel of {notebook} to start")
    return panel


def click_menu(page: Page, menu: str, item: str) -> None:
    """Click ``menu > item`` in JupyterLab's main menu bar, as a student would."""
    page.locator(f'.lm-MenuBar-itemLabel:text-is("{menu}")').click(timeout=UI_MS)
    entry = page.locator(".lm-Menu.lm-MenuBar-menu li.lm-Menu-item").filter(
        has=page.locator(f'.lm-Menu-itemLabel:text-is("{item}")'))
    entry.wait_for(state="visible", timeout=UI_MS)
    classes = entry.get_attribute("class") or ""
    if "lm-mod-disabled" in classes:
        page.keyboard.press("Escape")
        raise AssertionError(f"menu item {menu} > {item} is disabled")
    entry.click(timeout=UI_MS)


def clear_and_run_all(page: Page, panel: Locator) -> None:
    """Clear every output, then Run > Run All Cells, and wait until the run ends.

    Clearing first (the committed notebooks hold outputs and execution counts) makes
    "finished" unambiguous: every code cell shows a fresh number, or a cell failed.
    """
    click_menu(page, "Edit", "Clear Outputs of All Cells")
    _wait(page, _CLEARED_JS, panel, UI_MS, "the outputs to clear")
    click_menu(page, "Run", "Run All Cells")
    _wait(page, _RUN_FINISHED_JS, panel, RUN_ALL_MS, "Run All Cells to finish")


def error_outputs(page: Page, panel: Locator) -> list[str]:
    """Texts of error outputs: tracebacks, anything on stderr, widgets that failed."""
    return page.evaluate(_PROBLEMS_JS, panel.element_handle())


def broken_output_images(page: Page, panel: Locator) -> list[str]:
    """Sources of output images (static figures, explorers) that did not load."""
    return page.evaluate(_BROKEN_IMAGES_JS, panel.element_handle())


def unexecuted_cells(page: Page, panel: Locator) -> list[str]:
    """Code cells without an execution number (each as ``code cell N: <source…>``)."""
    return page.evaluate(_UNEXECUTED_JS, panel.element_handle())


@dataclass
class ExplorerView:
    """One explorer on the page: its output area, sliders, numbers line and image."""

    output: Locator
    image: Locator
    sliders: list[Locator]
    #: The line between the sliders and the image with the numbers of the view.
    numbers: Locator


def explorers(panel: Locator) -> list[ExplorerView]:
    """Every output on the page that holds slider widgets (an explorer)."""
    page = panel.page
    outputs = panel.locator(".jp-OutputArea-output").filter(has=page.locator(".widget-slider"))
    views = []
    for index in range(outputs.count()):
        output = outputs.nth(index)
        sliders = output.locator(".widget-slider")
        views.append(ExplorerView(
            output=output,
            image=output.locator("img.widget-image"),
            sliders=[sliders.nth(k) for k in range(sliders.count())],
            numbers=output.locator(".widget-html .widget-html-content"),
        ))
    return views


def iter_sliders(view: ExplorerView) -> Iterator[tuple[str, Locator]]:
    """(description, slider) for each slider of ``view``."""
    for slider in view.sliders:
        # Scrolled into view first, as a student would: JupyterLab does not render
        # cells far off screen, and text that is not rendered reads as empty.
        slider.scroll_into_view_if_needed(timeout=UI_MS)
        yield slider.locator(".widget-label").inner_text().strip(), slider


def image_state(image: Locator) -> dict[str, object]:
    """``{"src", "loaded", "digest"}`` of the image an explorer shows now."""
    return image.evaluate(_IMAGE_STATE_JS)


def wait_for_new_image(image: Locator, before: dict[str, object], what: str,
                       timeout_ms: float = REDRAW_MS) -> dict[str, object]:
    """Wait until ``image`` shows a new, loaded picture; return its state.

    Raises AssertionError (naming ``what``) if no new picture arrives in time.
    """
    try:
        image.page.wait_for_function(_IMAGE_REPLACED_JS, arg=[image.element_handle(),
                                                              before["src"]],
                                     timeout=timeout_ms)
    except _playwright_timeout():
        raise AssertionError(
            f"{what}: the explorer's image did not change within {timeout_ms / 1000:.0f} s"
        ) from None
    return image_state(image)


def wait_for_other_text(element: Locator, before: str, what: str,
                        timeout_ms: float = REDRAW_MS) -> str:
    """Wait until ``element`` shows a non-empty text other than ``before``; return it."""
    try:
        element.page.wait_for_function(
            "([e, old]) => e.textContent.trim() !== '' && e.textContent.trim() !== old",
            arg=[element.element_handle(), before], timeout=timeout_ms)
    except _playwright_timeout():
        raise AssertionError(
            f"{what} still shows {before!r} after {timeout_ms / 1000:.0f} s") from None
    return element.text_content().strip()


def wait_for_text(element: Locator, expected: str, what: str,
                  timeout_ms: float = REDRAW_MS) -> None:
    """Wait until ``element`` shows exactly ``expected``."""
    try:
        element.page.wait_for_function(_TEXT_IS_JS, arg=[element.element_handle(), expected],
                                       timeout=timeout_ms)
    except _playwright_timeout():
        raise AssertionError(
            f"{what} shows {element.text_content().strip()!r}, expected {expected!r}"
        ) from None


def readout(slider: Locator) -> Locator:
    return slider.locator(".widget-readout")


def press_slider_key(slider: Locator) -> str:
    """Focus the slider's handle and press End (Home if already at the end).

    Returns the key pressed.
    """
    handle = slider.locator(".noUi-handle")
    now, high = (float(handle.get_attribute(name) or "nan")
                 for name in ("aria-valuenow", "aria-valuemax"))
    key = "Home" if now == high else "End"
    handle.press(key, timeout=UI_MS)
    return key


def type_into_readout(slider: Locator, text: str) -> None:
    """Type ``text`` into the slider's readout and press Enter."""
    box = readout(slider)
    box.fill(text, timeout=UI_MS)
    box.press("Enter", timeout=UI_MS)


def exercise_slider(view: ExplorerView, slider: Locator, what: str,
                    timeout_ms: float = REDRAW_MS) -> None:
    """Move ``slider`` three times and check the explorer redraws each time.

    1. Keyboard: End (Home if the slider sits at its end) on the handle: the readout
       moves, the image shows a different picture and the numbers line other numbers.
    2. Readout: type the starting value back and press Enter: a different picture
       again, and the readout shows that value.
    3. Keyboard again, to the same end: the picture and the numbers equal those of
       step 1 (same value, same view: the redraw is deterministic and its noise fixed).

    Raises AssertionError naming ``what`` at the first step that fails.
    """
    slider.scroll_into_view_if_needed(timeout=UI_MS)
    start = image_state(view.image)
    assert start["loaded"], f"{what}: the explorer's image is not loaded before any move"
    start_numbers = view.numbers.text_content().strip()
    start_text = readout(slider).inner_text().strip()
    assert start_text, f"{what}: the slider's readout shows no value"

    key = press_slider_key(slider)
    at_end = wait_for_new_image(view.image, start, f"{what}, key {key}", timeout_ms)
    end_text = readout(slider).inner_text().strip()
    assert end_text != start_text, f"{what}: key {key} did not move the slider ({start_text})"
    assert at_end["digest"] != start["digest"], (
        f"{what}: after key {key} ({start_text} → {end_text}) the image was replaced by the "
        "same picture")
    end_numbers = wait_for_other_text(view.numbers, start_numbers,
                                      f"{what}, key {key}: the numbers line", timeout_ms)

    type_into_readout(slider, start_text)
    typed = wait_for_new_image(view.image, at_end, f"{what}, typing {start_text!r}",
                               timeout_ms)
    shown = readout(slider).inner_text().strip()
    assert shown == start_text, (
        f"{what}: typed the readout's own earlier text {start_text!r} back in, and it now "
        f"shows {shown!r}: the readout cannot read back the format it displays (ipywidgets "
        "parses typed text with parseFloat, so e.g. a thousands separator breaks it)")
    assert typed["digest"] != at_end["digest"], (
        f"{what}: typing {start_text!r} (from {end_text}) gave the same picture")

    press_slider_key(slider)
    again = wait_for_new_image(view.image, typed, f"{what}, key {key} again", timeout_ms)
    assert again["digest"] == at_end["digest"], (
        f"{what}: the same value ({end_text}) drew a different picture the second time")
    wait_for_text(view.numbers, end_numbers,
                  f"{what}, key {key} again: the numbers line", timeout_ms)
