"""Checks shared by the explorer tests: find a figure's lines and bands, render it.

Imported by the ``tests/explorers/test_explorer*.py`` files as ``explorer_checks`` (pytest puts
``tests/`` on ``sys.path``, as for ``conftest.py``). Not a test module itself.
"""

from __future__ import annotations

import dataclasses
import io

import numpy as np
from matplotlib.axes import Axes
from matplotlib.axis import Tick
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.legend import Legend
from matplotlib.text import Text

from lqe_helpers.scenario import DEFAULT, Scenario


def explorer_draw(scenario: Scenario = DEFAULT) -> Scenario:
    """``scenario`` with the seed explorers draw their noise from (its ``explorer_seed``)."""
    return dataclasses.replace(scenario, seed=scenario.explorer_seed)


#: The scenario whose noise the explorers show by default: another draw than the tasks'.
EXPLORER_SCENARIO = explorer_draw(DEFAULT)


def line(ax: Axes, label: str) -> np.ndarray:
    """y data of the one line of ``ax`` labelled ``label``."""
    found = [artist for artist in ax.get_lines() if artist.get_label() == label]
    assert len(found) == 1, f"expected one line labelled {label!r}, got {len(found)}"
    return np.asarray(found[0].get_ydata(), float)


def lines_by_gid(figure: Figure) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """(x, y) data of every line of ``figure`` that has a gid, by gid (each gid once)."""
    found = {}
    for ax in figure.axes:
        for artist in ax.lines:
            gid = artist.get_gid()
            if gid is not None:
                assert gid not in found, f"duplicate line {gid}"
                found[gid] = (np.asarray(artist.get_xdata(), float),
                              np.asarray(artist.get_ydata(), float))
    return found


def band_matches(ax: Axes, label: str, low: np.ndarray, high: np.ndarray,
                 dt: float = DEFAULT.dt) -> None:
    """The filled band of ``ax`` labelled ``label`` traces ``low`` and ``high``.

    ``low[j]`` and ``high[j]`` are the band's edges at time ``j · dt``; every vertex
    of the band lies on one of them (to 1e-9 relative to the largest edge value, at
    least 1e-9 absolute) and both are traced over every sample.
    """
    found = [c for c in ax.collections if c.get_label() == label]
    assert len(found) == 1, f"expected one band labelled {label!r}, got {len(found)}"
    vertices = np.concatenate([path.vertices for path in found[0].get_paths()])
    index = np.rint(vertices[:, 0] / dt).astype(int)
    tolerance = 1e-9 * max(1.0, float(np.max(np.abs(low))), float(np.max(np.abs(high))))
    on_edge = (np.isclose(vertices[:, 1], low[index], rtol=0, atol=tolerance)
               | np.isclose(vertices[:, 1], high[index], rtol=0, atol=tolerance))
    assert on_edge.all()
    assert np.unique(index).size == low.size


def png(figure: Figure, dpi: int = 60) -> bytes:
    """``figure`` rendered to PNG bytes (no metadata, so equal pictures give equal bytes)."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi, metadata={"Software": None})
    return buffer.getvalue()


def pngs(*figures: Figure, dpi: int = 30) -> list[bytes]:
    """Each figure rendered to PNG bytes (:func:`png`), then closed (pyplot forgets it)."""
    import matplotlib.pyplot as plt

    try:
        return [png(figure, dpi) for figure in figures]
    finally:
        for figure in figures:
            plt.close(figure)


def same_png(first: Figure, second: Figure) -> bool:
    """Whether two figures render to the same PNG (both closed): a result's own figure
    against its painter fed the same arrays."""
    first_png, second_png = pngs(first, second)
    return first_png == second_png


def fresh_figure(figsize: tuple[float, float] = (10.0, 5.0)) -> Figure:
    """An empty figure with an Agg canvas, as an explorer makes one."""
    figure = Figure(figsize=figsize)
    FigureCanvasAgg(figure)
    return figure


def assert_only_numbers_change(explorer, name: str, value: float) -> None:
    """Moving slider ``name`` to ``value`` changes ``explorer.numbers``, no figure text.

    Text is the costliest artist to repaint, so the numbers of a view live beside the
    figure: no text in it (tick labels aside, which follow the axis limits) may
    change, and no text or legend may be painted again over the moving data.
    """
    def texts() -> list[str]:
        ticks = {label for tick in explorer.figure.findobj(Tick)
                 for label in (tick.label1, tick.label2)}
        return [text.get_text() for text in explorer.figure.findobj(Text) if text not in ticks]

    before, numbers = texts(), explorer.numbers
    explorer.sliders[name].value = value
    assert texts() == before
    assert explorer.numbers != numbers
    repainted = explorer.layers.repainted
    assert not [artist for artist in repainted if isinstance(artist, (Text, Legend))]
