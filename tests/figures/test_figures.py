"""Tests of lqe_helpers.figures: each function draws the data it is given."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.figure import Figure

from lqe_helpers import figures

# --- tracking_comparison_figure, paired_mse_figure, start_up_figure, squared_error_figure ---

def test_tracking_comparison_figure_draws_estimates_and_their_errors():
    times = np.linspace(0.0, 1.0, 11)
    truth = np.sin(times)
    estimate = truth + 0.1 * np.cos(7 * times)
    readings = truth + 0.5
    fig = figures.tracking_comparison_figure(
        times, truth, {"fused": (estimate, "estimate")},
        readings={"vision": (readings, "vision")}, title="σ_v = 1.5 cm")
    try:
        assert isinstance(fig, Figure)
        top, bottom = fig.axes
        lines = top.get_lines()
        np.testing.assert_array_equal(lines[0].get_ydata(), readings)
        np.testing.assert_array_equal(lines[1].get_ydata(), truth)
        np.testing.assert_array_equal(lines[2].get_ydata(), estimate)
        error = next(line for line in bottom.get_lines() if line.get_label() == "fused")
        np.testing.assert_allclose(error.get_ydata(), estimate - truth)
        assert top.get_title() == "σ_v = 1.5 cm"
        # The legend sits above the panel (under the title), not over the data.
        renderer = fig.canvas.get_renderer()
        legend, panel = top.get_legend().get_window_extent(renderer), top.get_window_extent()
        title = top.title.get_window_extent(renderer)
        assert panel.y1 <= legend.y0 and legend.y1 <= title.y0
        assert [text.get_text() for text in top.get_legend().get_texts()] == [
            "vision", "true position", "fused"]
    finally:
        plt.close(fig)


def test_paired_mse_figure_puts_one_point_per_run():
    first = np.array([1.0, 2.0, 3.0])
    second = np.array([0.5, 1.5, 3.5])
    fig = figures.paired_mse_figure(first, second, "vision only", "fused")
    try:
        runs = fig.axes[0].get_lines()[0]
        np.testing.assert_array_equal(runs.get_xdata(), first)
        np.testing.assert_array_equal(runs.get_ydata(), second)
        assert "vision only" in fig.axes[0].get_xlabel()
    finally:
        plt.close(fig)


def test_paired_mse_figure_rejects_unpaired_runs():
    with pytest.raises(ValueError, match="paired"):
        figures.paired_mse_figure(np.ones(3), np.ones(4), "a", "b")


def test_start_up_figure_shows_position_and_velocity_up_to_until():
    times = np.arange(0.0, 3.0, 0.5)
    truth = np.stack([times, 2 * times], axis=1)
    estimate = truth + 1.0
    fig = figures.start_up_figure(times, truth, {"P0 = diag(1)": (estimate, "estimate")},
                                  until=1.0)
    try:
        ax_p, ax_v = fig.axes
        shown = times <= 1.0
        np.testing.assert_array_equal(ax_p.get_lines()[1].get_ydata(), estimate[shown, 0])
        np.testing.assert_array_equal(ax_v.get_lines()[1].get_ydata(), estimate[shown, 1])
        # The legend sits between the position panel and its title, clear of the data.
        renderer = fig.canvas.get_renderer()
        legend = ax_p.get_legend().get_window_extent(renderer)
        assert ax_p.get_window_extent().y1 <= legend.y0
        assert legend.y1 <= ax_p.title.get_window_extent(renderer).y0
        assert ax_p.get_title() == "Position"
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="until"):
        figures.start_up_figure(times, truth, {}, until=0.0)


def test_squared_error_figure_draws_curves_on_a_log_axis():
    times = np.linspace(0.0, 2.0, 21)
    curve = np.exp(-times) + 0.1
    fig = figures.squared_error_figure(times, {"diag(1)": (curve, "estimate")},
                                       threshold=0.2, marks={"t": (0.5, "estimate")})
    try:
        ax = fig.axes[0]
        assert ax.get_yscale() == "log"
        np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), curve)
        assert any(np.allclose(line.get_ydata(), 0.2) for line in ax.get_lines()[1:])
    finally:
        plt.close(fig)


# --- estimate_error_figure, delay_figure (notebooks 01 and 05) ---

def test_estimate_error_figure_draws_each_error_and_its_band():
    times = np.linspace(0.0, 2.0, 21)
    error = 0.3 * np.sin(3 * times)
    systematic = 0.1 * np.cos(times)
    std = np.full_like(times, 0.5)
    fig = figures.estimate_error_figure(
        times, {"σ_v = 1.5 cm": (error, std, systematic, "estimate"),
                "σ_v = 4.5 cm": (2 * error, 2 * std, 2 * systematic, "alternative")},
        skipped=0.5)
    try:
        assert isinstance(fig, Figure)
        first, second = fig.axes
        np.testing.assert_array_equal(first.get_lines()[0].get_ydata(), error)
        np.testing.assert_array_equal(first.get_lines()[1].get_ydata(), systematic)
        np.testing.assert_array_equal(second.get_lines()[0].get_ydata(), 2 * error)
        band = first.collections[0].get_paths()[0].vertices[:, 1]
        assert band.max() == pytest.approx(1.0) and band.min() == pytest.approx(-1.0)
        assert first.get_title(loc="left") == "σ_v = 1.5 cm"
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="panels"):
        figures.estimate_error_figure(times, {})


def test_delay_figure_draws_the_four_series_and_shades_the_start():
    times = np.arange(0.0, 1.0, 0.01)
    truth = np.sin(2 * np.pi * times)
    late = np.concatenate([np.full(10, np.nan), truth[:-10]])
    fig = figures.delay_figure(times, truth, late + 0.2, late, truth + 0.05, delay=0.1,
                               fast_window=(0.4, 0.6))
    try:
        ax_all, ax_start, ax_fast = fig.axes
        lines = ax_all.get_lines()
        np.testing.assert_array_equal(lines[0].get_ydata(), late + 0.2)
        np.testing.assert_array_equal(lines[1].get_ydata(), truth)
        np.testing.assert_array_equal(lines[2].get_ydata(), late)
        np.testing.assert_array_equal(lines[3].get_ydata(), truth + 0.05)
        assert ax_start.get_xlim() == pytest.approx((0.0, 0.5))
        assert ax_fast.get_xlim() == pytest.approx((0.4, 0.6))
        assert ax_fast.get_title() == "Fast flight, 0.4–0.6 s"   # says where, not what
        shaded = ax_start.patches[0].get_extents().transformed(ax_start.transData.inverted())
        assert shaded.x0 == pytest.approx(0.0) and shaded.x1 == pytest.approx(0.1)
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="delay"):
        figures.delay_figure(times, truth, late, late, truth, delay=0.0)


# --- notebooks 00 and 06: open_loop_figure, mse_intervals_figure, uncertainty_growth_figure,
# --- jerk_sweep_figure, tracking_panels_figure, bias_learning_figure,
# --- acceleration_signal_figure, drift_figure, noise_sweep_figure, bias_settling_figure

def _intervals(means, half=0.1):
    from lqe_helpers.metrics import Interval

    return [Interval(mean=m, low=m - half, high=m + half, runs=10) for m in means]


def test_open_loop_figure_draws_tracking_then_the_prediction_and_its_band():
    times = np.arange(0.0, 3.0, 0.5)
    truth, readings, estimate = np.sin(times), np.sin(times) + 0.3, np.sin(times) + 0.1
    pred_times = np.array([2.0, 2.5])
    pred, std = np.array([1.0, 2.0]), np.array([0.5, 1.0])
    fig = figures.open_loop_figure(times, truth, readings, estimate, 2.0, pred_times, pred, std,
                                   start=0.0)
    try:
        lines = fig.axes[0].get_lines()
        np.testing.assert_array_equal(lines[0].get_ydata(), readings[times <= 2.0])
        np.testing.assert_array_equal(lines[2].get_ydata(), estimate[times <= 2.0])
        np.testing.assert_array_equal(lines[3].get_ydata(), pred)
        band = fig.axes[0].collections[0].get_paths()[0].vertices[:, 1]
        assert band.max() == pytest.approx(4.0) and band.min() == pytest.approx(0.0)
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="limit"):
        figures.open_loop_figure(times, truth, readings, estimate, 2.0, pred_times, pred, std,
                                 limit=0.0)


def test_mse_intervals_figure_puts_one_row_per_interval():
    fig = figures.mse_intervals_figure(["a", "b"], _intervals([1.0, 2.0]), reference=1.5)
    try:
        np.testing.assert_array_equal(fig.axes[0].get_lines()[0].get_xdata(), [1.0, 2.0])
        assert [t.get_text() for t in fig.axes[0].get_yticklabels()] == ["a", "b"]
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="labels"):
        figures.mse_intervals_figure(["a"], _intervals([1.0, 2.0]))


def test_uncertainty_growth_figure_draws_each_curve_on_log_axes():
    elapsed = np.array([0.1, 0.5, 1.0])
    fig = figures.uncertainty_growth_figure(elapsed, {"P = 0": (elapsed**2.5, "-", 2.0)},
                                            amplitude=10.0)
    try:
        ax = fig.axes[0]
        assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
        np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), elapsed**2.5)
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="elapsed"):
        figures.uncertainty_growth_figure(np.array([0.0, 1.0]), {})


def test_jerk_sweep_figure_draws_the_mse_and_its_parts():
    jerks = np.array([10.0, 100.0, 1000.0])
    fig = figures.jerk_sweep_figure(jerks, _intervals([3.0, 1.0, 2.0]), [2.9, 0.5, 0.1],
                                    [0.1, 0.5, 1.9], [0.01, 0.9, 2.5], 2.25, 100.0)
    try:
        lines = fig.axes[0].get_lines()
        np.testing.assert_array_equal(lines[0].get_ydata(), [3.0, 1.0, 2.0])
        data = [np.asarray(line.get_ydata()).tolist() for line in lines]
        assert [2.9, 0.5, 0.1] in data and [0.01, 0.9, 2.5] in data
    finally:
        plt.close(fig)


def test_tracking_panels_figure_draws_one_panel_per_filter():
    times = np.linspace(0.0, 5.0, 51)
    truth = np.sin(times)
    fig = figures.tracking_panels_figure(times, truth, truth + 0.5,
                                         {"slow": truth * 0.5, "fast": truth * 2}, (2.0, 4.0))
    try:
        shown = (times >= 2.0) & (times <= 4.0)
        assert len(fig.axes) == 2
        np.testing.assert_array_equal(fig.axes[1].get_lines()[2].get_ydata(), 2 * truth[shown])
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="window"):
        figures.tracking_panels_figure(times, truth, truth, {"a": truth}, (4.0, 2.0))


def test_bias_learning_figure_draws_the_run_and_the_monte_carlo_error():
    times = np.linspace(0.0, 4.0, 41)
    estimate = 20 * (1 - np.exp(-times))
    fig = figures.bias_learning_figure(times, estimate, np.full_like(times, 2.0), 20.0,
                                       np.exp(-times) + 0.1, np.exp(-times) + 0.2, until=3.0)
    try:
        ax_run, ax_mc = fig.axes
        np.testing.assert_array_equal(ax_run.get_lines()[1].get_ydata(), estimate[times <= 3.0])
        np.testing.assert_array_equal(ax_mc.get_lines()[0].get_ydata(), np.exp(-times) + 0.1)
        assert ax_mc.get_yscale() == "log"
    finally:
        plt.close(fig)


def test_acceleration_signal_figure_draws_readings_truth_and_shifted_truth():
    times = np.linspace(0.0, 3.0, 31)
    accel = np.cos(times)
    fig = figures.acceleration_signal_figure(times, accel + 5.0, accel, bias=4.0)
    try:
        lines = fig.axes[0].get_lines()
        shown = times <= 2.0
        np.testing.assert_array_equal(lines[0].get_ydata(), accel[shown] + 5.0)
        np.testing.assert_allclose(lines[2].get_ydata(), accel[shown] + 4.0)
    finally:
        plt.close(fig)


def test_drift_figure_draws_theory_then_errors():
    elapsed = np.array([0.1, 1.0, 10.0])
    fig = figures.drift_figure(elapsed, {"dead reckoning": (elapsed**2, "alternative", "-")},
                               {"b t²/2": (elapsed**2 / 2, "-")}, amplitude=10.0)
    try:
        lines = fig.axes[0].get_lines()
        np.testing.assert_array_equal(lines[0].get_ydata(), elapsed**2 / 2)
        np.testing.assert_array_equal(lines[1].get_ydata(), elapsed**2)
    finally:
        plt.close(fig)


def test_noise_sweep_figure_draws_mse_and_bias_errors():
    values = np.array([1.0, 10.0, 100.0])
    fig = figures.noise_sweep_figure(values, _intervals([0.1, 0.2, 0.9]), _intervals([0.4])[0],
                                     [0.1, 1.0, 10.0], [0.12, 1.1, 9.0], 10.0, "σ_a (cm/s²)")
    try:
        ax_mse, ax_bias = fig.axes
        np.testing.assert_array_equal(ax_mse.get_lines()[0].get_ydata(), [0.1, 0.2, 0.9])
        np.testing.assert_array_equal(ax_bias.get_lines()[0].get_ydata(), [0.1, 1.0, 10.0])
    finally:
        plt.close(fig)


def test_bias_settling_figure_draws_mean_errors_and_filter_stds():
    times = np.linspace(0.0, 4.0, 41)
    fig = figures.bias_settling_figure(times, {"b = 20": -20 * np.exp(-times)},
                                       {"σ_v = 1.5": np.exp(-times) + 0.1})
    try:
        ax_b, ax_v = fig.axes
        early = times <= 2.0
        np.testing.assert_array_equal(ax_b.get_lines()[0].get_ydata(),
                                      -20 * np.exp(-times[early]))
        np.testing.assert_array_equal(ax_v.get_lines()[0].get_ydata(), np.exp(-times) + 0.1)
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="until"):
        figures.bias_settling_figure(times, {}, {}, until=0.0)


def _sweep():
    """A small delay sweep: 0–0.4 s, compensation hurting first and last."""
    delays = np.linspace(0.0, 0.4, 5)
    share = [-0.0, -0.3, 0.5, 0.2, -0.4]
    delayed = _intervals([1.0, 2.0, 4.0, 8.0, 16.0])
    compensated = _intervals([1.0, 2.5, 2.0, 6.0, 20.0])
    return delays, delayed, compensated, _intervals(share)


def test_delay_sweep_figure_draws_both_panels_and_points_at_the_losses():
    delays, delayed, compensated, share = _sweep()
    theory_delays = np.linspace(0.0, 1.0, 11)
    fig = figures.delay_sweep_figure(delays, delayed, compensated, 1.0, theory_delays,
                                     theory_delays + 1.0, delays**2, share, delay=0.15)
    try:
        ax_mse, ax_share = fig.axes
        lines = ax_mse.get_lines()
        np.testing.assert_array_equal(lines[0].get_ydata(), [1.0, 2.0, 4.0, 8.0, 16.0])
        np.testing.assert_array_equal(lines[1].get_ydata(), [1.0, 2.5, 2.0, 6.0, 20.0])
        np.testing.assert_allclose(lines[2].get_xdata(), theory_delays[:5])  # within the sweep
        np.testing.assert_allclose(lines[3].get_ydata(), (delays**2)[1:])    # no d = 0
        assert ax_mse.get_yscale() == "log"
        assert ax_mse.get_xlim() == ax_share.get_xlim() == (0.0, 0.4)
        np.testing.assert_array_equal(ax_share.get_lines()[0].get_ydata(),
                                      [interval.mean for interval in share])
        arrows = [text for text in ax_share.texts if hasattr(text, "xy")]
        # The deepest loss before the question's delay (0.15 s) and the late one.
        assert [tuple(np.round(arrow.xy, 6)) for arrow in arrows] == [(0.1, -0.3), (0.4, -0.4)]
    finally:
        plt.close(fig)


def test_delay_sweep_figure_draws_no_arrow_where_compensation_never_hurts():
    delays, delayed, compensated, _ = _sweep()
    fig = figures.delay_sweep_figure(delays, delayed, compensated, 1.0, delays, delays + 1.0,
                                     delays**2, _intervals([0.0, 0.1, 0.5, 0.2, 0.1]), 0.1)
    try:
        assert not [text for text in fig.axes[1].texts if hasattr(text, "xy")]
    finally:
        plt.close(fig)


def test_prediction_error_sources_figure_draws_theory_parts_and_simulation():
    theory_delays = np.array([0.0, 0.01, 0.1, 1.0])
    extrapolated = np.array([0.5, 0.6, 2.0, 50.0])
    jerks = np.array([0.0, 1e-6, 1e-2, 100.0])
    fig = figures.prediction_error_sources_figure(
        theory_delays, extrapolated + jerks, extrapolated, jerks, np.array([0.0, 0.01, 0.02]),
        _intervals([0.5, 0.61, 0.7]), takeover=0.8)
    try:
        ax, = fig.axes
        lines = ax.get_lines()
        np.testing.assert_allclose(lines[0].get_xdata(), [0.01, 0.1, 1.0])   # d > 0 only
        np.testing.assert_allclose(lines[0].get_ydata(), (extrapolated + jerks)[1:])
        np.testing.assert_allclose(lines[1].get_ydata(), extrapolated[1:])
        np.testing.assert_allclose(lines[2].get_ydata(), jerks[1:])
        np.testing.assert_allclose(lines[3].get_ydata(), [0.61, 0.7])
        assert ax.get_xscale() == ax.get_yscale() == "log"
        assert any("from d = 0.80 s" in text.get_text() for text in ax.texts)
    finally:
        plt.close(fig)


def test_belief_and_error_figure_draws_error_then_belief_for_each_filter():
    times = np.arange(300) * 0.01
    error = 1.0 + np.exp(-times)
    belief = 0.5 + np.exp(-2 * times)
    fig = figures.belief_and_error_figure(
        times, {"P0 = diag(1)": (error, belief, 0.4, "estimate"),
                "P0 = diag(1e5)": (2 * error, 2 * belief, 0.1, "alternative")},
        steady_variance=0.4, threshold=0.8, runs=50)
    try:
        ax, = fig.axes
        lines = ax.get_lines()
        shown = times <= 2.0
        np.testing.assert_allclose(lines[0].get_ydata(), error[shown])
        np.testing.assert_allclose(lines[1].get_ydata(), belief[shown])
        np.testing.assert_allclose(lines[3].get_ydata(), 2 * error[shown])   # after a mark
        assert lines[0].get_label() == "P0 = diag(1): mean squared error (50 runs)"
        assert [text.get_text() for text in ax.texts] == [" converged\n 0.40 s",
                                                          " converged\n 0.10 s"]
        assert ax.get_yscale() == "log" and ax.get_xlim() == (0.0, 2.0)
    finally:
        plt.close(fig)


def test_gains_figure_draws_one_panel_per_state_with_the_steady_gain():
    times = np.arange(200) * 0.01
    gain = np.stack([0.1 + times, 1 + times, 10 + times], axis=-1)       # (n, 3)
    fig = figures.gains_figure(times, {"P0 = diag(1)": (gain, "estimate")},
                               np.array([[0.5], [5.0], [50.0]]))
    try:
        assert len(fig.axes) == 3
        early = times <= 1.5
        for state, ax in enumerate(fig.axes):
            first, steady = ax.get_lines()
            np.testing.assert_allclose(first.get_ydata(), gain[early, state])
            assert steady.get_ydata()[0] == [0.5, 5.0, 50.0][state]
            assert ax.get_yscale() == "log"
    finally:
        plt.close(fig)


def test_p0_sweep_figure_draws_convergence_and_both_mses_against_p0():
    grid = np.logspace(-2, 6, 5)
    fig = figures.p0_sweep_figure(
        grid, _intervals([0.5, 0.3, 0.1, 0.1, 0.2]), _intervals([3.0, 2.0, 1.0, 1.0, 1.5]),
        _intervals([0.4, 0.4, 0.4, 0.4, 0.4], half=0.01), 1.0, {"diag(1)": 1.0},
        {"A²": 100.0}, (1.0, 1e4), 0.1)
    try:
        ax_t, ax_m = fig.axes
        assert ax_t.get_xscale() == ax_m.get_xscale() == "log"
        np.testing.assert_allclose(ax_t.get_lines()[0].get_ydata(), [0.5, 0.3, 0.1, 0.1, 0.2])
        labels = ax_m.get_legend_handles_labels()[1]
        assert "MSE over the first 1 s" in labels and "MSE after 1 s" in labels
        assert "plateau: start-up MSE within 10 % of best" in labels
    finally:
        plt.close(fig)


def test_proprioception_sweep_figure_draws_simulation_and_theory_in_both_panels():
    from lqe_helpers.metrics import Interval

    sigma_p = np.array([0.3, 1.5, 4.5, 100.0])
    fig = figures.proprioception_sweep_figure(
        sigma_p, _intervals([0.05, 0.2, 0.35, 0.38], half=0.01),
        _intervals([90.0, 45.0, 10.0, 0.0]), np.geomspace(0.3, 100, 7), np.linspace(0, 0.4, 7),
        np.linspace(90, 0, 7), Interval(0.38, 0.37, 0.39, 10), 0.4, 1.5,
        {"(c)": 1.5, "(d)": 4.5}, ticks=[0.3, 1, 3, 10, 30, 100])
    try:
        ax_mse, ax_margin = fig.axes
        np.testing.assert_allclose(ax_mse.get_lines()[0].get_ydata(), [0.05, 0.2, 0.35, 0.38])
        np.testing.assert_allclose(ax_margin.get_lines()[0].get_ydata(), [90, 45, 10, 0])
        assert ax_mse.get_ylim() == pytest.approx((0.0, 1.15 * 0.4))
        assert [label.get_text() for label in ax_mse.get_xticklabels()] == [
            "0.3", "1", "3", "10", "30", "100"]
        assert [text.get_text() for text in ax_margin.texts] == ["(c)", "(d)"]
    finally:
        plt.close(fig)


def test_assumed_noise_figure_zooms_on_the_cost_of_misjudging():
    assumed = np.array([0.5, 1.5, 4.5, 13.5, 40.0])
    fig = figures.assumed_noise_figure(
        assumed, _intervals([3.0, 1.0, 0.35, 0.37, 0.38], half=0.01),
        _intervals([2.6, 0.6, 0.0, 0.02, 0.03], half=0.002), 0.38, 0.032, 4.5, 1.5, 300,
        ticks=[0.5, 1, 2, 5, 10, 20, 40], mse_ticks=[0.4, 1, 3])
    try:
        ax, ax_cost = fig.axes
        np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), [3.0, 1.0, 0.35, 0.37, 0.38])
        assert ax.get_yscale() == "log" and ax_cost.get_yscale() == "linear"
        assert ax_cost.get_ylim() == pytest.approx((-1.8 * 0.032 / 12, 1.8 * 0.032))
        assert [label.get_text() for label in ax.get_yticklabels()] == ["0.4", "1", "3"]
        assert "300 runs" in fig.get_suptitle()
    finally:
        plt.close(fig)


# --- the pieces every figure module shares ---

def test_label_axes_sets_scales_before_limits_and_draws_the_legend_asked_for():
    from lqe_helpers.figures.common import label_axes

    fig, ax = plt.subplots()
    try:
        ax.plot([1.0, 10.0], [1.0, 100.0], label="curve")
        label_axes(ax, "time (s)", "error (cm²)", "a title", yscale="log", xlim=(1.0, 10.0),
                   ylim=(0.5, 200.0), legend={"loc": "upper left", "fontsize": 8})
        assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_title()) == (
            "time (s)", "error (cm²)", "a title")
        assert ax.get_yscale() == "log" and ax.get_xscale() == "linear"
        assert ax.get_xlim() == (1.0, 10.0) and ax.get_ylim() == (0.5, 200.0)
        assert [t.get_text() for t in ax.get_legend().get_texts()] == ["curve"]
        label_axes(ax, title="another")  # only what is given changes
        assert (ax.get_xlabel(), ax.get_title()) == ("time (s)", "another")
    finally:
        plt.close(fig)


def test_first_seconds_masks_up_to_until_and_refuses_a_non_positive_until():
    from lqe_helpers.figures.common import first_seconds

    times, shown = first_seconds([0, 1, 2, 3], 2.0)
    assert times.dtype == float
    np.testing.assert_array_equal(shown, [True, True, True, False])
    with pytest.raises(ValueError, match="until must be > 0 s, got 0"):
        first_seconds([0, 1], 0)


def test_errorbar_intervals_and_mean_band_draw_the_means_and_their_intervals():
    from lqe_helpers.figures.common import errorbar_intervals, mean_band
    from lqe_helpers.metrics import Interval

    intervals = [Interval(1.0, 0.5, 1.25, 10), Interval(2.0, 1.0, 3.5, 10)]
    fig, ax = plt.subplots()
    try:
        errorbar_intervals(ax, np.array([1.0, 2.0]), intervals, "estimate", marker="o")
        (container,) = ax.containers
        np.testing.assert_array_equal(container.lines[0].get_ydata(), [1.0, 2.0])
        segments = container.lines[2][0].get_segments()
        np.testing.assert_array_equal([s[:, 1] for s in segments], [[0.5, 1.25], [1.0, 3.5]])
        means = mean_band(ax, np.array([1.0, 2.0]), intervals, "prediction", "band")
        np.testing.assert_array_equal(means, [1.0, 2.0])
        assert ax.get_lines()[-1].get_label() == "band"
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="intervals must hold at least one interval"):
        mean_band(None, np.array([]), [], "estimate", "empty")
