"""The bias explorer of notebook 06 draws exactly what the engine computes."""

from __future__ import annotations

import dataclasses
import html
import math

import numpy as np
import pytest
from explorer_checks import EXPLORER_SCENARIO, band_matches, line, png
from matplotlib.figure import Figure
from matplotlib.text import Text

from lqe_helpers import bias_model, model
from lqe_helpers.explorers import bias as bias_explorer
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT

SHOWN = DEFAULT.times <= bias_explorer.WINDOW


def direct_filter(bias: float, sigma_a: float, sigma_v: float, noise: np.ndarray):
    """The experiment assembled by hand from Lesson 0.5 eqs. (5) and (9)."""
    dt = DEFAULT.dt
    readings = (bias_model.step_accelerations(DEFAULT) + bias + sigma_a * noise[:, 1])
    y = DEFAULT.truth[:, :1] + sigma_v * noise[:, :1]
    F = np.array([[1, dt, -dt**2 / 2], [0, 1, -dt], [0, 0, 1]])
    G = np.array([[dt**2 / 2], [dt], [0]])
    speed = DEFAULT.amplitude * 2 * np.pi * DEFAULT.frequency
    P0 = np.diag([DEFAULT.amplitude**2, speed**2, bias_model.DEFAULT_BIAS_PRIOR_STD**2])
    return kalman_filter(y, F, model.observation_matrix(("vision",)), G @ G.T * sigma_a**2,
                         np.array([[sigma_v**2]]), np.zeros(3), P0, B=G, u=readings[:, None])


def direct_vision_only(sigma_v: float, noise: np.ndarray):
    """Notebook 01's vision-only filter (the jerk model of notebook 00) on vision's noise."""
    y = DEFAULT.truth[:, :1] + sigma_v * noise[:, :1]
    return kalman_filter(y, DEFAULT.A, model.observation_matrix(("vision",)), DEFAULT.Q,
                         np.array([[sigma_v**2]]), DEFAULT.z0, DEFAULT.P0)


def direct_dead_reckoning(bias: float, sigma_a: float, noise: np.ndarray) -> np.ndarray:
    """Positions (cm) of the signal integrated step by step from the true start, b̂ = 0."""
    dt = DEFAULT.dt
    readings = bias_model.step_accelerations(DEFAULT) + bias + sigma_a * noise[:, 1]
    omega = 2 * np.pi * DEFAULT.frequency
    p, v = DEFAULT.amplitude * np.sin(-omega * dt), DEFAULT.amplitude * omega * np.cos(-omega * dt)
    positions = []
    for reading in readings:
        p, v = p + dt * v + dt**2 / 2 * reading, v + dt * reading
        positions.append(p)
    return np.array(positions)


def check_numbers(numbers: str, values: dict[str, float], noise: np.ndarray) -> None:
    """The line of text states b, b̂ ± 2σ at the end, the MSE and dead reckoning's end error."""
    bias = values["bias"]
    expected = direct_filter(bias, values["sigma_a"], values["sigma_v"], noise)
    truth = DEFAULT.truth[:, 0]
    end = f"{DEFAULT.duration:g} s"
    assert numbers.startswith("The pack's filter with the signal as input (bias_model). ")
    assert f"b = {bias:g} cm/s²" in numbers
    final, std = expected.estimates[-1, 2], np.sqrt(expected.estimate_covariances[-1, 2, 2])
    # ± 2σ to two significant figures, b̂ to as many decimals.
    decimals = 1 - math.floor(math.log10(2 * std))
    assert (f"estimate at {end} (± 2σ): {final:.{decimals}f} ± {2 * std:.{decimals}f} cm/s²"
            in numbers)
    skip = DEFAULT.burn_in_steps
    mse = np.mean((expected.estimates[skip:, 0] - truth[skip:]) ** 2)
    alone = direct_vision_only(values["sigma_v"], noise)
    alone_mse = np.mean((alone.estimates[skip:, 0] - truth[skip:]) ** 2)
    assert (f"after {DEFAULT.burn_in:g} s: {mse:.3g} cm² (vision-only filter on the same "
            f"camera noise: {alone_mse:.3g} cm²)") in numbers
    off = direct_dead_reckoning(bias, values["sigma_a"], noise)[-1] - truth[-1]
    assert f"dead reckoning ends {off:+.0f} cm off the path at {end}" in numbers


def texts(figure: Figure) -> list[str]:
    """Every non-empty text the figure draws (titles, labels, legends, tick labels)."""
    return sorted(t.get_text() for t in figure.findobj(Text) if t.get_text())


@pytest.fixture
def explorer():
    """A new explorer for every test, so no test sees another's slider moves."""
    return bias_explorer.explore_bias()


def test_sliders_follow_the_conventions(explorer) -> None:
    b, sigma_a, sigma_v = (explorer.sliders[name] for name in ("bias", "sigma_a", "sigma_v"))
    assert b.description == "b (cm/s²)"
    assert (b.min, b.max, b.step) == (*bias_explorer.BIAS_RANGE, bias_explorer.BIAS_STEP)
    assert b.value == bias_model.DEFAULT_BIAS
    assert sigma_a.description == "σ_a (cm/s²)"
    low, high = bias_explorer.SIGMA_A_RANGE
    assert (sigma_a.min, sigma_a.max, sigma_a.base) == (math.log10(low), math.log10(high), 10)
    assert low > 0
    assert sigma_a.value == pytest.approx(bias_model.DEFAULT_SIGMA_A)
    assert sigma_v.description == "σ_v (cm)"
    assert (sigma_v.min, sigma_v.max) == bias_explorer.SIGMA_V_RANGE
    assert sigma_v.min > 0
    assert sigma_v.value == DEFAULT.sigma_v
    for slider in (b, sigma_a, sigma_v):
        assert slider.continuous_update is False
        # The readout must read back what it shows: no thousands separators.
        assert "," not in slider.readout_format


@pytest.mark.parametrize(("name", "value"),
                         [("bias", -55.0), ("sigma_a", 300.0), ("sigma_v", 4.5), ("bias", 0.0)])
@pytest.mark.slow
def test_moving_a_slider_redraws_the_direct_computation(explorer, name: str,
                                                        value: float) -> None:
    previous_png = explorer.png
    explorer.sliders[name].value = value
    values = explorer.values
    bias_ax, path_ax = explorer.figure.axes
    noise = bias_model.unit_noise(EXPLORER_SCENARIO)
    expected = direct_filter(values["bias"], values["sigma_a"], values["sigma_v"], noise)
    np.testing.assert_allclose(line(bias_ax, bias_explorer.BIAS_ESTIMATE_LABEL),
                               expected.estimates[SHOWN, 2], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(line(bias_ax, bias_explorer.TRUE_BIAS_LABEL),
                                  values["bias"])
    std = np.sqrt(expected.estimate_covariances[SHOWN, 2, 2])
    centre = expected.estimates[SHOWN, 2]
    band_matches(bias_ax, bias_explorer.BIAS_BAND_LABEL, centre - 2 * std, centre + 2 * std)
    truth = DEFAULT.truth[SHOWN, 0]
    np.testing.assert_allclose(line(path_ax, bias_explorer.VISION_LABEL),
                               truth + values["sigma_v"] * noise[SHOWN, 0], atol=1e-12)
    np.testing.assert_allclose(line(path_ax, bias_explorer.ESTIMATE_LABEL),
                               expected.estimates[SHOWN, 0], rtol=0, atol=1e-9)
    # Dead reckoning: the uncorrected bias's b t²/2 plus the same noise-driven wander.
    drift = line(path_ax, bias_explorer.DEAD_RECKONING_LABEL) - truth
    unbiased = bias_model.dead_reckoning(
        bias_model.step_accelerations(DEFAULT) + values["sigma_a"] * noise[:, 1],
        bias_model.initial_state(DEFAULT, 0.0), DEFAULT.dt)[SHOWN, 0] - truth
    np.testing.assert_allclose(drift - unbiased,
                               bias_model.bias_drift(DEFAULT, values["bias"])[SHOWN],
                               rtol=1e-9, atol=1e-9)
    check_numbers(explorer.numbers, values, noise)
    assert explorer.png != previous_png


@pytest.mark.slow
def test_the_numbers_go_beside_the_figure_and_its_text_stays_put(explorer) -> None:
    """Text is the costliest thing to repaint: a move changes the line, not the figure's text."""
    before, numbers = texts(explorer.figure), explorer.numbers
    bias_ax, path_ax = explorer.figure.axes
    assert (bias_ax.get_title(), path_ax.get_title()) == (bias_explorer.BIAS_TITLE,
                                                          bias_explorer.PATH_TITLE)
    assert explorer.figure.get_suptitle() == ""
    for name, value in (("bias", -40.0), ("sigma_a", 100.0), ("sigma_v", 3.5)):
        explorer.sliders[name].value = value
        assert texts(explorer.figure) == before, name
        assert explorer.numbers != numbers, name
        numbers = explorer.numbers
    check_numbers(explorer.numbers, explorer.values, bias_model.unit_noise(EXPLORER_SCENARIO))
    assert html.escape(explorer.numbers) in explorer._repr_mimebundle_()["text/html"]


@pytest.mark.slow
def test_a_move_recomputes_only_what_its_slider_changes(explorer) -> None:
    """The filter run hangs on (σ_a, σ_v) only, since a move of b only shifts it; the
    run of the last (σ_a, σ_v) is kept, so a σ moved back to an earlier value pays again."""
    kept = explorer.draw.keywords["unbiased_runs"]
    noise = bias_model.unit_noise(EXPLORER_SCENARIO)
    start = explorer.sliders["sigma_v"].value
    assert kept.computed == 1
    # (slider, value, filter runs) of each move.
    for name, value, filters in [("bias", -30.0, 0), ("sigma_v", 3.0, 1), ("sigma_v", start, 1),
                                 ("sigma_a", 40.0, 1), ("bias", 20.0, 0), ("bias", -30.0, 0),
                                 ("sigma_a", 20.0, 1)]:
        before = kept.computed
        explorer.sliders[name].value = value
        assert kept.computed - before == filters, (name, value)
        # What is drawn is still the library's run at these values.
        values = explorer.values
        run = bias_model.track_with_input(DEFAULT, noise=noise, **values)
        bias_ax, path_ax = explorer.figure.axes
        np.testing.assert_allclose(line(bias_ax, bias_explorer.BIAS_ESTIMATE_LABEL),
                                   run.bias_estimates[SHOWN], rtol=0, atol=1e-9)
        np.testing.assert_allclose(line(path_ax, bias_explorer.ESTIMATE_LABEL),
                                   run.positions[SHOWN], rtol=0, atol=1e-9)
        np.testing.assert_array_equal(line(path_ax, bias_explorer.DEAD_RECKONING_LABEL),
                                      run.dead_reckoning[SHOWN, 0])
        check_numbers(explorer.numbers, values, noise)


@pytest.mark.slow
def test_noise_pattern_stays_fixed_across_slider_moves(explorer) -> None:
    explorer.sliders["bias"].value = 20.0
    truth = DEFAULT.truth[SHOWN, 0]
    patterns, estimates = [], []
    for sigma_v in (1.0, 3.0, 1.0):
        explorer.sliders["sigma_v"].value = sigma_v
        path_ax = explorer.figure.axes[1]
        patterns.append((line(path_ax, bias_explorer.VISION_LABEL) - truth) / sigma_v)
        estimates.append(line(path_ax, bias_explorer.ESTIMATE_LABEL))
    np.testing.assert_allclose(patterns[0], patterns[1], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(estimates[0], estimates[2])
    # The acceleration signal's noise too: moving σ_a only rescales it.
    noise_free = bias_model.dead_reckoning(bias_model.step_accelerations(DEFAULT) + 20.0,
                                           bias_model.initial_state(DEFAULT, 0.0),
                                           DEFAULT.dt)[SHOWN, 0]
    wander = []
    for sigma_a in (10.0, 40.0):
        explorer.sliders["sigma_a"].value = sigma_a
        wander.append(line(explorer.figure.axes[1], bias_explorer.DEAD_RECKONING_LABEL)
                      - noise_free)
    np.testing.assert_allclose(wander[1], 4 * wander[0], rtol=1e-6, atol=1e-9)


def test_draw_function_on_a_fresh_figure_with_given_noise() -> None:
    figure = Figure()
    noise = np.zeros((DEFAULT.n_steps, 2))
    bias_explorer.draw_bias(figure, bias=30.0, sigma_a=5.0, sigma_v=2.0, noise=noise)
    bias_ax, path_ax = figure.axes
    truth = DEFAULT.truth[SHOWN, 0]
    np.testing.assert_array_equal(line(path_ax, bias_explorer.VISION_LABEL), truth)
    # Without noise, dead reckoning's error is exactly the bias's b t²/2.
    np.testing.assert_allclose(line(path_ax, bias_explorer.DEAD_RECKONING_LABEL) - truth,
                               bias_model.bias_drift(DEFAULT, 30.0)[SHOWN], atol=1e-3)
    expected = direct_filter(30.0, 5.0, 2.0, noise)
    np.testing.assert_allclose(line(bias_ax, bias_explorer.BIAS_ESTIMATE_LABEL),
                               expected.estimates[SHOWN, 2], rtol=0, atol=1e-9)
    # Drawing again replaces, not adds.
    bias_explorer.draw_bias(figure, bias=-10.0, sigma_a=5.0, sigma_v=2.0, noise=noise)
    assert len(figure.axes) == 2
    assert len(figure.axes[1].get_lines()) == 4


def test_the_bias_is_learned_at_the_default_values() -> None:
    figure = Figure()
    bias_explorer.draw_bias(figure, bias=20.0, sigma_a=20.0, sigma_v=1.5)
    estimate = line(figure.axes[0], bias_explorer.BIAS_ESTIMATE_LABEL)
    # Within 2 cm/s² of the true 20 cm/s² over the last second shown.
    assert np.all(np.abs(estimate[-100:] - 20.0) < 2.0)


@pytest.mark.parametrize(
    ("values", "name"),
    [({"bias": np.nan, "sigma_a": 20.0, "sigma_v": 1.5}, "bias"),
     ({"bias": 20.0, "sigma_a": 0.0, "sigma_v": 1.5}, "sigma_a"),
     ({"bias": 20.0, "sigma_a": 20.0, "sigma_v": -1.0}, "sigma_v")],
)
def test_bad_values_are_rejected_by_name(values: dict[str, float], name: str) -> None:
    with pytest.raises(ValueError, match=name):
        bias_explorer.draw_bias(Figure(), **values)


def test_wrong_noise_shape_is_rejected() -> None:
    with pytest.raises(ValueError, match="noise"):
        bias_explorer.draw_bias(Figure(), bias=0.0, sigma_a=1.0, sigma_v=1.0,
                                noise=np.zeros((DEFAULT.n_steps, 1)))


def test_static_display_carries_the_picture(explorer) -> None:
    bundle = explorer._repr_mimebundle_()
    assert bundle["text/plain"].startswith("Interactive explorer")
    for description in ("b (cm/s²)", "σ_a (cm/s²)", "σ_v (cm)"):
        assert description in bundle["text/html"]
    assert explorer.png.startswith(b"\x89PNG")


@pytest.mark.slow
def test_redraw_in_place_gives_the_same_picture_as_a_fresh_figure() -> None:
    reused = Figure(figsize=(10, 4.6))
    for values in ({"bias": -55.0, "sigma_a": 300.0, "sigma_v": 4.5},
                   {"bias": 20.0, "sigma_a": 20.0, "sigma_v": 1.5},
                   {"bias": 60.0, "sigma_a": 1.0, "sigma_v": 0.5}):
        bias_explorer.draw_bias(reused, **values)
        fresh = Figure(figsize=(10, 4.6))
        bias_explorer.draw_bias(fresh, **values)
        assert png(reused) == png(fresh)
    assert len(reused.axes) == 2


def test_foreign_or_cleared_figure_is_rebuilt() -> None:
    figure = Figure()
    figure.add_subplot().plot([0, 1], [5, 6], label="someone else's line")
    bias_explorer.draw_bias(figure, bias=10.0, sigma_a=20.0, sigma_v=1.5)
    bias_ax, path_ax = figure.axes
    assert "someone else's line" not in [line.get_label() for line in path_ax.get_lines()]
    figure.clear()
    numbers = bias_explorer.draw_bias(figure, bias=-10.0, sigma_a=20.0, sigma_v=1.5)
    bias_ax, path_ax = figure.axes
    check_numbers(numbers, {"bias": -10.0, "sigma_a": 20.0, "sigma_v": 1.5},
                  bias_model.unit_noise(DEFAULT))
    assert bias_ax.get_title() == bias_explorer.BIAS_TITLE
    assert len(bias_ax.get_lines()) == 2
    assert len(path_ax.get_lines()) == 4


def test_another_scenario_rebuilds_the_panels() -> None:
    """The fixed artists (the true path) follow the scenario a figure is drawn for."""
    figure = Figure()
    bias_explorer.draw_bias(figure, bias=0.0, sigma_a=20.0, sigma_v=1.5)
    wider = dataclasses.replace(DEFAULT, amplitude=15.0)
    bias_explorer.draw_bias(figure, bias=0.0, sigma_a=20.0, sigma_v=1.5, scenario=wider)
    path_ax = figure.axes[1]
    np.testing.assert_array_equal(line(path_ax, bias_explorer.TRUTH_LABEL),
                                  wider.truth[SHOWN, 0])
    assert path_ax.get_ylim() == (-30.0, 30.0)


def test_sigma_v_slider_starts_at_the_scenarios() -> None:
    scenario = dataclasses.replace(DEFAULT, sigma_v=4.5)
    assert bias_explorer.explore_bias(scenario).sliders["sigma_v"].value == 4.5


@pytest.mark.parametrize("sigma_v", [0.2, 7.5])
def test_scenario_outside_the_slider_range_is_refused(sigma_v: float) -> None:
    """Not clipped into the range: the explorer would show another σ_v than asked for."""
    scenario = dataclasses.replace(DEFAULT, sigma_v=sigma_v)
    with pytest.raises(ValueError, match=rf"scenario\.sigma_v .*\[0\.5, 6\] cm, got {sigma_v:g}"):
        bias_explorer.explore_bias(scenario)


def test_the_vision_only_run_hangs_on_sigma_v_only(explorer) -> None:
    kept = explorer.draw.keywords["vision_mses"]
    assert kept.computed == 1
    for name, value, runs in [("bias", -30.0, 0), ("sigma_a", 40.0, 0), ("sigma_v", 3.0, 1)]:
        before = kept.computed
        explorer.sliders[name].value = value
        assert kept.computed - before == runs, (name, value)


@pytest.mark.parametrize("sigma_a", [1.0, 1000.0])
def test_the_numbers_keep_their_precision_at_both_ends_of_sigma_a(explorer, sigma_a) -> None:
    """At σ_a = 1 cm/s² b̂ is known to a few hundredths: no "± 0.0" (the trial's complaint)."""
    explorer.sliders["sigma_a"].value = sigma_a
    spread = explorer.numbers.split(" ± ")[1].split(" cm/s²")[0]
    assert float(spread) > 0 and len(spread.replace(".", "").lstrip("0")) == 2, explorer.numbers
    check_numbers(explorer.numbers, explorer.values, bias_model.unit_noise(EXPLORER_SCENARIO))


def test_plus_minus_gives_two_significant_figures() -> None:
    assert bias_explorer._plus_minus(19.934, 0.3141) == "19.93 ± 0.31"
    assert bias_explorer._plus_minus(20.0123, 0.03141) == "20.012 ± 0.031"
    assert bias_explorer._plus_minus(21.4, 13.2) == "21 ± 13"
    assert bias_explorer._plus_minus(-3.0, 0.0) == "-3.00 ± 0.00"
