"""The σ_v explorer of question (a) draws exactly what the engine computes."""

from __future__ import annotations

import dataclasses
import html
import re

import numpy as np
import pytest
from explorer_checks import EXPLORER_SCENARIO, assert_only_numbers_change, band_matches, line, png
from matplotlib.figure import Figure

from lqe_helpers import experiments, metrics
from lqe_helpers.explorers import vision
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.student_code import StudentCodeError, calling


@pytest.fixture
def explorer():
    """A new explorer for every test, so no test sees another's slider moves."""
    return vision.explore_vision()


def test_slider_follows_the_conventions(explorer) -> None:
    slider = explorer.sliders["sigma_v"]
    assert slider.description == "σ_v (cm)"
    assert (slider.min, slider.max) == vision.SIGMA_V_RANGE
    assert slider.min > 0
    assert slider.value == DEFAULT.sigma_v
    assert slider.continuous_update is False
    assert slider.readout_format == ".1f"
    # The question's two values are reachable slider positions.
    for value in (1.5, 4.5):
        position = (value - slider.min) / slider.step
        assert position == pytest.approx(round(position))


@pytest.mark.parametrize("sigma_v", [0.1, 4.5, 10.0, 1.5])
@pytest.mark.slow
def test_moving_the_slider_redraws_the_direct_computation(explorer, sigma_v: float) -> None:
    previous_png = explorer.png
    explorer.sliders["sigma_v"].value = sigma_v
    (ax,) = explorer.figure.axes
    noise = EXPLORER_SCENARIO.unit_noise(sensors=("vision",))
    truth = DEFAULT.truth[:, 0]
    # Measurements straight from Tutorial eq. (3): truth plus σ_v times the fixed noise.
    np.testing.assert_allclose(line(ax, vision.VISION_LABEL), truth + sigma_v * noise[:, 0],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(line(ax, vision.TRUTH_LABEL), truth)
    expected = experiments.track(DEFAULT, sigmas=[sigma_v], noise=noise)
    np.testing.assert_allclose(line(ax, vision.ESTIMATE_LABEL), expected.positions,
                               rtol=0, atol=1e-12)
    std = np.sqrt(expected.position_variances)
    band_matches(ax, vision.BAND_LABEL, expected.positions - 2 * std,
                 expected.positions + 2 * std)
    # The numbers go to the line beside the figure, not into it.
    raw = metrics.mse(truth + sigma_v * noise[:, 0], truth, DEFAULT.burn_in_steps)
    filtered = np.mean((expected.positions - truth)[DEFAULT.burn_in_steps:] ** 2)
    assert explorer.numbers == (f"σ_v = {sigma_v:.1f} cm, filtered by the pack's engine. "
                                f"MSE of this run after {DEFAULT.burn_in:g} s: raw vision "
                                f"{raw:.3g} cm², filtered {filtered:.3g} cm², ratio raw / "
                                f"filtered {raw / filtered:.3g}.")
    assert ax.get_title() == ""
    if sigma_v != DEFAULT.sigma_v:
        assert explorer.png != previous_png


@pytest.mark.parametrize("sigma_v", [vision.SIGMA_V_RANGE[0], 1.5, vision.SIGMA_V_RANGE[1]])
def test_numbers_line_keeps_three_significant_figures_at_every_slider_value(explorer,
                                                                          sigma_v) -> None:
    """At σ_v = 0.1 cm the MSEs are about 0.01 cm²: a fixed two decimals printed "0.00"."""
    explorer.sliders["sigma_v"].value = sigma_v
    raw, filtered, ratio = (float(text) for text in re.findall(
        r"raw vision (\S+) cm², filtered (\S+) cm², ratio raw / filtered (\S+)\.$",
        explorer.numbers)[0])
    assert min(raw, filtered, ratio) > 0
    assert raw / filtered == pytest.approx(ratio, rel=1e-2)


def test_no_text_in_the_figure_changes_with_the_slider(explorer) -> None:
    assert_only_numbers_change(explorer, "sigma_v", 7.3)


def test_noise_pattern_stays_fixed_across_slider_moves(explorer) -> None:
    truth = DEFAULT.truth[:, 0]
    patterns = []
    for sigma_v in (0.5, 7.3, 0.5):
        explorer.sliders["sigma_v"].value = sigma_v
        (ax,) = explorer.figure.axes
        patterns.append((line(ax, vision.VISION_LABEL) - truth) / sigma_v)
    np.testing.assert_allclose(patterns[0], patterns[1], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(patterns[0], patterns[2])


def test_draw_function_on_a_fresh_figure_with_given_noise() -> None:
    figure = Figure()
    noise = np.zeros((DEFAULT.n_steps, 1))
    numbers = vision.draw_vision(figure, sigma_v=2.0, noise=noise)
    (ax,) = figure.axes
    truth = DEFAULT.truth[:, 0]
    # Zero noise: vision sees the truth, and the filter's only error is its lag.
    np.testing.assert_array_equal(line(ax, vision.VISION_LABEL), truth)
    expected = experiments.track(DEFAULT, sigmas=[2.0], noise=noise)
    np.testing.assert_allclose(line(ax, vision.ESTIMATE_LABEL), expected.positions,
                               rtol=0, atol=1e-12)
    assert (f"raw vision 0 cm², filtered {float(expected.mse()):.3g} cm², ratio raw / "
            f"filtered 0." in numbers)
    # Drawing again replaces, not adds.
    vision.draw_vision(figure, sigma_v=3.0, noise=noise)
    assert len(figure.axes) == 1
    assert len(figure.axes[0].get_lines()) == 3


def test_filter_beats_raw_vision_at_the_question_values() -> None:
    figure = Figure()
    for sigma_v in (1.5, 4.5):
        vision.draw_vision(figure, sigma_v=sigma_v)
        (ax,) = figure.axes
        truth = DEFAULT.truth[:, 0]
        skip = DEFAULT.burn_in_steps
        raw = np.mean((line(ax, vision.VISION_LABEL) - truth)[skip:] ** 2)
        filtered = np.mean((line(ax, vision.ESTIMATE_LABEL) - truth)[skip:] ** 2)
        assert filtered < raw / 3


@pytest.mark.parametrize("bad", [0.0, -1.5, np.nan, np.inf])
def test_bad_sigma_v_is_rejected_by_name(bad: float) -> None:
    with pytest.raises(ValueError, match="sigma_v"):
        vision.draw_vision(Figure(), sigma_v=bad)


def test_wrong_noise_shape_is_rejected() -> None:
    with pytest.raises(ValueError, match="noise"):
        vision.draw_vision(Figure(), sigma_v=1.5, noise=np.zeros((10, 1)))


def test_static_display_carries_the_picture(explorer) -> None:
    bundle = explorer._repr_mimebundle_()
    assert bundle["text/plain"].startswith("Interactive explorer")
    assert "σ_v (cm)" in bundle["text/html"]
    assert explorer.png.startswith(b"\x89PNG")
    assert explorer.numbers.startswith(f"σ_v = {DEFAULT.sigma_v:.1f} cm, filtered by ")
    assert html.escape(explorer.numbers) in bundle["text/html"]


def test_slider_starts_at_the_scenarios_sigma_v() -> None:
    scenario = dataclasses.replace(DEFAULT, sigma_v=4.5)
    assert vision.explore_vision(scenario).sliders["sigma_v"].value == 4.5


@pytest.mark.parametrize("sigma_v", [0.05, 12.0])
def test_scenario_outside_the_slider_range_is_refused(sigma_v: float) -> None:
    """Not clipped into the range: the explorer would show another σ_v than asked for."""
    scenario = dataclasses.replace(DEFAULT, sigma_v=sigma_v)
    with pytest.raises(ValueError, match=rf"scenario\.sigma_v .*\[0\.1, 10\] cm, got {sigma_v:g}"):
        vision.explore_vision(scenario)


@pytest.mark.slow
def test_redraw_in_place_gives_the_same_picture_as_a_fresh_figure() -> None:
    reused = Figure(figsize=(9, 4))
    for sigma_v in (0.3, 9.0, 2.5):
        vision.draw_vision(reused, sigma_v=sigma_v)
        fresh = Figure(figsize=(9, 4))
        vision.draw_vision(fresh, sigma_v=sigma_v)
        assert png(reused) == png(fresh)
    assert len(reused.axes) == 1


def test_foreign_or_cleared_figure_is_rebuilt() -> None:
    figure = Figure()
    figure.add_subplot().plot([0, 1], [5, 6], label="someone else's line")
    vision.draw_vision(figure, sigma_v=1.5)
    (ax,) = figure.axes
    assert "someone else's line" not in [artist.get_label() for artist in ax.get_lines()]
    figure.clear()
    numbers = vision.draw_vision(figure, sigma_v=2.0)
    (ax,) = figure.axes
    assert numbers.startswith("σ_v = 2.0 cm, filtered by the pack's engine. ")
    assert len(ax.get_lines()) == 3


# ------------------------------------------------------------------------------------------
# The student's own filter on the slider (issue 15 §4)
# ------------------------------------------------------------------------------------------


def my_filter(y, A, C, Q, R, z0, P0):
    """A correct student filter (the engine's estimates, returned as the task asks)."""
    return np.array(kalman_filter(y, A, C, Q, R, z0, P0).estimates)


@pytest.mark.slow
def test_the_slider_runs_the_students_filter_and_says_so() -> None:
    calls = []

    def my_filter_counted(y, A, C, Q, R, z0, P0):
        calls.append((y.shape, R.tolist()))
        return my_filter(y, A, C, Q, R, z0, P0)

    explorer = vision.explore_vision(filter=my_filter_counted)
    engine = vision.explore_vision()
    for sigma_v in (1.5, 0.1, 7.3):
        for each in (explorer, engine):
            each.sliders["sigma_v"].value = sigma_v
        (ours,), (theirs,) = explorer.figure.axes, engine.figure.axes
        np.testing.assert_allclose(line(ours, vision.ESTIMATE_LABEL),
                                   line(theirs, vision.ESTIMATE_LABEL), rtol=0, atol=1e-9)
        assert explorer.numbers == engine.numbers.replace("the pack's engine",
                                                          "your my_filter_counted")
        assert explorer.problem == ""
    assert calls[-1] == ((DEFAULT.n_steps, 1), [[7.3**2]])
    assert "estimate of your my_filter_counted with a ±2σ band from the engine's" in (
        explorer.description)


def test_the_drawing_shows_what_the_students_filter_returns() -> None:
    """Not the engine's estimate: a filter 1 cm off draws a line 1 cm off, band included."""
    def off_by_one(y, A, C, Q, R, z0, P0):
        return my_filter(y, A, C, Q, R, z0, P0) + 1.0

    figure = Figure()
    numbers = vision.draw_vision(figure, sigma_v=2.0, filter=off_by_one)
    expected = experiments.track(DEFAULT, sigmas=[2.0])
    (ax,) = figure.axes
    np.testing.assert_allclose(line(ax, vision.ESTIMATE_LABEL), expected.positions + 1.0,
                               rtol=0, atol=1e-9)
    std = np.sqrt(expected.position_variances)   # the engine's covariance, data-independent
    band_matches(ax, vision.BAND_LABEL, expected.positions + 1.0 - 2 * std,
                 expected.positions + 1.0 + 2 * std)
    filtered = metrics.mse(expected.positions + 1.0, DEFAULT.truth[:, 0], DEFAULT.burn_in_steps)
    assert f"filtered {filtered:.3g} cm², ratio" in numbers
    assert "filtered by your off_by_one." in numbers


def test_a_broken_filter_is_one_line_and_the_next_move_tries_again() -> None:
    state = {"broken": True}

    def my_filter_draft(y, A, C, Q, R, z0, P0):
        if state["broken"]:
            K = P0 @ C @ np.linalg.inv(C @ P0 @ C.T + R)   # C where Cᵀ belongs: shapes clash
            return K
        return my_filter(y, A, C, Q, R, z0, P0)

    explorer = vision.explore_vision(filter=my_filter_draft)
    assert explorer.problem.startswith("my_filter_draft raised ValueError")
    assert "(in my_filter_draft, line" in explorer.problem and "`K = P0 @ C @" in (
        explorer.problem)
    assert "\n" not in explorer.problem and explorer.numbers == explorer.problem
    state["broken"] = False
    explorer.sliders["sigma_v"].value = 2.5
    assert explorer.problem == ""
    assert explorer.numbers.startswith("σ_v = 2.5 cm, filtered by your my_filter_draft. ")


def test_a_filter_not_written_yet_says_so() -> None:
    def my_filter(y, A, C, Q, R, z0, P0):
        raise NotImplementedError

    explorer = vision.explore_vision(filter=my_filter)
    assert explorer.problem.startswith("my_filter is not written yet: replace the line")
    assert explorer.problem.endswith("then run the Explore cell again")
    assert explorer.png.startswith(b"\x89PNG")     # a picture is still shown


@pytest.mark.parametrize(("returned", "phrase"), [
    (lambda est: est[:, 0], "returned an array of shape (1000,)"),
    (lambda est: list(est), "returned a Python list"),
    (lambda est: est + 1j, "returned complex numbers"),
    (lambda est: None, "returned None"),
])
def test_a_filter_returning_the_wrong_thing_is_named(returned, phrase) -> None:
    def my_filter_wrong(y, A, C, Q, R, z0, P0):
        return returned(my_filter(y, A, C, Q, R, z0, P0))

    with pytest.raises(StudentCodeError, match=r"^my_filter_wrong ") as info:
        vision.draw_vision(Figure(), sigma_v=1.5, filter=my_filter_wrong)
    assert phrase in str(info.value)


def test_an_endless_filter_is_stopped(monkeypatch) -> None:
    monkeypatch.setattr(calling, "TIME_LIMIT", 0.2)

    def my_filter(y, A, C, Q, R, z0, P0):
        while True:
            pass

    explorer = vision.explore_vision(filter=my_filter)
    assert explorer.problem.startswith("my_filter did not return within 0.2 s")


def test_the_filter_gets_copies_and_cannot_spoil_the_next_draw() -> None:
    def my_filter_in_place(y, A, C, Q, R, z0, P0):
        estimates = my_filter(y, A, C, Q, R, z0, P0)
        y[...] = 0.0                                   # changes its input
        return estimates

    with pytest.raises(StudentCodeError, match="changed its input y"):
        vision.draw_vision(Figure(), sigma_v=1.5, filter=my_filter_in_place)
    numbers = vision.draw_vision(Figure(), sigma_v=1.5)
    assert numbers == vision.draw_vision(Figure(), sigma_v=1.5)


def test_explore_vision_refuses_a_filter_that_is_not_a_function() -> None:
    with pytest.raises(ValueError, match=r"filter must be None .*or a function.* got a ndarray"):
        vision.explore_vision(filter=np.zeros(3))
