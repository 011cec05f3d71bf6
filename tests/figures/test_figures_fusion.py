"""Notebook 03's frequency-response figure draws the curves and points it is given."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

from lqe_helpers import figures
from lqe_helpers.plotting import COLORS

FREQUENCY = np.geomspace(0.1, 10.0, 25)


def curves() -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    return {"vision only": (1 + 0.1 * FREQUENCY, 0.001 * FREQUENCY, "alternative"),
            "fused": (1 + 0.2 * FREQUENCY, -0.002 * FREQUENCY, "estimate")}


def test_frequency_response_figure_draws_gain_and_lead_in_ms_with_the_points():
    points = {"vision only: fit": (1.02, 0.0075, "alternative"),
              "fused: fit": (1.01, 0.0055, "estimate")}
    fig = figures.frequency_response_figure(FREQUENCY, curves(), marked=0.5, points=points,
                                            title="settled filters")
    try:
        gain, lead = fig.axes
        assert gain.get_xscale() == "log"
        assert gain.get_title() == "settled filters"
        drawn = {line.get_label(): line for line in gain.get_lines()}
        for label, (g, _, role) in curves().items():
            np.testing.assert_array_equal(drawn[label].get_xdata(), FREQUENCY)
            np.testing.assert_array_equal(drawn[label].get_ydata(), g)
            assert drawn[label].get_color() == COLORS[role]
        leads = {line.get_label(): line for line in lead.get_lines()}
        for label, (_, t, _) in curves().items():
            np.testing.assert_allclose(leads[label].get_ydata(), 1000 * t)   # ms
        for label, (g, t, role) in points.items():
            np.testing.assert_array_equal(drawn[label].get_xdata(), [0.5])
            np.testing.assert_array_equal(drawn[label].get_ydata(), [g])
            np.testing.assert_allclose(leads[label].get_ydata(), [1000 * t])
            assert drawn[label].get_marker() == "o"
            assert drawn[label].get_markeredgecolor() == COLORS[role]
        # The flight's frequency is marked in both panels, the unchanged gain 1 on top.
        assert any(np.array_equal(line.get_xdata(), [0.5, 0.5]) for line in lead.get_lines())
        assert any(line.get_label().startswith("|H| = 1") for line in gain.get_lines())
        assert lead.get_ylabel() == "lead (ms), > 0 = ahead"
        assert lead.get_xlim() == pytest.approx((0.1, 10.0))
    finally:
        plt.close(fig)


@pytest.mark.parametrize(("frequency", "bad", "marked", "message"), [
    (np.array([0.0, 1.0]), None, 0.5, "frequency must be frequencies > 0 Hz"),
    (FREQUENCY[:, None], None, 0.5, "frequency must be frequencies > 0 Hz"),
    (FREQUENCY, "gain", 0.5, "curve 'fused' must have gain and lead of shape"),
    (FREQUENCY, None, 0.0, "marked must be a frequency > 0 Hz"),
])
def test_frequency_response_figure_refuses_what_it_cannot_draw(frequency, bad, marked, message):
    given = curves()
    if bad == "gain":
        given["fused"] = (np.ones(3), np.zeros(3), "estimate")
    with pytest.raises(ValueError, match=message):
        figures.frequency_response_figure(frequency, given, marked=marked)
    plt.close("all")


def test_the_trial_figure_puts_its_legend_above_the_data_under_the_title():
    """The readings fill the top panel from edge to edge: a legend inside covered them
    (notebook 03's Figure 1, drawn by tracking_comparison_figure)."""
    times = np.linspace(0.0, 10.0, 1001)
    truth = 10 * np.sin(np.pi * times)
    fig = figures.tracking_comparison_figure(
        times, truth, {"vision only": (truth + 0.5, "alternative"),
                       "vision + proprioception": (truth - 0.5, "estimate")},
        readings={"vision readings": (truth + 3.0, "vision"),
                  "proprioception readings": (truth - 3.0, "proprioception")},
        title="σ_v = σ_p = 1.5 cm")
    try:
        fig.canvas.draw()
        top = fig.axes[0]
        legend = top.get_legend()
        assert [text.get_text() for text in legend.get_texts()] == [
            "vision readings", "proprioception readings", "true position", "vision only",
            "vision + proprioception"]
        renderer = fig.canvas.get_renderer()
        panel = top.get_window_extent(renderer)
        box = legend.get_window_extent(renderer)
        title = top.title.get_window_extent(renderer)
        assert box.y0 >= panel.y1 - 1          # above the data, not over it
        assert title.y0 >= box.y1 - 1          # and under the title
        assert fig.bbox.contains(box.x0, box.y0) and fig.bbox.contains(box.x1, box.y1)
    finally:
        plt.close(fig)
