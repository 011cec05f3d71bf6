"""Figure conventions of the pack: one Okabe–Ito colour and one line style per role.

Nothing here runs on import. A notebook opts in with :func:`use_pack_style`.
"""

from __future__ import annotations

import base64
import html
import io

import matplotlib as mpl
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

#: Okabe–Ito colours by role, the same in every notebook.
COLORS = {
    "truth": "#000000",
    "vision": "#999999",
    "proprioception": "#E69F00",
    "estimate": "#0072B2",
    "prediction": "#D55E00",
    "alternative": "#009E73",  # a second filtered estimate compared with the first
    "reference": "#CC79A7",    # theory lines: steady states, σ² levels
}

#: Line and marker styles by role, so no role is told apart by colour alone.
STYLES = {
    "truth": {"color": COLORS["truth"], "linestyle": "-", "linewidth": 1.6},
    "vision": {"color": COLORS["vision"], "linestyle": "none", "marker": ".",
               "markersize": 3, "alpha": 0.7},
    "proprioception": {"color": COLORS["proprioception"], "linestyle": "none", "marker": "x",
                       "markersize": 3, "alpha": 0.6},
    "estimate": {"color": COLORS["estimate"], "linestyle": "-", "linewidth": 1.6},
    "prediction": {"color": COLORS["prediction"], "linestyle": "--", "linewidth": 1.6},
    "alternative": {"color": COLORS["alternative"], "linestyle": "-.", "linewidth": 1.6},
    "reference": {"color": COLORS["reference"], "linestyle": ":", "linewidth": 1.4},
}

#: zorder of bands, bars and spans that an explorer's slider changes: above the grid and
#: ticks (1.5, matplotlib's ``axes.axisbelow: line``) and below lines (2). At the default
#: zorder 1 they would lie under the grid, and every move would repaint each axis with
#: its tick labels (see :class:`~lqe_helpers.explorers.layers.LayeredCanvas`).
DATA_UNDER_LINES = 1.6

#: rcParams applied by :func:`use_pack_style`.
RC_PARAMS = {
    "figure.figsize": (9.0, 4.0),
    "figure.dpi": 100,
    "savefig.dpi": 100,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.frameon": False,
    "font.size": 10,
    "svg.hashsalt": "lqe-course-pack",
}


def use_pack_style() -> None:
    """Apply the pack's matplotlib settings (call once at the top of a notebook)."""
    mpl.rcParams.update(RC_PARAMS)


def style(role: str, **overrides: object) -> dict:
    """Keyword arguments for ``Axes.plot`` in one of the :data:`STYLES` roles."""
    if role not in STYLES:
        raise ValueError(f"role must be one of {tuple(STYLES)}, got {role!r}")
    return {**STYLES[role], **overrides}


def plot_band(ax: Axes, times: np.ndarray, centre: np.ndarray, std: np.ndarray,
              role: str = "estimate", label: str | None = None) -> None:
    """Shade ``centre ± 2·std`` in a light fill of the role's colour (≈ 95 % band)."""
    if role not in COLORS:
        raise ValueError(f"role must be one of {tuple(COLORS)}, got {role!r}")
    ax.fill_between(times, centre - 2 * std, centre + 2 * std, color=COLORS[role],
                    alpha=0.15, linewidth=0, label=label)


def label_time_position(ax: Axes, position_unit: str = "cm") -> None:
    """Standard axis labels: time (s) against position."""
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"position ({position_unit})")


def figure_png(figure: Figure) -> bytes:
    """The figure as PNG bytes, cropped like the notebook's inline backend (deterministic)."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", bbox_inches="tight", metadata={"Software": None})
    return buffer.getvalue()


def figure_bundle(figure: Figure, description: str) -> tuple[dict[str, str], dict[str, dict]]:
    """The display bundle and metadata that show ``figure`` described by ``description``.

    Three forms of the one figure, so every reader gets the description:

    - ``text/html``: ``<img src="data:image/png;base64,…" alt="description">``, what
      JupyterLab shows (its own PNG renderer writes no ``alt``, so a screen reader
      would meet an unlabelled image) and what the handouts show;
    - ``image/png`` with ``metadata["image/png"]["alt"] = description``, for tools that
      want the picture itself (PDF export, nbconvert's other templates);
    - ``text/plain``: the description, for a reader (or a test) with text only.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure (left open).
    description : str
        What the figure shows, in words: one or two sentences, not empty.

    Returns
    -------
    data : dict of str to str
        The bundle by mimetype (the PNG base64-encoded, as in a notebook file).
    metadata : dict of str to dict
        ``{"image/png": {"alt": description}}``.

    Raises
    ------
    ValueError
        If ``description`` is not a string with some text in it.
    """
    if not isinstance(description, str) or not description.strip():
        raise ValueError(f"description must be a non-empty sentence, got {description!r}")
    text = description.strip()
    png = base64.b64encode(figure_png(figure)).decode("ascii")
    data = {
        "text/html": f'<img src="data:image/png;base64,{png}" alt="{html.escape(text)}">',
        "image/png": png,
        "text/plain": text,
    }
    return data, {"image/png": {"alt": text}}


def show_figure(figure: Figure, description: str) -> None:
    """Display ``figure`` as a static PNG described by ``description``, then close it.

    The description is the figure's alt text: one or two sentences saying what the
    figure shows, written beside the figure in the notebook (e.g. "Position against
    time, 0–10 s: true path, noisy vision at σ_v = 1.5 cm, filtered estimate with its
    ±2σ band"). It reaches JupyterLab's screen-reader users (the ``<img alt>`` of the
    ``text/html`` form), the handouts and plain-text readers: see :func:`figure_bundle`.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to show; it is closed afterwards, so it is not drawn twice.
    description : str
        What the figure shows, in words (not empty).

    Raises
    ------
    ValueError
        If ``description`` is empty (the figure is then left open, nothing is shown).
    """
    from IPython.display import display

    data, metadata = figure_bundle(figure, description)
    plt.close(figure)
    display(data, raw=True, metadata=metadata)
