"""Panels an explorer builds once and refills: the part of drawing that makes a move fast.

Building a figure's axes, ticks and legends costs more than most filter runs, so a
drawing function builds its panels once per figure with :func:`reuse_panels` and on
later calls only replaces the data of the same artists; :func:`pin_axis_labels`
saves the label placement of panels whose ticks never change. Axis limits that change
in steps (:func:`set_ylim_in_steps`) and bands above the grid
(:data:`lqe_helpers.plotting.DATA_UNDER_LINES`, which the painters in
:mod:`lqe_helpers.figures` give them) keep the repaint of a move small
(:class:`~lqe_helpers.explorers.layers.LayeredCanvas`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .. import validation

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
    (:class:`~lqe_helpers.explorers.layers.LayeredCanvas`); the limits are set only
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
