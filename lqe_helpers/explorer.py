"""The machinery shared by every notebook's interactive explorer.

An explorer is a row of sliders above a figure. Moving a slider calls a plain
drawing function ``draw(figure, **values)`` that tests can also call directly, then
renders the figure to PNG bytes shown in an :class:`ipywidgets.Image`. Rendering to
a fixed-size image (instead of clearing an output area) keeps the page from jumping
and needs no interactive matplotlib backend.

Displayed in JupyterLab the explorer is live. Where no widget manager runs (an
HTML handout, a static notebook viewer) the same output carries a static picture
of the figure at its current values and a note listing those values (and whether
they are the defaults) and saying that the sliders live in JupyterLab.

Building a figure's axes, ticks and legends costs more than most filter runs, so a
drawing function builds its panels once per figure with :func:`reuse_panels` and on
later calls only replaces the data of the same artists; :func:`pin_axis_labels`
saves the label placement of panels whose ticks never change. Rendering them costs
more still, so the explorer keeps a picture of everything a move leaves alone and
repaints only the changed artists over it
(:class:`~lqe_helpers.explorers._layers.LayeredCanvas`; the picture equals a full
rendering). Axis limits that change in steps (:func:`set_ylim_in_steps`) and bands
above the grid (:data:`DATA_UNDER_LINES`) keep that repaint small.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import ipywidgets as widgets
import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from . import png, validation
from .explorers._layers import LayeredCanvas

#: zorder of bands, bars and spans that a slider changes: above the grid and ticks
#: (1.5, matplotlib's ``axes.axisbelow: line``) and below lines (2). At the default
#: zorder 1 they would lie under the grid, and every move would repaint each axis
#: with its tick labels (see :class:`~lqe_helpers.explorers._layers.LayeredCanvas`).
DATA_UNDER_LINES = 1.6

#: Signature of a drawing function: it (re)draws ``figure`` for the slider values and
#: returns the numbers of this view as one line of plain text (or None).
DrawFunction = Callable[..., "str | None"]

#: Whatever a panel builder returns: artists, possibly in tuples, lists or dicts.
Panels = TypeVar("Panels")

#: Attribute of a figure holding what :func:`reuse_panels` built on it. Kept on the
#: figure itself (not in a registry) so the panels live and die with their figure.
_BUILT_ATTRIBUTE = "_lqe_built_panels"


@dataclass(frozen=True)
class _Built(Generic[Panels]):
    """What ``build(figure, key)`` made on one figure, and how to tell it is still there."""

    build: Callable[[Figure, Any], Panels]
    key: object
    panels: Panels
    axes: tuple[Axes, ...]
    artists: tuple[Artist, ...]

    def shown_on(self, figure: Figure, build: Callable[[Figure, Any], Panels],
                 key: object) -> bool:
        """True if ``figure`` shows exactly these panels, made by ``build`` for ``key``."""
        return (self.build == build and (self.key is key or self.key == key)
                and figure.axes == list(self.axes)
                and all(_shows(figure, artist) for artist in self.artists))


def _artists_in(panels: object) -> Iterator[Artist]:
    """Every artist in ``panels``: itself, or inside (nested) tuples, lists and dict values."""
    if isinstance(panels, Artist):
        yield panels
    elif isinstance(panels, (tuple, list)):
        for item in panels:
            yield from _artists_in(item)
    elif isinstance(panels, Mapping):
        for item in panels.values():
            yield from _artists_in(item)


def _shows(figure: Figure, artist: Artist) -> bool:
    """True if ``artist`` is still drawn as part of ``figure`` (in one of its axes, or on it)."""
    if isinstance(artist, Axes):
        return artist in figure.axes
    ax = artist.axes
    if ax is None:
        return artist in figure.get_children()
    return ax in figure.axes and artist in ax.get_children()


def reuse_panels(figure: Figure, build: Callable[[Figure, Any], Panels], key: object) -> Panels:
    """The panels ``build(figure, key)`` made on ``figure`` before, or new ones.

    ``build`` lays out a figure's axes and artists (typically with no data yet) and
    returns them: an artist, or (named) tuples, lists or dicts of artists. On the
    first call for a figure, and whenever the figure no longer shows exactly what was
    built for this ``build`` and ``key``, the figure is cleared and ``build`` runs
    again: a figure drawn by other code, cleared, given other axes or missing one of
    the returned artists, or another ``key`` or ``build``. Otherwise the same panels
    come back, and the caller only replaces their data, limits and titles. Artists
    the caller adds later (and removes again) do not count.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to draw on.
    build : callable
        ``build(figure, key)``: adds the panels to the empty ``figure`` and returns
        them. It must not clear the figure or call pyplot.
    key : object
        Everything besides the figure that the built panels depend on (an explorer
        passes its scenario); compared with ``==``.

    Returns
    -------
    Panels
        What ``build`` returned, from now or from an earlier call.
    """
    built = getattr(figure, _BUILT_ATTRIBUTE, None)
    if built is not None and built.shown_on(figure, build, key):
        return built.panels
    figure.clear()
    panels = build(figure, key)
    setattr(figure, _BUILT_ATTRIBUTE, _Built(build, key, panels, tuple(figure.axes),
                                             tuple(_artists_in(panels))))
    return panels


def pin_axis_labels(figure: Figure) -> None:
    """Fix every axis label of ``figure`` where automatic placement puts it now.

    Matplotlib places an axis label by measuring the tick labels (of shared and
    aligned axes too) at every draw. When an explorer's panels keep their ticks
    while the sliders move, measuring once, when the panels are built, is enough
    and saves several ms per redraw. Positions are stored in axes coordinates, so
    the figure can still be saved at any dpi. Not for axes whose limits (and so tick
    labels) follow the data.
    """
    figure.draw_without_rendering()
    for ax in figure.axes:
        for axis in (ax.xaxis, ax.yaxis):
            label = axis.label
            if label.get_text():
                display = label.get_transform().transform(label.get_position())
                axis.set_label_coords(*ax.transAxes.inverted().transform(display))


def set_ylim_in_steps(ax: Axes, low: float, high: float, step: float) -> None:
    """Give ``ax`` y limits holding ``[low, high]``, rounded outward to multiples of ``step``.

    Limits that change only in steps keep the axis (ticks, tick labels) as it was for
    most slider moves, so the explorer repaints only the data
    (:class:`~lqe_helpers.explorers._layers.LayeredCanvas`); the limits are set only
    if they differ from the current ones.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes.
    low, high : float
        Data range that must be visible, ``low <= high``, in the axis' units.
    step : float
        Rounding step, > 0, same units.
    """
    step = validation.positive("step", step)
    limits = (step * math.floor(low / step), step * math.ceil(high / step))
    if limits[0] == limits[1]:
        limits = (limits[0] - step, limits[1] + step)
    if tuple(ax.get_ylim()) != limits:
        ax.set_ylim(*limits)


def encode_png(rgba: np.ndarray, dpi: float) -> bytes:
    """The picture ``rgba`` (uint8, shape (h, w, 4)) as PNG bytes, fast rather than small.

    An opaque picture is stored as RGB, a quarter fewer bytes to compress; the writer
    (:func:`lqe_helpers.png.encode`) skips row filters and uses zlib's fastest level,
    since for a widget on the same machine encoding time matters more than bytes. No
    metadata besides the resolution, so equal pictures give equal bytes.
    """
    opaque = bool(rgba[..., 3].min() == 255)
    return png.encode(np.ascontiguousarray(rgba[..., :3] if opaque else rgba), dpi)


def _check_readout_format(readout_format: str) -> None:
    """Reject readout formats the slider's text box cannot read back.

    ipywidgets parses text typed into the readout with ``parseFloat``, which stops at
    a thousands separator: "1,396" would be read as 1.
    """
    if "," in readout_format or "_" in readout_format:
        raise ValueError(
            f"readout_format must not group thousands (',' or '_'), got {readout_format!r}: "
            "the slider could not read its own readout back"
        )


def _check_range(description: str, value: float, low: float,
                 high: float) -> tuple[float, float, float]:
    """``value``, ``low`` and ``high`` as floats if finite with ``low < high`` and
    ``low <= value <= high``; otherwise a ``ValueError`` naming the slider.

    ipywidgets would instead clip a value outside the range without a word, so a
    slider could silently start somewhere its caller never asked for.
    """
    low = validation.finite_number("low", low)
    high = validation.finite_number("high", high)
    value = validation.finite_number("value", value)
    if not low < high:
        raise ValueError(
            f"low must be < high for the slider {description!r}, got low = {low:.12g}, "
            f"high = {high:.12g}"
        )
    if not low <= value <= high:
        raise ValueError(
            f"value must lie in the slider's range [low, high] = [{low:.12g}, {high:.12g}] "
            f"for the slider {description!r}, got {value:.12g}"
        )
    return value, low, high


def float_slider(description: str, value: float, low: float, high: float, step: float,
                 readout_format: str = ".2f") -> widgets.FloatSlider:
    """A linear slider with the pack's conventions (symbol and unit, no live drag).

    Parameters
    ----------
    description : str
        Symbol and unit shown beside the slider, e.g. ``"σ_v (cm)"``.
    value : float
        Starting value, ``low <= value <= high``.
    low, high : float
        Ends of the range, ``low < high``.
    step : float
        Distance between slider positions, > 0.
    readout_format : str
        Python format of the readout; no thousands separators.

    Raises
    ------
    ValueError
        If a number is not finite, the range is empty, ``step <= 0``, ``value`` lies
        outside ``[low, high]`` or the readout could not be read back.
    """
    _check_readout_format(readout_format)
    value, low, high = _check_range(description, value, low, high)
    step = validation.positive("step", step)
    return widgets.FloatSlider(
        value=value, min=low, max=high, step=step, description=description,
        readout_format=readout_format, continuous_update=False,
        style={"description_width": "initial"}, layout=widgets.Layout(width="340px"),
    )


def log_slider(description: str, value: float, low: float, high: float,
               steps_per_decade: int = 4, readout_format: str = ".3g") -> widgets.FloatLogSlider:
    """A base-10 logarithmic slider from ``low`` to ``high`` (e.g. P0 in cm²).

    Parameters
    ----------
    description : str
        Symbol and unit shown beside the slider, e.g. ``"P0 (cm²)"``.
    value : float
        Starting value, ``low <= value <= high``.
    low, high : float
        Ends of the range, ``0 < low < high``.
    steps_per_decade : int
        Slider positions per factor of ten, a whole number >= 1.
    readout_format : str
        Python format of the readout; no thousands separators.

    Raises
    ------
    ValueError
        If a number is not finite, ``low <= 0``, the range is empty, ``value`` lies
        outside ``[low, high]``, ``steps_per_decade`` is not a whole number >= 1 or
        the readout could not be read back.
    """
    _check_readout_format(readout_format)
    value, low, high = _check_range(description, value, low, high)
    if low <= 0:
        raise ValueError(
            f"low must be > 0 for the logarithmic slider {description!r}, got {low:.12g}"
        )
    steps_per_decade = validation.count("steps_per_decade", steps_per_decade, minimum=1)
    return widgets.FloatLogSlider(
        value=value, base=10, min=math.log10(low), max=math.log10(high),
        step=1.0 / steps_per_decade, description=description, readout_format=readout_format,
        continuous_update=False, style={"description_width": "initial"},
        layout=widgets.Layout(width="340px"),
    )


def starting_value(field: str, value: float, low: float, high: float, unit: str) -> float:
    """The scenario's ``field`` as a slider's starting value, if it lies in ``[low, high]``.

    An explorer starts its slider at a value of the scenario it is given. A value
    outside the slider's range is refused rather than clipped into it, so the
    figure never silently shows another value than the scenario asks for.

    Parameters
    ----------
    field : str
        Name of the scenario attribute, for the message (e.g. ``"sigma_v"``).
    value : float
        Its value.
    low, high : float
        The slider's range.
    unit : str
        Unit of all three, for the message (e.g. ``"cm"``).

    Raises
    ------
    ValueError
        If ``value`` lies outside ``[low, high]``.
    """
    value = float(value)
    if not low <= value <= high:
        raise ValueError(
            f"scenario.{field} must lie in the explorer's slider range "
            f"[{low:.12g}, {high:.12g}] {unit}, got {value:.12g} {unit}"
        )
    return value


class Explorer:
    """Sliders that redraw a matplotlib figure.

    Parameters
    ----------
    title : str
        What the explorer shows; used in the static note.
    sliders : mapping of str to ipywidgets.ValueWidget
        Keyword name of each value passed to ``draw`` → its slider.
    draw : callable
        ``draw(figure, **values)``: draws everything on ``figure`` (clearing it first
        if it needs to) and returns the numbers of this view (this run's MSEs, a gain,
        …) as one line of plain text, or None; must not call pyplot. The line is shown
        between the sliders and the figure (:attr:`numbers`), not drawn in the figure:
        text is the costliest thing to render again on every move.
    figsize : (float, float)
        Figure size in inches; with ``dpi`` it fixes the image's height on the page.
    dpi : int
        Resolution of the rendered PNG.
    describe : callable, optional
        ``describe(**values) -> str``: one or two sentences saying what the figure
        shows at those slider values (the static picture's alt text,
        :attr:`description`); default the title.
    """

    def __init__(self, title: str, sliders: Mapping[str, widgets.ValueWidget],
                 draw: DrawFunction, figsize: tuple[float, float] = (9.0, 4.0),
                 dpi: int = 90, describe: Callable[..., str] | None = None) -> None:
        if not sliders:
            raise ValueError("sliders must name at least one slider, got none")
        self.title = title
        self.sliders = dict(sliders)
        self.draw = draw
        self.describe = describe
        self.dpi = dpi
        self.figure = Figure(figsize=figsize, dpi=dpi)
        FigureCanvasAgg(self.figure)
        self.layers = LayeredCanvas(self.figure)
        width, height = (round(size * dpi) for size in figsize)
        #: The numbers of the current view, as ``draw`` returned them ("" for none).
        self.numbers = ""
        self.readout = widgets.HTML(layout=widgets.Layout(margin="0 0 0 8px"))
        self.image = widgets.Image(
            format="png",
            layout=widgets.Layout(width=f"{width}px", height=f"{height}px",
                                  object_fit="contain"),
        )
        for slider in self.sliders.values():
            slider.observe(self._on_change, names="value")
        self.widget = widgets.VBox(
            [widgets.HBox(list(self.sliders.values()),
                          layout=widgets.Layout(flex_flow="row wrap")),
             self.readout, self.image]
        )
        self.png = b""
        #: Slider values the explorer started at, by keyword name.
        self.defaults = self.values
        self.redraw()

    @property
    def values(self) -> dict[str, float]:
        """Current slider values, by the keyword names ``draw`` receives."""
        return {name: slider.value for name, slider in self.sliders.items()}

    @property
    def description(self) -> str:
        """One or two sentences saying what the figure shows at the current values.

        The alt text of the static picture (:meth:`static_html`); the title when the
        explorer was made without a ``describe`` function.
        """
        if self.describe is None:
            return self.title
        return self.describe(**self.values)

    def redraw(self) -> None:
        """Draw the figure for the current values and show it.

        Only the artists the drawing changed are painted again, over a cached picture
        of the rest (:class:`~lqe_helpers.explorers._layers.LayeredCanvas`); the
        picture is the same as a full rendering.
        """
        numbers = self.draw(self.figure, **self.values)
        if numbers is not None and not isinstance(numbers, str):
            raise TypeError(f"draw must return a str or None, got {type(numbers).__name__}")
        self.png = encode_png(self.layers.render(), self.dpi)
        self.numbers = numbers or ""
        self.readout.value = html.escape(self.numbers)
        self.image.value = self.png

    def _on_change(self, change: Mapping[str, object]) -> None:
        self.redraw()

    def static_html(self) -> str:
        """The figure at the current values as an embedded image, with a note.

        The note lists every slider's current value (as its readout shows it), says
        whether these are the explorer's default values, since a reader of a static
        page cannot see the sliders, and gives the view's :attr:`numbers`.
        """
        encoded = base64.b64encode(self.png).decode("ascii")
        shown = "; ".join(
            f"{slider.description} = {format(slider.value, getattr(slider, 'readout_format', ''))}"
            for slider in self.sliders.values())
        at = f"its default values: {shown}" if self.values == self.defaults else shown
        return (
            f'<figure class="lqe-explorer"><img alt="{html.escape(self.description)}" '
            f'src="data:image/png;base64,{encoded}"/>'
            f"<figcaption><em>{html.escape(self.title)}, shown at {html.escape(at)}.</em>"
            + (f" {html.escape(self.numbers)}" if self.numbers else "")
            + " <em>Open the notebook in JupyterLab to move the sliders.</em>"
            "</figcaption></figure>"
        )

    def _repr_mimebundle_(self, **kwargs: object) -> dict[str, object]:
        bundle = dict(self.widget._repr_mimebundle_(**kwargs) or {})
        bundle["text/plain"] = f"Interactive explorer: {self.title}"
        bundle["text/html"] = self.static_html()
        bundle["image/png"] = base64.b64encode(self.png).decode("ascii")
        return bundle
