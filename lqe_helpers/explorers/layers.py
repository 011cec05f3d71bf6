"""Redraw only what changed: a cached static layer under the artists a slider moved.

A slider move changes a few artists of an explorer's figure (lines, a band, a title)
and leaves the rest (axes, ticks, grid, legends, fixed curves) as it was. Rendering
that rest again costs most of a redraw, so :class:`LayeredCanvas` keeps it as a
pixel buffer and, on a move, restores the buffer and draws only the changed artists
and whatever must be drawn over them.

Why the picture equals a fresh full drawing: Agg paints artists one after another
in a fixed order (figure patch, then each axes' patch and children by zorder, then
figure-level artists). Let R be the changed artists plus every later artist whose
pixels may overlap an artist already in R (bounding boxes, widened by a margin). The
background holds every artist not in R, painted in order; R is then painted in
order on top. At any pixel, every artist of the background that covers it comes
before every artist of R that covers it, so the pixel goes through the same
compositing steps as in a full drawing.

Which artists changed is read from matplotlib's ``stale`` flags (every setter sets
it). The background is rendered again (a full drawing) whenever it may no longer
hold: another figure size or dpi, artists added, removed, hidden or given another
zorder, any axes' limits changed, an axis (ticks, tick labels) stale, or R changed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.axis import Axis
from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.text import Text
from matplotlib.transforms import Bbox

#: Pixels added on every side of a bounding box before testing overlap: antialiased
#: edges, line caps and rounding of clip rectangles stay within it.
MARGIN_PX = 3.0
#: The extent of an artist clipped away entirely: a point far off any canvas.
_EMPTY = Bbox([[-1e9, -1e9], [-1e9, -1e9]])


def leaves(figure: Figure) -> list[Artist]:
    """Every artist ``figure`` paints itself, in no particular order.

    The figure's patch, its non-axes children (legends, texts, …) and every child of
    every axes (patch, lines, collections, spines, axes, titles, legend). Axes are
    containers, not leaves.
    """
    found = [figure.patch]
    for child in figure.get_children():
        if isinstance(child, Axes):
            found.extend(child.get_children())
        elif child is not figure.patch:
            found.append(child)
    return found


def _paints(artist: Artist) -> bool:
    """False for artists that paint no pixel (hidden, or a text with no characters)."""
    if not artist.get_visible():
        return False
    return not (isinstance(artist, Text) and not artist.get_text())


def _extent(artist: Artist, renderer: RendererAgg, whole: Bbox) -> Bbox:
    """A box (display px) that holds every pixel ``artist`` paints, widened by the margin.

    A clipped artist stays inside its clip box; an axis draws its grid inside its axes
    and its ticks and labels around it; anything else reports its window extent. An
    extent that cannot be measured (or is a mere point) counts as the whole figure.
    """
    clip = artist.get_clip_box() if artist.get_clip_on() else None
    if clip is not None:
        box = clip
        # A line inside its clip box (e.g. one marker) paints only where its own
        # extent, which includes its markers, meets the clip box.
        if isinstance(artist, Line2D):
            try:
                own = artist.get_window_extent(renderer)
            except (TypeError, RuntimeError, ValueError):
                own = None
            if own is not None and np.all(np.isfinite(own.get_points())):
                box = Bbox.intersection(clip, own.padded(MARGIN_PX)) or _EMPTY
    elif isinstance(artist, Axis):
        parts = [artist.axes.bbox]
        tight = artist.get_tightbbox(renderer)
        if tight is not None:
            parts.append(tight)
        box = Bbox.union(parts)
    else:
        try:
            box = artist.get_window_extent(renderer)
        except (TypeError, RuntimeError, ValueError):
            box = whole
        # A flat box is a straight spine or line; a point, matplotlib's "no extent".
        if not np.all(np.isfinite(box.get_points())) or (box.width <= 0 and box.height <= 0):
            box = whole
    return box.expanded(1.0, 1.0).padded(MARGIN_PX)


def _skip(renderer: RendererAgg, *args: object, **kwargs: object) -> None:
    """Stands in for the draw method of an artist left out of the background."""


def _overlaps(box: Bbox, others: list[Bbox]) -> bool:
    return any(box.overlaps(other) for other in others)


@dataclass
class _Background:
    """The static layer: pixels of every artist outside ``redrawn``, and what it assumed."""

    signature: tuple
    order: list[Artist]
    redrawn: list[Artist]
    pixels: object  # a BufferRegion of the whole canvas
    #: Extents of the artists in ``order`` when it was rendered, by ``id``.
    boxes: dict[int, Bbox]


class LayeredCanvas:
    """Renders a figure after changes, repainting only the changed artists.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        A figure with an Agg canvas (``FigureCanvasAgg(figure)``).

    Attributes
    ----------
    full_renders : int
        How many times the whole figure was rendered (the first time, and whenever the
        background could no longer be trusted).
    fast_renders : int
        How many renders restored the background and repainted only the changed artists.
    """

    def __init__(self, figure: Figure) -> None:
        if not isinstance(figure.canvas, FigureCanvasAgg):
            raise ValueError(
                f"figure must have an Agg canvas, got {type(figure.canvas).__name__}")
        self.figure = figure
        self._background: _Background | None = None
        self._rendered = False
        self.full_renders = 0
        self.fast_renders = 0

    @property
    def repainted(self) -> tuple[Artist, ...]:
        """The artists a move repaints over the cached layer (empty before the first one).

        The changed artists of the last full render and every artist that may paint
        over them, in drawing order: what the next fast render will paint again.
        """
        return () if self._background is None else tuple(self._background.redrawn)

    def render(self) -> np.ndarray:
        """Bring the canvas up to date with the figure; its RGBA pixels, shape (h, w, 4).

        The returned array is a view of the canvas buffer, valid until the next render.
        """
        figure = self.figure
        if not self._rendered:
            # A new figure: every artist is stale, so nothing tells yet which ones a
            # slider moves. Draw it whole; the next render builds the background.
            figure.canvas.draw()
            self._rendered = True
            self.full_renders += 1
            return np.asarray(figure.canvas.get_renderer().buffer_rgba())
        renderer = figure.canvas.get_renderer()
        current = [artist for artist in leaves(figure) if _paints(artist)]
        changed = [artist for artist in current if artist.stale]
        background = self._background
        if (background is None or background.signature != self._signature(renderer, current)
                or any(isinstance(artist, Axis) for artist in changed)):
            return self._render_full(changed)
        redrawn = self._closure(background.order, set(map(id, changed)), renderer,
                                figure.bbox, background.boxes)
        if [id(a) for a in redrawn] != [id(a) for a in background.redrawn]:
            return self._render_full(changed)
        renderer.restore_region(background.pixels)
        for artist in redrawn:
            artist.draw(renderer)
        self.fast_renders += 1
        return np.asarray(renderer.buffer_rgba())

    def _signature(self, renderer: RendererAgg, current: list[Artist]) -> tuple:
        """Everything the background depends on besides the artists' own content."""
        figure = self.figure
        return (
            (renderer.width, renderer.height, figure.dpi),
            tuple((id(artist), artist.get_zorder()) for artist in current),
            tuple(tuple(ax.viewLim.get_points().ravel()) for ax in figure.axes),
        )

    def _order(self) -> list[Artist]:
        """The leaves in the order a full drawing paints them (recorded, not guessed)."""
        order: list[Artist] = []
        patched = []
        for artist in leaves(self.figure):
            original = artist.draw

            def recording(renderer, *args, _artist=artist, _original=original, **kwargs):
                order.append(_artist)
                return _original(renderer, *args, **kwargs)

            artist.draw = recording
            patched.append(artist)
        try:
            self.figure.draw_without_rendering()
        finally:
            for artist in patched:
                del artist.draw
        seen: set[int] = set()
        unique = []
        for artist in order:
            if id(artist) not in seen and _paints(artist):
                seen.add(id(artist))
                unique.append(artist)
        return unique

    @staticmethod
    def _closure(order: list[Artist], changed: set[int], renderer: RendererAgg,
                 whole: Bbox, known: dict[int, Bbox]) -> list[Artist]:
        """The changed artists and every later one that may paint over them, in order.

        ``known`` caches extents by ``id``: a changed artist is measured anew (and its
        entry replaced), an unchanged one is as it was when last measured (any change
        since would have made it stale at some render), so its entry holds.
        """
        redrawn: list[Artist] = []
        boxes: list[Bbox] = []
        for artist in order:
            if id(artist) in changed:
                redrawn.append(artist)
                box = known[id(artist)] = _extent(artist, renderer, whole)
                boxes.append(box)
            elif boxes:
                box = known.get(id(artist))
                if box is None:
                    box = known[id(artist)] = _extent(artist, renderer, whole)
                if _overlaps(box, boxes):
                    redrawn.append(artist)
                    boxes.append(box)
        return redrawn

    def _render_full(self, changed: list[Artist]) -> np.ndarray:
        """Render the background again, then repaint the changed layer on it.

        The changed artists (but not axes, whose ticks change only with the limits)
        are taken as the ones the next move changes again.
        """
        figure = self.figure
        order = self._order()
        renderer = figure.canvas.get_renderer()
        moving = {id(artist) for artist in changed if not isinstance(artist, Axis)}
        boxes: dict[int, Bbox] = {}
        redrawn = self._closure(order, moving, renderer, figure.bbox, boxes)
        # Leave R out by skipping its draw calls, not by hiding it: a hidden axis or
        # title changes where matplotlib places other artists (titles, labels).
        for artist in redrawn:
            artist.draw = _skip
        try:
            figure.canvas.draw()
        finally:
            for artist in redrawn:
                del artist.draw
        renderer = figure.canvas.get_renderer()
        current = [artist for artist in leaves(figure) if _paints(artist)]
        self._background = _Background(self._signature(renderer, current), order, redrawn,
                                       renderer.copy_from_bbox(figure.bbox), boxes)
        for artist in redrawn:
            artist.draw(renderer)
        self.full_renders += 1
        return np.asarray(renderer.buffer_rgba())
