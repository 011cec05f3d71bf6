"""The machinery shared by every notebook's interactive explorer.

An explorer is a row of sliders above a figure. Moving a slider calls a plain
drawing function ``draw(figure, **values)`` that tests can also call directly, then
renders the figure to PNG bytes shown in an :class:`ipywidgets.Image`. Rendering to
a fixed-size image (instead of clearing an output area) keeps the page from jumping
and needs no interactive matplotlib backend.

Displayed in JupyterLab the explorer is live. Where no widget manager runs (an
HTML handout, a static notebook viewer) the same output carries a static picture
of the figure at its current values and a note that the sliders live in JupyterLab.
"""

from __future__ import annotations

import base64
import html
import io
import math
from collections.abc import Callable, Mapping

import ipywidgets as widgets
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

#: Signature of a drawing function: it (re)draws ``figure`` for the slider values.
DrawFunction = Callable[..., None]


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


def float_slider(description: str, value: float, low: float, high: float, step: float,
                 readout_format: str = ".2f") -> widgets.FloatSlider:
    """A linear slider with the pack's conventions (symbol and unit, no live drag)."""
    _check_readout_format(readout_format)
    return widgets.FloatSlider(
        value=value, min=low, max=high, step=step, description=description,
        readout_format=readout_format, continuous_update=False,
        style={"description_width": "initial"}, layout=widgets.Layout(width="340px"),
    )


def log_slider(description: str, value: float, low: float, high: float,
               steps_per_decade: int = 4, readout_format: str = ".3g") -> widgets.FloatLogSlider:
    """A base-10 logarithmic slider from ``low`` to ``high`` (e.g. P0 in cm²)."""
    _check_readout_format(readout_format)
    return widgets.FloatLogSlider(
        value=value, base=10, min=math.log10(low), max=math.log10(high),
        step=1.0 / steps_per_decade, description=description, readout_format=readout_format,
        continuous_update=False, style={"description_width": "initial"},
        layout=widgets.Layout(width="340px"),
    )


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
        if it needs to); must not call pyplot.
    figsize : (float, float)
        Figure size in inches; with ``dpi`` it fixes the image's height on the page.
    dpi : int
        Resolution of the rendered PNG.
    """

    def __init__(self, title: str, sliders: Mapping[str, widgets.ValueWidget],
                 draw: DrawFunction, figsize: tuple[float, float] = (9.0, 4.0),
                 dpi: int = 90) -> None:
        if not sliders:
            raise ValueError("sliders must name at least one slider, got none")
        self.title = title
        self.sliders = dict(sliders)
        self.draw = draw
        self.dpi = dpi
        self.figure = Figure(figsize=figsize, dpi=dpi)
        FigureCanvasAgg(self.figure)
        width, height = (round(size * dpi) for size in figsize)
        self.image = widgets.Image(
            format="png",
            layout=widgets.Layout(width=f"{width}px", height=f"{height}px",
                                  object_fit="contain"),
        )
        for slider in self.sliders.values():
            slider.observe(self._on_change, names="value")
        self.widget = widgets.VBox(
            [widgets.HBox(list(self.sliders.values()),
                          layout=widgets.Layout(flex_flow="row wrap")), self.image]
        )
        self.png = b""
        self.redraw()

    @property
    def values(self) -> dict[str, float]:
        """Current slider values, by the keyword names ``draw`` receives."""
        return {name: slider.value for name, slider in self.sliders.items()}

    def redraw(self) -> None:
        """Draw the figure for the current values and show it."""
        self.draw(self.figure, **self.values)
        buffer = io.BytesIO()
        # Fast zlib level: encoding time matters more than bytes for a local widget.
        self.figure.savefig(buffer, format="png", dpi=self.dpi, metadata={"Software": None},
                            pil_kwargs={"compress_level": 1})
        self.png = buffer.getvalue()
        self.image.value = self.png

    def _on_change(self, change: Mapping[str, object]) -> None:
        self.redraw()

    def static_html(self) -> str:
        """The figure at the current values as an embedded image, with a note."""
        names = ", ".join(slider.description for slider in self.sliders.values())
        encoded = base64.b64encode(self.png).decode("ascii")
        return (
            f'<figure class="lqe-explorer"><img alt="{html.escape(self.title)}" '
            f'src="data:image/png;base64,{encoded}"/>'
            f"<figcaption><em>{html.escape(self.title)}, shown at its default values. "
            f"Open the notebook in JupyterLab to move the sliders ({html.escape(names)})."
            f"</em></figcaption></figure>"
        )

    def _repr_mimebundle_(self, **kwargs: object) -> dict[str, object]:
        bundle = dict(self.widget._repr_mimebundle_(**kwargs) or {})
        bundle["text/plain"] = f"Interactive explorer: {self.title}"
        bundle["text/html"] = self.static_html()
        bundle["image/png"] = base64.b64encode(self.png).decode("ascii")
        return bundle
