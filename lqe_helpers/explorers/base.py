"""The explorer: sliders above a figure that a plain drawing function redraws.

An explorer is a row of sliders (:mod:`lqe_helpers.explorers.sliders`) above a figure.
Moving a slider calls a plain drawing function ``draw(figure, **values)`` that tests
can also call directly, then renders the figure to PNG bytes shown in an
:class:`ipywidgets.Image`. Rendering to a fixed-size image (instead of clearing an
output area) keeps the page from jumping and needs no interactive matplotlib backend.

Displayed in JupyterLab the explorer is live. Where no widget manager runs (an
HTML handout, a static notebook viewer) the same output carries a static picture
of the figure at its current values and a note listing those values (and whether
they are the defaults) and saying that the sliders live in JupyterLab.

A redraw is fast because the drawing function refills panels it built once
(:mod:`lqe_helpers.explorers.panels`) and the explorer repaints only the changed
artists over a cached picture of the rest
(:class:`~lqe_helpers.explorers.layers.LayeredCanvas`; the picture equals a full
rendering), then writes the PNG without row filters (:mod:`lqe_helpers.explorers.png`).
"""

from __future__ import annotations

import base64
import dataclasses
import html
from collections.abc import Callable, Mapping

import ipywidgets as widgets
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..scenario import Scenario
from ..student_code import StudentCodeError
from . import png
from .layers import LayeredCanvas

#: Signature of a drawing function: it (re)draws ``figure`` for the slider values and
#: returns the numbers of this view as one line of plain text (or None).
DrawFunction = Callable[..., "str | None"]


def with_explorer_seed(scenario: Scenario) -> Scenario:
    """``scenario`` with its seed replaced by its ``explorer_seed``: where explorers draw noise.

    An explorer shows another noise draw than the tasks compute on, so at its default
    values it never prints a number a task asks the student to find (issue 15). Every
    explorer draws its fixed unit noise from this scenario, and only its noise: all
    else comes from the scenario it was given.
    """
    return dataclasses.replace(scenario, seed=scenario.explorer_seed)


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
        text is the costliest thing to render again on every move. It may raise
        :class:`~lqe_helpers.student_code.StudentCodeError` when a student's function it
        runs fails: the explorer then shows that message in the numbers line
        (:attr:`problem`) and keeps its last picture, and the next move tries again.
        Any other exception propagates: it is a bug of the pack.
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
        #: The numbers of the current view, as ``draw`` returned them ("" for none),
        #: or the one-line :attr:`problem` when the last drawing failed.
        self.numbers = ""
        #: The student's code's one-line message if the last drawing raised a
        #: StudentCodeError, else "".
        self.problem = ""
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
        of the rest (:class:`~lqe_helpers.explorers.layers.LayeredCanvas`); the
        picture is the same as a full rendering.
        """
        try:
            numbers = self.draw(self.figure, **self.values)
        except StudentCodeError as error:
            self._show_problem(error)
            return
        if numbers is not None and not isinstance(numbers, str):
            raise TypeError(f"draw must return a str or None, got {type(numbers).__name__}")
        self.png = png.encode_picture(self.layers.render(), self.dpi)
        self.problem = ""
        self.numbers = numbers or ""
        self.readout.value = html.escape(self.numbers)
        self.image.value = self.png

    def _show_problem(self, error: StudentCodeError) -> None:
        """Show ``error`` as one line in place of the numbers; keep the last picture.

        Never a traceback: the slider stays usable and its next move draws again. An
        explorer whose very first drawing fails shows its figure as it is (no picture
        was made before).
        """
        self.problem = " ".join(str(error).split()) or "the student's function failed"
        self.numbers = self.problem
        self.readout.value = html.escape(self.problem)
        if not self.png:
            self.png = png.encode_picture(self.layers.render(), self.dpi)
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
