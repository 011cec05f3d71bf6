"""The shared explorer machinery: sliders, redraw on change, the static fallback."""

from __future__ import annotations

import base64
import dataclasses
import gc
import html
import importlib
import io
import weakref
from typing import NamedTuple

import numpy as np
import pytest
import traitlets
from explorer_checks import png
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.legend import Legend
from matplotlib.lines import Line2D
from matplotlib.text import Text
from PIL import Image

from lqe_helpers.explorers import Explorer, float_slider, log_slider
from lqe_helpers.explorers.layers import LayeredCanvas
from lqe_helpers.explorers.panels import pin_axis_labels, reuse_panels
from lqe_helpers.explorers.png import encode_picture
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.student_code import StudentCodeError

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def draw_line(figure, *, slope):
    figure.clear()
    ax = figure.add_subplot()
    ax.plot([0.0, 1.0], [0.0, slope])


def make_explorer() -> Explorer:
    return Explorer("a test line", {"slope": float_slider("s (cm)", 1.0, 0.0, 5.0, 0.5)},
                    draw_line, figsize=(4.0, 3.0), dpi=50)


def draw_line_with_numbers(figure, *, slope):
    draw_line(figure, slope=slope)
    return f"rise over one unit: {slope:g} cm <ok>"


@pytest.mark.slow
def test_the_numbers_of_a_view_go_beside_the_figure_and_into_the_static_caption():
    explorer = Explorer("a test line", {"slope": float_slider("s (cm)", 1.0, 0.0, 5.0, 0.5)},
                        draw_line_with_numbers, figsize=(4.0, 3.0), dpi=50)
    assert explorer.numbers == "rise over one unit: 1 cm <ok>"
    assert explorer.readout.value == "rise over one unit: 1 cm &lt;ok&gt;"
    assert explorer.widget.children.index(explorer.readout) == 1  # sliders, numbers, image
    explorer.sliders["slope"].value = 2.5
    assert explorer.readout.value == "rise over one unit: 2.5 cm &lt;ok&gt;"
    assert "rise over one unit: 2.5 cm &lt;ok&gt;" in explorer.static_html()
    silent = make_explorer()  # draw returns None: no numbers, an empty line
    assert (silent.numbers, silent.readout.value) == ("", "")
    assert "rise" not in silent.static_html()


def test_a_drawing_that_returns_something_else_is_refused():
    with pytest.raises(TypeError, match="draw must return a str or None, got float"):
        Explorer("bad", {"slope": float_slider("s (cm)", 1.0, 0.0, 5.0, 0.5)},
                 lambda figure, slope: 1.0, figsize=(4.0, 3.0), dpi=50)


def test_slider_conventions():
    linear = float_slider("σ_v (cm)", 1.5, 0.5, 5.0, 0.1, readout_format=".1f")
    assert (linear.min, linear.max, linear.value) == (0.5, 5.0, 1.5)
    assert linear.continuous_update is False
    logarithmic = log_slider("P0 (cm²)", 1.0, 1e-2, 1e6, steps_per_decade=4)
    assert (logarithmic.min, logarithmic.max, logarithmic.step) == (-2.0, 6.0, 0.25)
    assert logarithmic.value == pytest.approx(1.0)
    assert logarithmic.continuous_update is False


@pytest.mark.parametrize(
    ("arguments", "message"),
    [((50.0, 0.0, 10.0, 1.0), r"value must lie in .*\[0, 10\] .*'x \(cm\)', got 50"),
     ((-0.5, 0.0, 10.0, 1.0), r"value must lie in .*\[0, 10\] .*got -0\.5"),
     ((1.0, 10.0, 0.0, 1.0), r"low must be < high .*got low = 10, high = 0"),
     ((1.0, 2.0, 2.0, 1.0), r"low must be < high .*got low = 2, high = 2"),
     ((1.0, 0.0, 10.0, 0.0), r"step must be a finite number > 0, got 0"),
     ((1.0, 0.0, 10.0, -0.5), r"step must be a finite number > 0, got -0\.5"),
     ((float("nan"), 0.0, 10.0, 1.0), r"value must be a finite number, got nan"),
     ((1.0, 0.0, float("inf"), 1.0), r"high must be a finite number, got inf")],
)
def test_float_slider_refuses_what_ipywidgets_would_clip_or_break(arguments, message):
    with pytest.raises(ValueError, match=message):
        float_slider("x (cm)", *arguments)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [((1.0, 0.0, 10.0), r"low must be > 0 .*'P0 \(cm²\)', got 0"),
     ((1.0, -1.0, 10.0), r"low must be > 0 .*got -1"),
     ((1e7, 1e-2, 1e6), r"value must lie in .*\[0\.01, 1000000\] .*got 10000000"),
     ((1e-3, 1e-2, 1e6), r"value must lie in .*got 0\.001"),
     ((1.0, 10.0, 1.0), r"low must be < high"),
     ((1.0, 0.1, 10.0, 0), r"steps_per_decade must be a whole number >= 1, got 0"),
     ((1.0, 0.1, 10.0, 2.5), r"steps_per_decade must be a whole number >= 1, got 2\.5")],
)
def test_log_slider_refuses_what_ipywidgets_would_clip_or_break(arguments, message):
    with pytest.raises(ValueError, match=message):
        log_slider("P0 (cm²)", *arguments)


def test_a_value_set_from_code_outside_the_range_raises_instead_of_being_clipped():
    """ipywidgets clips it without a word: P0 set to the exponent -2 would become 0.01."""
    logarithmic = log_slider("P0 (cm²)", 1.0, 1e-2, 1e6)
    with pytest.raises(traitlets.TraitError, match=r"'P0 \(cm²\)' takes values in \[0\.01, "
                                                   r"1e\+06\], got -2: the value itself, not "
                                                   r"its exponent"):
        logarithmic.value = -2
    assert logarithmic.value == pytest.approx(1.0)
    linear = float_slider("σ_v (cm)", 1.5, 0.1, 10.0, 0.1)
    with pytest.raises(traitlets.TraitError, match=r"takes values in \[0\.1, 10\], got 20$"):
        linear.value = 20.0
    assert linear.value == 1.5
    # The ends themselves, as the browser computes them (10 ** exponent), are in range.
    logarithmic.value = 10 ** 6.0
    linear.value = 0.1
    assert (logarithmic.value, linear.value) == (1e6, 0.1)


def test_slider_ends_are_valid_starting_values():
    assert float_slider("x (cm)", 0.0, 0.0, 10.0, 1.0).value == 0.0
    assert float_slider("x (cm)", 10.0, 0.0, 10.0, 1.0).value == 10.0
    assert log_slider("P0 (cm²)", 1e6, 1e-2, 1e6).value == pytest.approx(1e6)


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
    assert "JupyterLab" in html
    assert "shown at its default values: s (cm) = 1.00." in html


def test_static_note_lists_the_values_shown_after_a_slider_moved():
    explorer = make_explorer()
    explorer.sliders["slope"].value = 4.5
    html = explorer.static_html()
    assert "default" not in html
    assert "a test line, shown at s (cm) = 4.50." in html
    assert base64.b64encode(explorer.png).decode("ascii") in html
    # Back at the start: the default values again.
    explorer.sliders["slope"].value = 1.0
    assert "shown at its default values: s (cm) = 1.00." in explorer.static_html()


def test_static_note_lists_every_slider_as_its_readout_shows_it():
    sliders = {"slope": float_slider("s (cm)", 1.0, 0.0, 5.0, 0.5, readout_format=".1f"),
               "variance": log_slider("P0 (cm²)", 100.0, 1.0, 1e4, readout_format=".3g")}
    explorer = Explorer("two <sliders>", sliders, lambda figure, **_: draw_line(figure, slope=1),
                        figsize=(4.0, 3.0), dpi=50)
    html = explorer.static_html()
    assert "two &lt;sliders&gt;, shown at its default values: s (cm) = 1.0; P0 (cm²) = 100." in html


# reuse_panels: build a figure's panels once, refill them on later calls.

class Panels(NamedTuple):
    ax: Axes
    lines: dict[str, Line2D]
    title: Text


class CountingBuild:
    """A panel builder that records every call (and checks the figure is empty)."""

    def __init__(self) -> None:
        self.calls: list[object] = []

    def __call__(self, figure: Figure, key: object) -> Panels:
        assert figure.axes == [] and figure.texts == [], "build must get a cleared figure"
        self.calls.append(key)
        ax = figure.add_subplot()
        lines = {name: ax.plot([0.0, 1.0], [0.0, 0.0], gid=name)[0] for name in ("a", "b")}
        return Panels(ax, lines, figure.suptitle(f"built for {key}"))


def test_panels_are_built_once_per_figure_and_key():
    build, figure = CountingBuild(), Figure()
    first = reuse_panels(figure, build, "key")
    first.lines["a"].set_ydata([1.0, 2.0])
    for _ in range(3):
        assert reuse_panels(figure, build, "key") is first
    assert build.calls == ["key"]
    assert figure.axes == [first.ax]
    np.testing.assert_array_equal(figure.axes[0].lines[0].get_ydata(), [1.0, 2.0])
    # Keys are compared with ==, not identity.
    assert reuse_panels(figure, build, ("a", 1)) is not first
    assert reuse_panels(figure, build, ("a", 1 + 0)) is reuse_panels(figure, build, ("a", 1))


def test_another_key_or_builder_rebuilds_on_a_cleared_figure():
    build, other_build, figure = CountingBuild(), CountingBuild(), Figure()
    first = reuse_panels(figure, build, 1)
    second = reuse_panels(figure, build, 2)
    assert second.ax is not first.ax and figure.axes == [second.ax]
    assert first.lines["a"] not in figure.axes[0].lines
    assert figure.get_suptitle() == "built for 2"
    third = reuse_panels(figure, other_build, 2)
    assert third.ax is not second.ax and figure.axes == [third.ax]
    # Back to the first builder and key: the figure shows other panels now, so rebuild.
    assert reuse_panels(figure, build, 1) is not first
    assert (build.calls, other_build.calls) == ([1, 2, 1], [2])


def test_each_figure_has_its_own_panels():
    build, left, right = CountingBuild(), Figure(), Figure()
    on_left, on_right = reuse_panels(left, build, 0), reuse_panels(right, build, 0)
    assert on_left.ax is not on_right.ax
    assert reuse_panels(left, build, 0) is on_left
    assert reuse_panels(right, build, 0) is on_right
    assert len(build.calls) == 2


def test_foreign_figure_is_cleared_before_building():
    build, figure = CountingBuild(), Figure()
    foreign = figure.subplots(1, 3)
    figure.suptitle("someone else's title")
    panels = reuse_panels(figure, build, "key")
    assert figure.axes == [panels.ax]
    assert not any(ax in figure.axes for ax in foreign)
    assert figure.get_suptitle() == "built for key"


@pytest.mark.parametrize("change", [
    "clear figure", "clear axes", "remove line", "remove figure text", "add axes",
    "remove axes",
])
def test_figure_that_no_longer_shows_the_panels_is_rebuilt(change):
    build, figure = CountingBuild(), Figure()
    panels = reuse_panels(figure, build, "key")
    if change == "clear figure":
        figure.clear()
    elif change == "clear axes":
        panels.ax.clear()
    elif change == "remove line":
        panels.lines["b"].remove()
    elif change == "remove figure text":
        panels.title.remove()
    elif change == "add axes":
        figure.add_subplot(2, 2, 4)
    else:
        figure.delaxes(panels.ax)
    rebuilt = reuse_panels(figure, build, "key")
    assert rebuilt is not panels
    assert build.calls == ["key", "key"]
    assert figure.axes == [rebuilt.ax]
    assert sorted(line.get_gid() for line in rebuilt.ax.lines) == ["a", "b"]
    assert figure.get_suptitle() == "built for key"


def test_artists_added_after_building_do_not_force_a_rebuild():
    build, figure = CountingBuild(), Figure()
    panels = reuse_panels(figure, build, "key")
    span = panels.ax.axvspan(0.0, 0.5)
    assert reuse_panels(figure, build, "key") is panels
    span.remove()
    assert reuse_panels(figure, build, "key") is panels
    assert len(build.calls) == 1


@pytest.mark.slow
def test_built_panels_do_not_keep_their_figure_alive():
    figure = Figure()
    reuse_panels(figure, CountingBuild(), "key")
    gone = weakref.ref(figure)
    del figure
    gc.collect()
    assert gone() is None


def _label_boxes(figure: Figure) -> list[np.ndarray]:
    """Window extents (px) of every axis label, relative to its axes' lower-left corner."""
    renderer = figure.canvas.get_renderer()
    boxes = []
    for ax in figure.axes:
        corner = np.array([ax.bbox.x0, ax.bbox.y0])
        for axis in (ax.xaxis, ax.yaxis):
            extent = axis.label.get_window_extent(renderer)
            boxes.append(np.array([extent.p0 - corner, extent.p1 - corner]))
    return boxes


def test_pinned_axis_labels_stay_where_automatic_placement_put_them():
    figure = Figure(figsize=(10.0, 5.0))
    FigureCanvasAgg(figure)
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot([0, 1], [-150, 150])
    top.set_ylabel("position (cm)")
    bottom.set_ylabel("error (cm)")
    bottom.set_xlabel("time (s)")
    figure.align_ylabels((top, bottom))
    figure.canvas.draw()
    automatic = _label_boxes(figure)
    pin_axis_labels(figure)
    assert not top.yaxis._autolabelpos and not bottom.xaxis._autolabelpos
    figure.canvas.draw()
    for before, after in zip(automatic, _label_boxes(figure), strict=True):
        np.testing.assert_allclose(after, before, atol=1e-6)
    # Pinned in axes coordinates: at twice the dpi every offset doubles.
    figure.set_dpi(2 * figure.get_dpi())
    figure.canvas.draw()
    doubled = _label_boxes(figure)
    for before, after in zip(automatic, doubled, strict=True):
        assert np.all(np.abs(after - 2 * before) < 2.0)  # text bboxes round to whole pixels


#: (module, draw function, slider values) of every explorer in the pack.
DRAWINGS = [
    ("background", "draw_background", {"jerk_std": 300.0}),
    ("vision", "draw_vision", {"sigma_v": 2.0}),
    ("initial_covariance", "draw_initial_covariance", {"p0_variance": 10.0}),
    ("fusion", "draw_fusion", {"sigma_v": 2.0, "sigma_p": 3.0}),
    ("noisier_proprioception", "draw_noisier_proprioception", {"sigma_p": 6.0}),
    ("delay", "draw_delay", {"delay": 0.1}),
    ("bias", "draw_bias", {"bias": 20.0, "sigma_a": 50.0, "sigma_v": 2.0}),
]


@pytest.mark.parametrize(("module", "name", "values"), DRAWINGS, ids=[d[0] for d in DRAWINGS])
@pytest.mark.slow
def test_every_explorer_keeps_its_panels_until_the_scenario_changes(module, name, values):
    draw = getattr(importlib.import_module(f"lqe_helpers.explorers.{module}"), name)
    figure = Figure(figsize=(10.0, 5.0))
    draw(figure, **values)
    axes = list(figure.axes)
    draw(figure, **values)
    assert figure.axes == axes
    other = dataclasses.replace(DEFAULT, seed=DEFAULT.seed + 1, sigma_v=2.5)
    draw(figure, scenario=other, **values)
    assert not set(figure.axes) & set(axes)
    fresh = Figure(figsize=(10.0, 5.0))
    draw(fresh, scenario=other, **values)
    assert png(figure, dpi=40) == png(fresh, dpi=40)



# Fast redraws: only the changed artists are repainted, and the picture is the same.

#: (module, factory) of every explorer in the pack.
FACTORIES = [
    ("background", "explore_background"),
    ("vision", "explore_vision"),
    ("initial_covariance", "explore_initial_covariance"),
    ("fusion", "explore_fusion"),
    ("noisier_proprioception", "explore_noisier_proprioception"),
    ("delay", "explore_delay"),
    ("bias", "explore_bias"),
]


def _slider_cases() -> list[tuple[str, str, str]]:
    cases = []
    for module, factory in FACTORIES:
        explorer = getattr(importlib.import_module(f"lqe_helpers.explorers.{module}"), factory)()
        cases.extend((module, factory, name) for name in explorer.sliders)
    return cases


def _positions(slider) -> list[float]:
    """Slider values on its grid: a quarter along, both ends, three quarters along, then
    the low end, then one, two and one step above it (neighbours: the axes stay put)."""
    logarithmic = hasattr(slider, "base")
    values = []
    for fraction in (0.25, 1.0, 0.75, 0.0):
        exponent = slider.min + fraction * (slider.max - slider.min)
        exponent = slider.min + slider.step * round((exponent - slider.min) / slider.step)
        values.append(float(slider.base**exponent) if logarithmic else float(exponent))
    for steps in (1, 2, 1):
        up = slider.min + steps * slider.step
        values.append(float(slider.base**up) if logarithmic else float(up))
    return values


def _full_rendering(explorer: Explorer) -> np.ndarray:
    """RGB pixels of the explorer's drawing at its current values on a brand-new figure."""
    figure = Figure(figsize=explorer.figure.get_size_inches(), dpi=explorer.dpi)
    FigureCanvasAgg(figure)
    explorer.draw(figure, **explorer.values)
    figure.canvas.draw()
    return np.asarray(figure.canvas.buffer_rgba())[..., :3]


@pytest.mark.parametrize(("module", "factory", "name"), _slider_cases(),
                         ids=[f"{m}-{n}" for m, _, n in _slider_cases()])
@pytest.mark.slow
def test_fast_redraw_equals_a_fresh_full_drawing(module, factory, name):
    explorer = getattr(importlib.import_module(f"lqe_helpers.explorers.{module}"), factory)()
    slider = explorer.sliders[name]
    for value in _positions(slider):
        slider.value = value
        shown = np.asarray(Image.open(io.BytesIO(explorer.png)))
        expected = _full_rendering(explorer)
        assert shown.shape == expected.shape
        differing = int(np.any(shown != expected, axis=-1).sum())
        assert differing == 0, f"{module} {name} = {value}: {differing} pixels differ"
    # The last moves (between neighbours) took the fast path.
    assert explorer.layers.fast_renders >= 1, (explorer.layers.full_renders,
                                               explorer.layers.fast_renders)


@pytest.mark.slow
def test_fast_path_repaints_only_changed_artists_and_detects_other_changes():
    explorer = make_explorer()
    explorer.sliders["slope"].value = 2.0  # builds the cached layer
    explorer.sliders["slope"].value = 3.0
    assert explorer.layers.fast_renders == 0  # draw_line clears the figure: all new artists
    figure = Figure(figsize=(4.0, 3.0), dpi=50)
    FigureCanvasAgg(figure)
    ax = figure.add_subplot()
    (moving,) = ax.plot([0.0, 1.0], [0.0, 1.0])
    ax.set_ylim(0.0, 5.0)
    layers = LayeredCanvas(figure)
    layers.render()
    for slope, full, fast in ((2.0, 2, 0), (3.0, 2, 1), (4.0, 2, 2)):
        moving.set_ydata([0.0, slope])
        pixels = layers.render().copy()
        assert (layers.full_renders, layers.fast_renders) == (full, fast)
        figure.canvas.draw()
        np.testing.assert_array_equal(pixels, np.asarray(figure.canvas.buffer_rgba()))
    ax.set_ylim(0.0, 6.0)  # another axis range: repaint everything
    moving.set_ydata([0.0, 1.0])
    pixels = layers.render().copy()
    assert layers.full_renders == 3
    figure.canvas.draw()
    np.testing.assert_array_equal(pixels, np.asarray(figure.canvas.buffer_rgba()))
    ax.set_title("a static title, changed")  # a new text drawn after the line
    pixels = layers.render().copy()
    figure.canvas.draw()
    np.testing.assert_array_equal(pixels, np.asarray(figure.canvas.buffer_rgba()))


def _marker_and_legend() -> tuple[Figure, Line2D, Legend]:
    """A small figure: a fixed line, an empty marker line and a legend at lower right."""
    figure = Figure(figsize=(4.0, 3.0), dpi=60)
    FigureCanvasAgg(figure)
    ax = figure.add_subplot()
    ax.plot([0.0, 1.0], [0.0, 1.0], label="fixed")
    (marker,) = ax.plot([], [], linestyle="none", marker="o", markersize=9, label="moving")
    legend = ax.legend(loc="lower right")
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(0.0, 1.0)
    return figure, marker, legend


@pytest.mark.slow
def test_a_marker_is_repainted_with_what_covers_it_only_where_it_is():
    """A clipped line's extent is where its points and markers are, not its whole axes."""
    figure, marker, legend = _marker_and_legend()
    layers = LayeredCanvas(figure)
    layers.render()
    # Far from the legend, then under it, then beside it, then away again.
    for x, y in ((0.1, 0.9), (0.2, 0.9), (0.3, 0.8), (0.85, 0.1), (0.5, 0.1), (0.15, 0.8),
                 (0.2, 0.7)):
        marker.set_data([x], [y])
        pixels = layers.render()
        reference, reference_marker, _ = _marker_and_legend()
        reference_marker.set_data([x], [y])
        reference.canvas.draw()
        np.testing.assert_array_equal(pixels, np.asarray(reference.canvas.buffer_rgba()))
    assert layers.fast_renders >= 3, (layers.full_renders, layers.fast_renders)
    assert legend not in layers.repainted  # far from the marker: not repainted


def test_png_encoding_keeps_every_pixel():
    rng = np.random.default_rng(12)
    opaque = rng.integers(0, 256, (7, 5, 4), dtype=np.uint8)
    opaque[..., 3] = 255
    translucent = rng.integers(0, 256, (7, 5, 4), dtype=np.uint8)
    for rgba in (opaque, translucent):
        decoded = np.asarray(Image.open(io.BytesIO(encode_picture(rgba, 90))).convert("RGBA"))
        np.testing.assert_array_equal(decoded, rgba)


@pytest.mark.parametrize(("module", "factory"), FACTORIES, ids=[f[0] for f in FACTORIES])
@pytest.mark.slow
def test_static_picture_describes_the_current_view(module, factory):
    explorer = getattr(importlib.import_module(f"lqe_helpers.explorers.{module}"), factory)()
    description = explorer.description
    assert description != explorer.title and len(description.split()) >= 8
    assert f'alt="{html.escape(description)}"' in explorer.static_html()
    slider = next(iter(explorer.sliders.values()))
    slider.value = _positions(slider)[1]
    assert explorer.description != description  # it says which value is shown


# A student's broken code: one line in the numbers line, never a traceback.

class BreakableDrawing:
    """draw_line, but raising ``error`` (when set) instead of drawing."""

    def __init__(self) -> None:
        self.error: Exception | None = None
        self.calls = 0

    def __call__(self, figure, *, slope):
        self.calls += 1
        if self.error is not None:
            raise self.error
        draw_line(figure, slope=slope)
        return f"slope {slope:g} cm"


def test_a_student_code_error_shows_one_line_keeps_the_picture_and_the_next_move_tries_again():
    draw = BreakableDrawing()
    explorer = Explorer("a test line", {"slope": float_slider("s (cm)", 1.0, 0.0, 5.0, 0.5)},
                        draw, figsize=(4.0, 3.0), dpi=50)
    picture = explorer.png
    draw.error = StudentCodeError("my_filter raised ZeroDivisionError: division by zero\n"
                                  "  at line 3 of your cell <here>")
    for slope in (2.0, 2.5, 3.0):  # a loop of moves: no exception, no traceback
        explorer.sliders["slope"].value = slope
    message = ("my_filter raised ZeroDivisionError: division by zero at line 3 of your cell "
               "<here>")
    assert explorer.problem == explorer.numbers == message
    assert explorer.readout.value == html.escape(message)
    assert explorer.png == picture and explorer.image.value == picture
    assert html.escape(message) in explorer.static_html()
    assert draw.calls == 4  # every move tried again
    draw.error = None
    explorer.sliders["slope"].value = 3.5
    assert (explorer.problem, explorer.numbers) == ("", "slope 3.5 cm")
    assert explorer.readout.value == "slope 3.5 cm"
    assert explorer.png != picture and explorer.image.value == explorer.png


def test_any_other_exception_of_a_drawing_propagates_as_the_packs_bug():
    draw = BreakableDrawing()
    explorer = Explorer("a test line", {"slope": float_slider("s (cm)", 1.0, 0.0, 5.0, 0.5)},
                        draw, figsize=(4.0, 3.0), dpi=50)
    draw.error = ValueError("sigma_v must be > 0 cm, got -1")
    with pytest.raises(ValueError, match="sigma_v must be > 0 cm"):
        explorer.sliders["slope"].value = 2.0
    assert explorer.problem == ""


def test_an_explorer_whose_first_drawing_fails_shows_the_message_and_a_picture():
    draw = BreakableDrawing()
    draw.error = StudentCodeError("compensate is not written yet: replace the line "
                                  "`raise NotImplementedError` with your code")
    explorer = Explorer("a test line", {"slope": float_slider("s (cm)", 1.0, 0.0, 5.0, 0.5)},
                        draw, figsize=(4.0, 3.0), dpi=50)
    assert explorer.problem.startswith("compensate is not written yet")
    assert explorer.png.startswith(PNG_SIGNATURE) and explorer.image.value == explorer.png
    assert "compensate is not written yet" in explorer._repr_mimebundle_()["text/html"]
    draw.error = None
    explorer.sliders["slope"].value = 2.0
    assert explorer.numbers == "slope 2 cm"
