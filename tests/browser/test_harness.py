"""The harness can fail: it tells a live explorer from a dead one and sees errors.

A small notebook written by the fixtures holds a live explorer (a linear and a log
slider), a dead one whose drawing ignores its slider, a frozen one whose figure moves
but whose numbers line does not, a cell that raises and a cell after it. The checks
that the course notebooks pass must catch each defect here.
"""

from __future__ import annotations

import base64

import pytest
from lab_driver import (
    HARNESS_DIR,
    LabServer,
    clear_and_run_all,
    error_outputs,
    exercise_slider,
    explorers,
    image_state,
    iter_sliders,
    open_notebook,
    press_slider_key,
    screenshot_path,
    type_into_readout,
    unexecuted_cells,
    wait_for_new_image,
)
from offline_pages import open_offline

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]


def test_harness_catches_errors_skipped_cells_and_dead_sliders(lab_page,
                                                              lab_server: LabServer) -> None:
    page = lab_page
    panel = open_notebook(page, lab_server, f"{HARNESS_DIR}/selftest.ipynb", "harness")
    clear_and_run_all(page, panel)

    problems = error_outputs(page, panel)
    assert len(problems) == 1, problems
    assert "RuntimeError" in problems[0] and "deliberate failure" in problems[0]
    assert unexecuted_cells(page, panel) == ['code cell 5: print("never runs")']

    live, dead, frozen = explorers(panel)
    assert [description for description, _ in iter_sliders(live)] == ["a (cm)", "P0 (cm²)"]
    for description, slider in iter_sliders(live):
        exercise_slider(live, slider, f"live slider {description}")

    # Move the dead slider, then a live one. The kernel handles the messages in order,
    # so once the live picture is new, a redraw of the dead explorer would have arrived.
    (_, dead_slider), = iter_sliders(dead)
    dead_before = image_state(dead.image)
    press_slider_key(dead_slider)
    live_before = image_state(live.image)
    type_into_readout(live.sliders[0], "7.50")
    wait_for_new_image(live.image, live_before, "live slider typed after the dead one")
    assert image_state(dead.image) == dead_before

    with pytest.raises(AssertionError, match="did not change"):
        exercise_slider(dead, dead_slider, "dead slider", timeout_ms=2_000)
    (_, frozen_slider), = iter_sliders(frozen)
    with pytest.raises(AssertionError, match=r"numbers line still shows 'slope = 1\.00'"):
        exercise_slider(frozen, frozen_slider, "frozen numbers", timeout_ms=2_000)
    live.output.screenshot(path=screenshot_path("harness-live-explorer"))
    page.screenshot(path=screenshot_path("harness"))


PIXEL_PNG = ("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNkYPhfDwAChwGA60e6kgAAAABJ"
             "RU5ErkJggg==")


def test_offline_check_catches_missing_and_remote_images(browser, tmp_path) -> None:
    (tmp_path / "pixel.png").write_bytes(base64.b64decode(PIXEL_PNG))
    page_path = tmp_path / "page.html"
    page_path.write_text(f"""<!DOCTYPE html><html><head>
<script async src="https://cdn.example.org/mathjax.js"></script></head><body>
<img alt="embedded" src="data:image/png;base64,{PIXEL_PNG}">
<img alt="beside" src="pixel.png">
<img alt="missing" src="missing.png" loading="lazy">
<img alt="remote" src="https://example.org/figure.png">
<a href="pixel.png">fine</a> <a href="nowhere.html#top">gone</a>
</body></html>""")

    page = open_offline(browser, page_path)

    assert [image["alt"] for image in page.images] == ["embedded", "beside", "missing",
                                                       "remote"]
    assert [image["alt"] for image in page.broken_images] == ["missing", "remote"]
    assert sorted(request.split()[0] for request in page.blocked) == ["image", "script"]
    assert page.local_links == [tmp_path / "pixel.png", tmp_path / "nowhere.html"]
