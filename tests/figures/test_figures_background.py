"""Tests of the figures of notebook 00 added for its Going further E (lqe_helpers.figures)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

from lqe_helpers import figures
from lqe_helpers.plotting import COLORS


def test_jerk_choice_figure_draws_three_criteria_and_marks_each_choice():
    grid = np.array([700.0, 1000.0, 1400.0, 2000.0, 2800.0])
    likelihood = np.array([-20.0, -5.0, 0.0, -4.0, -15.0]) - 3000.0
    nis = np.array([1.05, 1.02, 0.99, 0.97, 0.95])
    mse = np.array([0.45, 0.40, 0.38, 0.39, 0.42])
    chosen = {"likelihood": 1400.0, "NIS": 1200.0, "MSE": 1350.0}
    fig = figures.jerk_choice_figure(grid, likelihood, nis, mse, chosen)
    try:
        top, middle, bottom = fig.axes
        # The likelihood is drawn relative to its largest value; NIS and MSE as given.
        np.testing.assert_array_equal(top.get_lines()[0].get_ydata(), likelihood - likelihood.max())
        np.testing.assert_array_equal(middle.get_lines()[0].get_ydata(), nis)
        np.testing.assert_array_equal(bottom.get_lines()[0].get_ydata(), mse)
        for ax in fig.axes:
            marks = {line.get_label(): line for line in ax.get_lines()[1:4]}
            assert sorted(marks) == sorted(f"chosen by {key}: {value:,.0f} cm/s³"
                                           for key, value in chosen.items())
            styles = {line.get_linestyle() for line in marks.values()}
            assert len(styles) == 3, "the three choices differ by line style, not colour alone"
        expected = [line for line in middle.get_lines() if line.get_label().startswith("expected")]
        assert expected and expected[0].get_color() == COLORS["reference"]
        assert np.allclose(expected[0].get_ydata(), 1.0)
        assert bottom.get_xscale() == "log" and "cm/s³" in bottom.get_xlabel()
    finally:
        plt.close(fig)


def test_jerk_choice_figure_refuses_curves_off_the_grid_and_unknown_choices():
    grid = np.array([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="the grid's shape"):
        figures.jerk_choice_figure(grid, np.zeros(2), np.zeros(3), np.zeros(3), {})
    with pytest.raises(ValueError, match="chosen must be keyed by"):
        figures.jerk_choice_figure(grid, np.zeros(3), np.zeros(3), np.zeros(3), {"AIC": 2.0})


@pytest.mark.parametrize("rows", [2, 4, 6])
def test_mse_intervals_figure_keeps_its_legend_off_every_interval(rows):
    """The trial found the legend beside the whole period's point (lower right): it now
    sits below the axis label, clear of the axes and of the label."""
    from lqe_helpers import metrics

    values = np.linspace(0.38, 0.47, rows)[::-1]
    intervals = [metrics.Interval(v, v - 0.003, v + 0.003, 300) for v in values]
    fig = figures.mse_intervals_figure([f"row {i}" for i in range(rows)], intervals,
                                       xlabel="MSE (cm²)", reference=0.4, reference_label="ref")
    try:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        ax = fig.axes[0]
        legend = ax.get_legend().get_window_extent(renderer)
        assert legend.y1 < ax.get_window_extent(renderer).y0
        assert legend.y1 < ax.xaxis.label.get_window_extent(renderer).y0
        assert legend.y0 >= 0, "the legend stays inside the figure"
    finally:
        plt.close(fig)
