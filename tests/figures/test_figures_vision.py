"""Figures of notebook 01 that tests/figures/test_figures.py does not cover: the lag figure."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

from lqe_helpers import figures
from lqe_helpers.plotting import COLORS


def test_lag_figure_draws_each_case_in_its_window_with_the_truth():
    times = np.linspace(0.0, 2.0, 201)
    truth = np.sin(np.pi * times)
    late, early = np.sin(np.pi * (times - 0.1)), np.sin(np.pi * (times + 0.02))
    fig = figures.lag_figure(times, truth, {
        "σ_v = 1.5 cm": {"LQE": (early, "estimate"), "smoother": (late, "alternative")},
        "σ_v = 4.5 cm": {"LQE": (2 * early, "estimate")}}, window=(0.25, 0.75))
    try:
        first, second = fig.axes
        shown = (times >= 0.25) & (times <= 0.75)
        truth_line, lqe, smoother = first.get_lines()
        np.testing.assert_array_equal(truth_line.get_xdata(), times[shown])
        np.testing.assert_array_equal(truth_line.get_ydata(), truth[shown])
        np.testing.assert_array_equal(lqe.get_ydata(), early[shown])
        np.testing.assert_array_equal(smoother.get_ydata(), late[shown])
        assert [line.get_color() for line in (truth_line, lqe, smoother)] == [
            COLORS["truth"], COLORS["estimate"], COLORS["alternative"]]
        assert smoother.get_linestyle() != lqe.get_linestyle()   # not by colour alone
        assert [text.get_text() for text in first.get_legend().get_texts()] == [
            "true position", "LQE", "smoother"]
        assert first.get_xlim() == pytest.approx((0.25, 0.75))
        assert first.get_title() == "σ_v = 1.5 cm" and first.get_ylabel() == "position (cm)"
        assert first.get_xlabel() == "time (s)" == second.get_xlabel()
        np.testing.assert_array_equal(second.get_lines()[1].get_ydata(), 2 * early[shown])
    finally:
        plt.close(fig)


@pytest.mark.parametrize(("panels", "window", "match"), [
    ({}, (0.2, 0.5), "panels must hold at least one case"),
    ({"a": {}}, (0.5, 0.2), r"window must be \(start, end\) with 0 <= start < end <= 2 s"),
    ({"a": {}}, (-1.0, 0.5), "window must be"),
])
def test_lag_figure_refuses_what_it_cannot_draw(panels, window, match):
    times = np.linspace(0.0, 2.0, 21)
    with pytest.raises(ValueError, match=match):
        figures.lag_figure(times, np.zeros_like(times), panels, window)
