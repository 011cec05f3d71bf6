"""The shared explorer machinery: sliders, redraw on change, the static fallback."""

from __future__ import annotations

import base64

import numpy as np
import pytest

from lqe_helpers.explorer import Explorer, float_slider, log_slider

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def draw_line(figure, *, slope):
    figure.clear()
    ax = figure.add_subplot()
    ax.plot([0.0, 1.0], [0.0, slope])


def make_explorer() -> Explorer:
    return Explorer("a test line", {"slope": float_slider("s (cm)", 1.0, 0.0, 5.0, 0.5)},
                    draw_line, figsize=(4.0, 3.0), dpi=50)


def test_slider_conventions():
    linear = float_slider("σ_v (cm)", 1.5, 0.5, 5.0, 0.1, readout_format=".1f")
    assert (linear.min, linear.max, linear.value) == (0.5, 5.0, 1.5)
    assert linear.continuous_update is False
    logarithmic = log_slider("P0 (cm²)", 1.0, 1e-2, 1e6, steps_per_decade=4)
    assert (logarithmic.min, logarithmic.max, logarithmic.step) == (-2.0, 6.0, 0.25)
    assert logarithmic.value == pytest.approx(1.0)
    assert logarithmic.continuous_update is False


@pytest.mark.parametrize("fmt", [",.0f", "_.1f"])
def test_readout_that_cannot_be_read_back_is_refused(fmt):
    with pytest.raises(ValueError, match="readout_format"):
        float_slider("x (cm)", 1.0, 0.0, 2.0, 0.5, readout_format=fmt)
    with pytest.raises(ValueError, match="readout_format"):
        log_slider("P0 (cm²)", 1.0, 0.1, 10.0, readout_format=fmt)


def test_needs_a_slider():
    with pytest.raises(ValueError, match="sliders"):
        Explorer("nothing", {}, draw_line)


def test_moving_a_slider_redraws_with_the_new_value():
    explorer = make_explorer()
    first = explorer.png
    assert first.startswith(PNG_SIGNATURE)
    assert explorer.image.value == first
    explorer.sliders["slope"].value = 4.0
    line = explorer.figure.axes[0].lines[0]
    np.testing.assert_array_equal(line.get_ydata(), [0.0, 4.0])
    assert explorer.png != first
    assert explorer.image.value == explorer.png
    assert explorer.values == {"slope": 4.0}


def test_image_keeps_its_size():
    explorer = make_explorer()
    assert (explorer.image.layout.width, explorer.image.layout.height) == ("200px", "150px")
    explorer.sliders["slope"].value = 5.0
    assert (explorer.image.layout.width, explorer.image.layout.height) == ("200px", "150px")


def test_static_fallback_shows_the_current_figure_and_a_note():
    explorer = make_explorer()
    bundle = explorer._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in bundle
    assert bundle["text/plain"] == "Interactive explorer: a test line"
    assert base64.b64decode(bundle["image/png"]) == explorer.png
    html = bundle["text/html"]
    assert bundle["image/png"] in html
    assert "JupyterLab" in html and "s (cm)" in html
