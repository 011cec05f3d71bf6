"""The P0 explorer of question (b) draws what the engine, or the student's filter, computes."""

from __future__ import annotations

import dataclasses
import html

import numpy as np
import pytest
import traitlets
from explorer_checks import EXPLORER_SCENARIO, assert_only_numbers_change, band_matches, line, png
from matplotlib.figure import Figure

from lqe_helpers import experiments, metrics
from lqe_helpers.explorers import initial_covariance as ic
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.student_code import calling

SHOWN = round(ic.WINDOW / DEFAULT.dt) + 1


@pytest.fixture
def explorer():
    """A new explorer for every test, so no test sees another's slider moves."""
    return ic.explore_initial_covariance()


def test_slider_is_logarithmic_over_the_documented_range(explorer) -> None:
    slider = explorer.sliders["p0_variance"]
    assert slider.description == "P0 (cm²)"
    assert slider.base == 10
    assert (10.0**slider.min, 10.0**slider.max) == pytest.approx(ic.P0_RANGE)
    assert slider.step == pytest.approx(1 / ic.P0_STEPS_PER_DECADE)
    assert slider.value == DEFAULT.p0_variance
    assert slider.continuous_update is False
    assert slider.readout_format == ".3g"
    # The question's two values are reachable slider positions.
    for value in (1.0, 1e5):
        position = (np.log10(value) - slider.min) / slider.step
        assert position == pytest.approx(round(position))


def test_an_exponent_set_from_code_is_refused_not_clipped(explorer) -> None:
    """P0 = 10⁻² set as -2 raises; ipywidgets alone clipped it to 0.01 and drew that."""
    numbers = explorer.numbers
    with pytest.raises(traitlets.TraitError, match=r"the value itself, not its exponent"):
        explorer.sliders["p0_variance"].value = -2
    assert explorer.sliders["p0_variance"].value == DEFAULT.p0_variance
    assert explorer.numbers == numbers
    explorer.sliders["p0_variance"].value = 1e-2
    assert explorer.numbers.startswith("The pack's engine, P0 = 0.01 · I. ")


@pytest.mark.parametrize("p0_variance", [1e-2, 1e5, 1e6, 1.0])
@pytest.mark.slow
def test_moving_the_slider_redraws_the_direct_computation(explorer, p0_variance) -> None:
    explorer.sliders["p0_variance"].value = p0_variance
    position_ax, velocity_ax = explorer.figure.axes
    noise = EXPLORER_SCENARIO.unit_noise(sensors=("vision",))
    truth = DEFAULT.truth
    expected = experiments.track(DEFAULT, p0_variance=p0_variance, noise=noise)
    estimates = expected.result.estimates[:SHOWN]
    variances = expected.result.estimate_covariances[:SHOWN]

    np.testing.assert_allclose(line(position_ax, ic.VISION_LABEL),
                               truth[:SHOWN, 0] + DEFAULT.sigma_v * noise[:SHOWN, 0],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(line(position_ax, ic.TRUTH_LABEL), truth[:SHOWN, 0])
    np.testing.assert_allclose(line(velocity_ax, ic.TRUTH_LABEL), truth[:SHOWN, 1])
    for ax, column in ((position_ax, 0), (velocity_ax, 1)):
        np.testing.assert_allclose(line(ax, ic.ESTIMATE_LABEL), estimates[:, column],
                                   rtol=1e-12, atol=1e-9)
        std = np.sqrt(variances[:, column, column])
        band_matches(ax, ic.BAND_LABEL, estimates[:, column] - 2 * std,
                     estimates[:, column] + 2 * std)

    # The numbers go to the line beside the figure, not into it.
    burn = DEFAULT.burn_in_steps
    early = metrics.mse(expected.positions[:burn], truth[:burn, 0])
    late = metrics.mse(expected.positions, truth[:, 0], burn)
    assert explorer.numbers == (f"The pack's engine, P0 = {p0_variance:.3g} · I. Position MSE "
                                f"of this run: {early:.3g} cm² in the first "
                                f"{DEFAULT.burn_in:g} s, {late:.3g} cm² after.")
    assert explorer.figure.get_suptitle() == ""


def test_no_text_in_the_figure_changes_with_the_slider(explorer) -> None:
    assert_only_numbers_change(explorer, "p0_variance", 1e6)


def test_first_step_follows_tutorial_gain_formula(explorer) -> None:
    """K = P0 Cᵀ (C P0 Cᵀ + R)⁻¹ at the first sample, by hand, for P0 = p · I."""
    for p0_variance in (1.0, 1e5):
        explorer.sliders["p0_variance"].value = p0_variance
        position_ax, velocity_ax = explorer.figure.axes
        y0 = line(position_ax, ic.VISION_LABEL)[0]
        gain = p0_variance / (p0_variance + DEFAULT.sigma_v**2)
        # z0 = 0, so the prediction A·z0 = 0 and the first estimate is K·y0.
        assert line(position_ax, ic.ESTIMATE_LABEL)[0] == pytest.approx(gain * y0)
        # A diagonal P0 gives velocity no gain at the first sample.
        assert line(velocity_ax, ic.ESTIMATE_LABEL)[0] == pytest.approx(0.0, abs=1e-12)


def test_noise_pattern_stays_fixed_across_slider_moves(explorer) -> None:
    seen = []
    for p0_variance in (1e-2, 1e6, 1e-2):
        explorer.sliders["p0_variance"].value = p0_variance
        seen.append(line(explorer.figure.axes[0], ic.VISION_LABEL))
    np.testing.assert_array_equal(seen[0], seen[1])
    np.testing.assert_array_equal(seen[0], seen[2])


def test_steady_state_part_does_not_depend_on_p0() -> None:
    """Different P0 give (nearly) the same estimates once the start-up is over."""
    figure = Figure()
    late = []
    for p0_variance in (1e-2, 1e6):
        ic.draw_initial_covariance(figure, p0_variance=p0_variance)
        late.append(line(figure.axes[0], ic.ESTIMATE_LABEL)[-20:])
    np.testing.assert_allclose(late[0], late[1], atol=0.05)


def test_draw_function_on_a_fresh_figure_with_given_noise() -> None:
    figure = Figure()
    noise = np.zeros((DEFAULT.n_steps, 1))
    ic.draw_initial_covariance(figure, p0_variance=1e5, noise=noise)
    position_ax, velocity_ax = figure.axes
    np.testing.assert_array_equal(line(position_ax, ic.VISION_LABEL), DEFAULT.truth[:SHOWN, 0])
    expected = experiments.track(DEFAULT, p0_variance=1e5, noise=noise)
    np.testing.assert_allclose(line(velocity_ax, ic.ESTIMATE_LABEL),
                               expected.result.estimates[:SHOWN, 1], rtol=1e-12, atol=1e-9)
    assert velocity_ax.get_ylim() == pytest.approx(
        (-2 * DEFAULT.truth[0, 1], 2 * DEFAULT.truth[0, 1]))
    ic.draw_initial_covariance(figure, p0_variance=1.0, noise=noise)
    assert len(figure.axes) == 2


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan, np.inf])
def test_bad_p0_variance_is_rejected_by_name(bad: float) -> None:
    with pytest.raises(ValueError, match="p0_variance"):
        ic.draw_initial_covariance(Figure(), p0_variance=bad)


def test_static_display_carries_the_picture(explorer) -> None:
    bundle = explorer._repr_mimebundle_()
    assert "P0 (cm²)" in bundle["text/html"]
    assert explorer.png.startswith(b"\x89PNG")
    assert explorer.numbers.startswith(f"The pack's engine, P0 = {DEFAULT.p0_variance:.3g} · I. ")
    assert html.escape(explorer.numbers) in bundle["text/html"]


@pytest.mark.slow
def test_redraw_in_place_gives_the_same_picture_as_a_fresh_figure() -> None:
    reused = Figure(figsize=(9, 4))
    for p0_variance in (1e6, 1e-2, 31.6):
        ic.draw_initial_covariance(reused, p0_variance=p0_variance)
        fresh = Figure(figsize=(9, 4))
        ic.draw_initial_covariance(fresh, p0_variance=p0_variance)
        assert png(reused) == png(fresh)
    assert len(reused.axes) == 2


def test_foreign_or_cleared_figure_is_rebuilt() -> None:
    figure = Figure()
    figure.add_subplot().plot([0, 1], [5, 6], label="someone else's line")
    ic.draw_initial_covariance(figure, p0_variance=1.0)
    assert len(figure.axes) == 2
    assert "someone else's line" not in [a.get_label() for a in figure.axes[0].get_lines()]
    figure.clear()
    numbers = ic.draw_initial_covariance(figure, p0_variance=1e3)
    assert len(figure.axes) == 2
    assert numbers.startswith("The pack's engine, P0 = 1e+03 · I. ")


def test_slider_starts_at_the_scenarios_p0_variance() -> None:
    scenario = dataclasses.replace(DEFAULT, p0_variance=1e5)
    slider = ic.explore_initial_covariance(scenario).sliders["p0_variance"]
    assert slider.value == pytest.approx(1e5)


@pytest.mark.parametrize("p0_variance", [1e-3, 1e7])
def test_scenario_outside_the_slider_range_is_refused(p0_variance: float) -> None:
    """Not clipped into the range: the explorer would show another P0 than asked for."""
    scenario = dataclasses.replace(DEFAULT, p0_variance=p0_variance)
    with pytest.raises(ValueError, match=r"scenario\.p0_variance .*\[0\.01, 1000000\] cm²"):
        ic.explore_initial_covariance(scenario)


# ------------------------------------------------------------------------------------------
# The student's own filter drives the explorer
# ------------------------------------------------------------------------------------------


def my_filter(y, A, C, Q, R, z0, P0):
    """A correct student's filter. (This file ships to students, so it wraps the engine
    rather than spell out eq. (5), notebook 01's task.)"""
    return experiments.FilterModel(A, C, Q, R, z0, P0).filter(y).estimates


def shifted_filter(y, A, C, Q, R, z0, P0):
    """A student's filter whose positions are 0.5 cm too high: what it returns is drawn."""
    return my_filter(y, A, C, Q, R, z0, P0) + np.array([0.5, 0.0, 0.0])


def test_the_students_filter_draws_what_the_engine_computes() -> None:
    """Estimates equal to the engine's (1e-9), bands from the engine, numbers say whose."""
    ours, theirs = Figure(), Figure()
    for p0_variance in (1e-2, 1.0, 1e5, 1e6):
        mine = ic.draw_initial_covariance(ours, p0_variance=p0_variance, filter=my_filter)
        engine = ic.draw_initial_covariance(theirs, p0_variance=p0_variance)
        assert mine.startswith(f"Your my_filter, P0 = {p0_variance:.3g} · I. ")
        assert mine.removeprefix("Your my_filter") == engine.removeprefix("The pack's engine")
        for column in (0, 1):
            np.testing.assert_allclose(line(ours.axes[column], ic.ESTIMATE_LABEL),
                                       line(theirs.axes[column], ic.ESTIMATE_LABEL),
                                       rtol=1e-9, atol=1e-9)
            bands = [[path.vertices for path in ax.collections[0].get_paths()]
                     for ax in (ours.axes[column], theirs.axes[column])]
            np.testing.assert_allclose(bands[0][0], bands[1][0], rtol=1e-9, atol=1e-9)


@pytest.mark.slow
def test_the_explorer_draws_what_the_students_filter_returns() -> None:
    """The estimate and its MSEs come from the student's function, the band from the engine."""
    shifted, engine = Figure(), Figure()
    numbers = ic.draw_initial_covariance(shifted, p0_variance=1.0, filter=shifted_filter)
    ic.draw_initial_covariance(engine, p0_variance=1.0)
    np.testing.assert_allclose(line(shifted.axes[0], ic.ESTIMATE_LABEL),
                               line(engine.axes[0], ic.ESTIMATE_LABEL) + 0.5, atol=1e-9)
    positions = experiments.track(DEFAULT, p0_variance=1.0).positions + 0.5  # draw's default
    late = metrics.mse(positions, DEFAULT.truth[:, 0], DEFAULT.burn_in_steps)
    assert numbers.startswith("Your shifted_filter, P0 = 1 · I. ")
    assert numbers.endswith(f"{late:.3g} cm² after.")


def test_an_explorer_of_the_students_filter_says_whose_it_is() -> None:
    explorer = ic.explore_initial_covariance(filter=my_filter)
    assert explorer.problem == ""
    assert explorer.numbers.startswith("Your my_filter, P0 = 1 · I. ")
    assert "by your my_filter" in explorer.description
    assert "do not depend on the readings" in explorer.description
    explorer.sliders["p0_variance"].value = 1e5
    assert explorer.numbers.startswith("Your my_filter, P0 = 1e+05 · I. ")


def broken_filter(y, A, C, Q, R, z0, P0):
    """A student's filter with a slip: a matrix product that does not fit."""
    return A @ y


def not_written_filter(y, A, C, Q, R, z0, P0):
    raise NotImplementedError


def wrong_shape_filter(y, A, C, Q, R, z0, P0):
    """Returns the positions only."""
    return my_filter(y, A, C, Q, R, z0, P0)[:, 0]


@pytest.mark.parametrize(("function", "phrase"), [
    (broken_filter, "broken_filter raised ValueError"),
    (not_written_filter, "not_written_filter is not written yet"),
    (wrong_shape_filter, "wrong_shape_filter returned an array of shape (1000,)"),
])
def test_a_broken_students_filter_is_one_line_and_the_next_move_tries_again(function,
                                                                           phrase) -> None:
    explorer = ic.explore_initial_covariance(filter=function)
    assert phrase in explorer.problem, explorer.problem
    assert explorer.numbers == explorer.problem and "\n" not in explorer.problem
    assert explorer.png.startswith(b"\x89PNG")            # a picture all the same
    explorer.sliders["p0_variance"].value = 1e3           # the next move tries again
    assert phrase in explorer.problem


def test_a_students_filter_that_hangs_is_stopped(monkeypatch) -> None:
    monkeypatch.setattr(calling, "TIME_LIMIT", 0.2)

    def hanging_filter(y, A, C, Q, R, z0, P0):
        while True:
            pass

    explorer = ic.explore_initial_covariance(filter=hanging_filter)
    assert "hanging_filter" in explorer.problem and "0.2 s" in explorer.problem


@pytest.mark.parametrize("bad", ["my_filter", 3.0, [my_filter]])
def test_a_filter_that_is_not_a_function_is_refused_by_name(bad) -> None:
    with pytest.raises(ValueError, match=r"filter must be None .* or a function"):
        ic.explore_initial_covariance(filter=bad)
    with pytest.raises(ValueError, match="filter must be None"):
        ic.draw_initial_covariance(Figure(), p0_variance=1.0, filter=bad)
