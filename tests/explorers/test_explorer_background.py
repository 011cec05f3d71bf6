"""The σ_j explorer of notebook 00 draws exactly what the engine computes."""

from __future__ import annotations

import dataclasses
import html
import math

import numpy as np
import pytest
from explorer_checks import EXPLORER_SCENARIO, assert_only_numbers_change, explorer_draw, line, png
from matplotlib.figure import Figure

from lqe_helpers import experiments, model
from lqe_helpers.explorers import background
from lqe_helpers.scenario import DEFAULT
from lqe_helpers.steady_state import steady_state


def direct_growth(jerk_std: float, steps: int = 100) -> np.ndarray:
    """2σ of the open-loop position, straight from Lesson 0.5 eq. (9) in a loop."""
    scenario = dataclasses.replace(DEFAULT, jerk_std=jerk_std)
    A = model.transition_matrix(DEFAULT.dt)
    Q = model.process_noise_covariance(DEFAULT.dt, jerk_std)
    P = steady_state(A, model.observation_matrix(("vision",)), scenario.Q,
                     model.measurement_noise_covariance([DEFAULT.sigma_v])).estimate_covariance
    out = [P[0, 0]]
    for _ in range(steps):
        P = A @ P @ A.T + Q
        out.append(P[0, 0])
    return 2 * np.sqrt(np.array(out))


@pytest.fixture
def explorer():
    """A new explorer for every test, so no test sees another's slider moves."""
    return background.explore_background()


def window() -> np.ndarray:
    low, high = background.TRACKING_WINDOW
    return (DEFAULT.times >= low) & (DEFAULT.times <= high)


def test_slider_follows_the_conventions(explorer) -> None:
    slider = explorer.sliders["jerk_std"]
    assert slider.description == "σ_j (cm/s³)"
    low, high = background.JERK_STD_RANGE
    assert (slider.min, slider.max) == (math.log10(low), math.log10(high))
    assert slider.base == 10
    # It starts on its grid near the scenario's σ_j, not at it (issue 15: at σ_j the
    # crossing time in the numbers line is a task's answer in notebook 00).
    assert slider.value == pytest.approx(background.START_JERK_STD) == pytest.approx(1000.0)
    exponent = (math.log10(background.START_JERK_STD) - slider.min) / slider.step
    assert exponent == pytest.approx(round(exponent))
    assert slider.value != pytest.approx(DEFAULT.process_jerk_std, rel=0.1)
    assert slider.continuous_update is False
    # The readout must read back what it shows ("1,396" would be read as 1).
    assert slider.readout_format == ".0f"
    assert low < DEFAULT.process_jerk_std < high


@pytest.mark.parametrize("jerk_std", [10.0, 100.0, 30000.0, 1.0e5])
@pytest.mark.slow
def test_moving_the_slider_redraws_the_direct_computation(explorer, jerk_std: float) -> None:
    previous_png = explorer.png
    explorer.sliders["jerk_std"].value = jerk_std
    growth_ax, track_ax = explorer.figure.axes
    np.testing.assert_allclose(line(growth_ax, background.GROWTH_LABEL),
                               direct_growth(jerk_std), rtol=1e-9)
    np.testing.assert_allclose(line(growth_ax, background.REFERENCE_LABEL),
                               direct_growth(DEFAULT.process_jerk_std), rtol=1e-9)
    noise = EXPLORER_SCENARIO.unit_noise(sensors=("vision",))
    shown = window()
    truth = DEFAULT.truth[:, 0]
    np.testing.assert_allclose(line(track_ax, background.VISION_LABEL),
                               (truth + DEFAULT.sigma_v * noise[:, 0])[shown], atol=1e-12)
    np.testing.assert_array_equal(line(track_ax, background.TRUTH_LABEL), truth[shown])
    expected = experiments.track(dataclasses.replace(DEFAULT, jerk_std=jerk_std), noise=noise)
    np.testing.assert_allclose(line(track_ax, background.ESTIMATE_LABEL),
                               expected.positions[shown], rtol=0, atol=1e-12)
    # The numbers go to the line beside the figure; the panels' titles never change.
    numbers = explorer.numbers
    assert numbers.startswith(f"The pack's vision-only filter (yours comes in notebook 01), "
                              f"σ_j = {background.format_jerk(jerk_std)} cm/s³. ")
    skip = DEFAULT.burn_in_steps
    mse = np.mean((expected.positions - truth)[skip:] ** 2)
    expects = np.mean(expected.position_variances[skip:])
    assert numbers.endswith(f"Tracking MSE of this run after {DEFAULT.burn_in:g} s: "
                            f"{mse:.3g} cm², the filter expects {expects:.3g} cm².")
    assert (growth_ax.get_title(), track_ax.get_title()) == (background.GROWTH_TITLE,
                                                             background.TRACKING_TITLE)
    assert explorer.png != previous_png


@pytest.mark.slow
def test_no_text_in_the_figure_changes_with_the_slider(explorer) -> None:
    assert_only_numbers_change(explorer, "jerk_std", 10.0)


@pytest.mark.slow
def test_numbers_give_when_the_uncertainty_reaches_the_amplitude(explorer) -> None:
    reaches = ("2σ of the predicted position reaches the flight's amplitude of "
               f"{DEFAULT.amplitude:g} cm")
    for jerk_std in (background.START_JERK_STD, DEFAULT.process_jerk_std):
        explorer.sliders["jerk_std"].value = jerk_std
        growth = direct_growth(jerk_std)
        first = int(np.argmax(growth >= DEFAULT.amplitude))
        assert first > 0
        assert f"{reaches} after {first * DEFAULT.dt:.2f} s. " in explorer.numbers
    # Very small σ_j: never within the second shown.
    assert not np.any(direct_growth(10.0) >= DEFAULT.amplitude)
    explorer.sliders["jerk_std"].value = 10.0
    assert f"{reaches} after more than {background.OPEN_LOOP_DURATION:g} s. " in explorer.numbers


@pytest.mark.slow
def test_lag_and_noise_show_in_the_tracking_error(explorer) -> None:
    """Too small σ_j: large, overconfident error; matched σ_j: much smaller."""
    mses = {}
    for jerk_std in (10.0, DEFAULT.process_jerk_std, 1.0e5):
        explorer.sliders["jerk_std"].value = jerk_std
        track_ax = explorer.figure.axes[1]
        error = line(track_ax, background.ESTIMATE_LABEL) - DEFAULT.truth[window(), 0]
        mses[jerk_std] = np.mean(error**2)
    assert mses[DEFAULT.process_jerk_std] < mses[1.0e5] < mses[10.0]


@pytest.mark.slow
def test_noise_pattern_stays_fixed_across_slider_moves(explorer) -> None:
    estimates, visions = [], []
    for jerk_std in (300.0, 3000.0, 300.0):
        explorer.sliders["jerk_std"].value = jerk_std
        track_ax = explorer.figure.axes[1]
        estimates.append(line(track_ax, background.ESTIMATE_LABEL))
        visions.append(line(track_ax, background.VISION_LABEL))
    np.testing.assert_array_equal(visions[0], visions[1])
    np.testing.assert_array_equal(estimates[0], estimates[2])
    assert not np.array_equal(estimates[0], estimates[1])


def test_draw_function_on_a_fresh_figure_with_given_noise() -> None:
    figure = Figure()
    noise = np.zeros((DEFAULT.n_steps, 1))
    numbers = background.draw_background(figure, jerk_std=500.0, noise=noise)
    growth_ax, track_ax = figure.axes
    np.testing.assert_allclose(line(growth_ax, background.GROWTH_LABEL), direct_growth(500.0),
                               rtol=1e-9)
    shown = window()
    np.testing.assert_array_equal(line(track_ax, background.VISION_LABEL),
                                  DEFAULT.truth[shown, 0])
    expected = experiments.track(dataclasses.replace(DEFAULT, jerk_std=500.0), noise=noise)
    np.testing.assert_allclose(line(track_ax, background.ESTIMATE_LABEL),
                               expected.positions[shown], rtol=0, atol=1e-12)
    assert (f"Tracking MSE of this run after {DEFAULT.burn_in:g} s: "
            f"{float(expected.mse()):.3g} cm², ") in numbers
    # Drawing again replaces, not adds.
    background.draw_background(figure, jerk_std=800.0, noise=noise)
    assert len(figure.axes) == 2
    assert len(figure.axes[1].get_lines()) == 3


@pytest.mark.parametrize("bad", [0.0, -10.0, np.nan, np.inf])
def test_bad_jerk_std_is_rejected_by_name(bad: float) -> None:
    with pytest.raises(ValueError, match="jerk_std"):
        background.draw_background(Figure(), jerk_std=bad)


@pytest.mark.slow
def test_static_display_carries_the_picture(explorer) -> None:
    bundle = explorer._repr_mimebundle_()
    assert bundle["text/plain"].startswith("Interactive explorer")
    assert "σ_j (cm/s³)" in bundle["text/html"]
    assert explorer.png.startswith(b"\x89PNG")
    assert explorer.numbers.startswith(f"{background.WHOSE_FILTER} σ_j = 1,000 cm/s³. ")
    assert html.escape(explorer.numbers) in bundle["text/html"]


@pytest.mark.slow
def test_redraw_in_place_gives_the_same_picture_as_a_fresh_figure() -> None:
    reused = Figure(figsize=(10, 4.2))
    for jerk_std in (10.0, 1.0e5, DEFAULT.process_jerk_std):
        background.draw_background(reused, jerk_std=jerk_std)
        fresh = Figure(figsize=(10, 4.2))
        background.draw_background(fresh, jerk_std=jerk_std)
        assert png(reused) == png(fresh)
    assert len(reused.axes) == 2


def test_foreign_or_cleared_figure_is_rebuilt() -> None:
    figure = Figure()
    figure.add_subplot().plot([0, 1], [5, 6], label="someone else's line")
    background.draw_background(figure, jerk_std=500.0)
    growth_ax, track_ax = figure.axes
    labels = [line.get_label() for ax in figure.axes for line in ax.get_lines()]
    assert "someone else's line" not in labels
    figure.clear()
    numbers = background.draw_background(figure, jerk_std=2000.0)
    growth_ax, track_ax = figure.axes
    assert numbers.startswith(f"{background.WHOSE_FILTER} σ_j = 2,000 cm/s³. ")
    assert growth_ax.get_title() == background.GROWTH_TITLE
    assert len(growth_ax.get_lines()) == 3
    assert len(track_ax.get_lines()) == 3


def test_another_scenario_redraws_its_reference_curve() -> None:
    """The fixed artists (reference growth, true path) follow the figure's scenario."""
    figure = Figure()
    background.draw_background(figure, jerk_std=500.0)
    noisier = dataclasses.replace(DEFAULT, sigma_v=4.5)
    background.draw_background(figure, jerk_std=500.0, scenario=noisier)
    growth_ax = figure.axes[0]
    P = steady_state(noisier.A, model.observation_matrix(("vision",)), noisier.Q,
                     model.measurement_noise_covariance([4.5])).estimate_covariance
    np.testing.assert_allclose(line(growth_ax, background.REFERENCE_LABEL)[0],
                               2 * np.sqrt(P[0, 0]), rtol=1e-12)


@pytest.mark.parametrize("jerk_std", [5.0, 300.0, 2.0e5])
@pytest.mark.slow
def test_the_scenarios_jerk_std_is_the_reference_whatever_its_value(jerk_std: float) -> None:
    """The slider starts at START_JERK_STD for any scenario; the scenario's σ_j, even one
    outside the slider's range, is the reference curve, and the noise is the explorer's."""
    scenario = dataclasses.replace(DEFAULT, jerk_std=jerk_std)
    explorer = background.explore_background(scenario)
    assert explorer.sliders["jerk_std"].value == pytest.approx(background.START_JERK_STD)
    growth_ax, track_ax = explorer.figure.axes
    np.testing.assert_allclose(line(growth_ax, background.REFERENCE_LABEL)[:5],
                               direct_growth(jerk_std, steps=4), rtol=1e-9)
    noise = explorer_draw(scenario).unit_noise(sensors=("vision",))
    np.testing.assert_allclose(line(track_ax, background.VISION_LABEL),
                               (scenario.truth[:, 0] + scenario.sigma_v * noise[:, 0])[window()],
                               atol=1e-12)
