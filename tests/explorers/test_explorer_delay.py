"""The delay explorer of notebook 05 draws what the engine computes, on fixed noise."""

from __future__ import annotations

import dataclasses
import html
import re

import numpy as np
import pytest
from explorer_checks import EXPLORER_SCENARIO, explorer_draw, fresh_figure, lines_by_gid
from matplotlib.figure import Figure
from matplotlib.text import Text

from lqe_helpers import experiments
from lqe_helpers.explorers.delay import MAX_DELAY, WINDOW, draw_delay, explore_delay
from lqe_helpers.filter import kalman_filter
from lqe_helpers.prediction import predict_ahead
from lqe_helpers.scenario import DEFAULT

SHOWN = DEFAULT.times <= WINDOW


def _lines(figure: Figure) -> dict[str, np.ndarray]:
    """y data of every line with a gid, by gid; every line runs over the shown window."""
    found = {}
    for gid, (x, y) in lines_by_gid(figure).items():
        np.testing.assert_array_equal(x, DEFAULT.times[SHOWN], err_msg=gid)
        found[gid] = y
    return found


def _independent(delay: float, noise: np.ndarray, sigma_v: float = DEFAULT.sigma_v) -> dict:
    """What the figure must show, built from a plain filter run without the delay module."""
    steps = round(delay / DEFAULT.dt)
    tracking = experiments.track(DEFAULT, ("vision",), sigmas=[sigma_v], noise=noise)
    estimates = tracking.result.estimates
    truth = DEFAULT.truth[:, 0]
    n = DEFAULT.n_steps
    delayed = np.full(n, np.nan)
    delayed[steps:] = estimates[: n - steps, 0]
    vision = np.full(n, np.nan)
    vision[steps:] = truth[: n - steps] + sigma_v * noise[: n - steps, 0]
    ahead = np.linalg.matrix_power(DEFAULT.A, steps)
    prediction = np.full(n, np.nan)
    prediction[steps:] = (estimates[: n - steps] @ ahead.T)[:, 0]
    skip = max(DEFAULT.burn_in_steps, steps)
    return {
        "steps": steps,
        "lines": {
            "truth": truth,
            "vision": vision,
            "delayed": delayed,
            "prediction": prediction,
            "delayed-error": delayed - truth,
            "prediction-error": prediction - truth,
        },
        "mse": {
            "delayed": np.mean((delayed[skip:] - truth[skip:]) ** 2),
            "compensated": np.mean((prediction[skip:] - truth[skip:]) ** 2),
            "no delay": np.mean((estimates[DEFAULT.burn_in_steps:, 0]
                                 - truth[DEFAULT.burn_in_steps:]) ** 2),
        },
    }


def three_figures(value: float) -> str:
    """``value`` (< 1000) to three significant figures, as the numbers line prints it."""
    return f"{value:#.3g}".rstrip(".")


def _texts(figure: Figure) -> list[str]:
    """Every non-empty text the figure draws (titles, labels, legend, tick labels)."""
    return sorted(t.get_text() for t in figure.findobj(Text) if t.get_text())


def _check_figure(figure: Figure, numbers: str, delay: float, noise: np.ndarray,
                  sigma_v: float = DEFAULT.sigma_v) -> None:
    """The figure shows, and ``numbers`` (the returned line of text) states, one run."""
    expected = _independent(delay, noise, sigma_v)
    lines = _lines(figure)
    assert set(lines) == set(expected["lines"])
    for gid, values in expected["lines"].items():
        np.testing.assert_allclose(lines[gid], values[SHOWN], rtol=1e-12, atol=1e-9,
                                   err_msg=gid)
    steps = expected["steps"]
    # Nothing has arrived before δ: no reading, no estimate, no prediction.
    for gid in ("vision", "delayed", "prediction"):
        assert np.all(np.isnan(lines[gid][:steps])), gid
        assert np.all(np.isfinite(lines[gid][steps:])), gid
    assert f"d = {delay:.2f} s" in numbers
    assert f"δ = {steps} {'step' if steps == 1 else 'steps'})" in numbers
    for name, value in expected["mse"].items():
        assert f"{name} {three_figures(value)} cm²" in numbers, (name, numbers)
    # The numbers are beside the figure, not in it.
    assert figure.get_suptitle() == ""
    assert not [text for text in _texts(figure)
                if "MSE" in text or "cm²" in text or "δ =" in text]
    # Every finite value is inside its axes' limits, however far a prediction overshoots.
    for ax in figure.axes:
        low, high = ax.get_ylim()
        for line in ax.lines:
            values = np.asarray(line.get_ydata(), float)
            values = values[np.isfinite(values)]
            assert np.all((values >= low) & (values <= high)), line.get_gid()
    # The grey "nothing yet" band spans exactly [0, d] on both axes, once.
    for ax in figure.axes:
        spans = [p for p in ax.patches if p.get_gid() == "nothing-yet" and p.get_visible()]
        if steps == 0:
            assert spans == []
        else:
            assert len(spans) == 1
            x = spans[0].get_x(), spans[0].get_x() + spans[0].get_width()
            np.testing.assert_allclose(x, [0.0, steps * DEFAULT.dt])


def test_slider_conventions():
    explorer = explore_delay()
    assert list(explorer.sliders) == ["delay"]
    slider = explorer.sliders["delay"]
    assert slider.description == "delay (s)"
    assert slider.min == 0.0
    assert slider.max == pytest.approx(MAX_DELAY)
    assert slider.step == pytest.approx(DEFAULT.dt)
    assert slider.value == pytest.approx(DEFAULT.delay)
    assert slider.readout_format == ".2f"
    assert slider.continuous_update is False
    # Every position of the slider is a whole number of steps.
    assert (slider.max / slider.step) == pytest.approx(round(slider.max / slider.step))


def test_initial_figure_is_the_question_delay():
    explorer = explore_delay()
    noise = EXPLORER_SCENARIO.unit_noise(sensors=("vision",))
    _check_figure(explorer.figure, explorer.numbers, DEFAULT.delay, noise)
    assert explorer.png.startswith(b"\x89PNG")


@pytest.mark.parametrize("delay", [0.0, 0.01, 0.25, MAX_DELAY])
@pytest.mark.slow
def test_slider_value_redraws_the_direct_computation(delay):
    explorer = explore_delay()
    before = explorer.png
    explorer.sliders["delay"].value = delay
    _check_figure(explorer.figure, explorer.numbers, delay,
                  EXPLORER_SCENARIO.unit_noise(sensors=("vision",)))
    assert explorer.png != before


@pytest.mark.slow
def test_noise_stays_fixed_across_slider_moves():
    explorer = explore_delay()
    explorer.sliders["delay"].value = 0.05
    first = _lines(explorer.figure)["vision"]
    explorer.sliders["delay"].value = 0.32
    second = _lines(explorer.figure)["vision"]
    shift = 32 - 5
    # The same readings, only arriving later: the pattern of the noise did not change.
    np.testing.assert_array_equal(second[shift:], first[: first.size - shift])
    explorer.sliders["delay"].value = 0.05
    np.testing.assert_array_equal(_lines(explorer.figure)["vision"], first)


@pytest.mark.slow
def test_slider_value_between_steps_is_rounded_to_a_step():
    explorer = explore_delay()
    explorer.sliders["delay"].value = 0.1240000001
    _check_figure(explorer.figure, explorer.numbers, 0.12,
                  EXPLORER_SCENARIO.unit_noise(sensors=("vision",)))


@pytest.mark.slow
def test_redraw_reuses_axes_and_keeps_one_band():
    explorer = explore_delay()
    axes = list(explorer.figure.axes)
    for delay in (0.2, 0.0, 0.3):
        explorer.sliders["delay"].value = delay
    assert explorer.figure.axes == axes
    assert len(axes) == 2
    _check_figure(explorer.figure, explorer.numbers, 0.3,
                  EXPLORER_SCENARIO.unit_noise(sensors=("vision",)))


@pytest.mark.slow
def test_slider_moves_change_the_numbers_line_not_the_figure_text():
    """Text is the costliest thing to repaint: a move changes only the line beside the figure."""
    explorer = explore_delay()
    explorer.sliders["delay"].value = 0.05
    texts, numbers = _texts(explorer.figure), explorer.numbers
    limits = [ax.get_ylim() for ax in explorer.figure.axes]
    explorer.sliders["delay"].value = 0.15  # both axes keep their limits, so their ticks
    assert [ax.get_ylim() for ax in explorer.figure.axes] == limits
    assert explorer.numbers != numbers
    assert _texts(explorer.figure) == texts
    assert html.escape(explorer.numbers) in explorer.static_html()


def test_draw_function_on_a_fresh_figure_with_given_noise():
    figure = fresh_figure()
    noise = np.random.default_rng(11).standard_normal((DEFAULT.n_steps, 1))
    numbers = draw_delay(figure, delay=0.17, noise=noise)
    _check_figure(figure, numbers, 0.17, noise)
    # Default noise is the scenario's fixed draw.
    numbers = draw_delay(figure, delay=0.17)
    _check_figure(figure, numbers, 0.17, DEFAULT.unit_noise(sensors=("vision",)))


@pytest.mark.parametrize("delay", [0.0, 0.01, 0.02, 0.5])
def test_numbers_line_tells_the_three_mses_apart_at_every_delay(delay):
    """Explore asks to compare them at d = 0 and at the shortest and longest delays: each MSE
    keeps three significant figures (no "0.00"), and at 0.01 s, where the delayed and the
    undelayed MSE differ by under 0.03 cm², the line still shows them different."""
    explorer = explore_delay()
    explorer.sliders["delay"].value = delay
    mses = dict(re.findall(r"(delayed|compensated|no delay) ([\d.]+) cm²", explorer.numbers))
    assert set(mses) == {"delayed", "compensated", "no delay"}, explorer.numbers
    for text in mses.values():
        digits = text.replace(".", "").lstrip("0")
        assert len(digits) >= 3 and "e" not in text, explorer.numbers
    if delay == 0.0:
        assert len(set(mses.values())) == 1, explorer.numbers
    else:
        assert len(set(mses.values())) == 3, explorer.numbers
    assert "(the pack's engine)" in explorer.numbers


def test_draw_function_clears_a_foreign_figure():
    figure = Figure()
    figure.subplots(1, 3)
    numbers = draw_delay(figure, delay=0.1)
    assert len(figure.axes) == 2
    _check_figure(figure, numbers, 0.1, DEFAULT.unit_noise(sensors=("vision",)))


def test_explorer_follows_its_scenario():
    scenario = dataclasses.replace(DEFAULT, sigma_v=4.5, delay=0.2)
    explorer = explore_delay(scenario)
    assert explorer.sliders["delay"].value == pytest.approx(0.2)
    noise = explorer_draw(scenario).unit_noise(sensors=("vision",))
    _check_figure(explorer.figure, explorer.numbers, 0.2, noise, sigma_v=4.5)


@pytest.mark.slow
def test_slider_range_stops_before_the_end_of_a_short_trial():
    scenario = dataclasses.replace(DEFAULT, duration=0.3, burn_in=0.1, delay=0.1)
    slider = explore_delay(scenario).sliders["delay"]
    assert slider.max == pytest.approx(0.29)


@pytest.mark.parametrize("delay", [-0.1, 0.105, 10.0, float("nan")])
def test_bad_delay_raises(delay):
    figure = Figure()
    with pytest.raises(ValueError, match="delay"):
        draw_delay(figure, delay=delay)


def test_static_display_shows_the_figure_and_names_the_slider():
    bundle = explore_delay()._repr_mimebundle_()
    assert "delay (s)" in bundle["text/html"]
    assert re.search(r'src="data:image/png;base64,[A-Za-z0-9+/=]{100,}"', bundle["text/html"])


def test_scenario_delay_beyond_the_slider_range_is_refused():
    """Not clipped to the slider's end: the explorer would show another delay than asked for."""
    scenario = dataclasses.replace(DEFAULT, delay=0.6)
    with pytest.raises(ValueError, match=r"scenario\.delay .*\[0, 0\.5\] s, got 0\.6 s"):
        explore_delay(scenario)


# ------------------------------------------------------------------------------------------
# The student's own my_filter and compensate drive the sliders (issue 15 §4)
# ------------------------------------------------------------------------------------------

# This file ships in the student pack, so a "student's" function here calls the pack's
# engine rather than spell out a worked answer of notebook 01 or 05 Task 1.

def my_filter(y, A, C, Q, R, z0, P0):
    """A student's correct filter of eq. (5)."""
    return kalman_filter(y, A, C, Q, R, z0, P0).estimates


def compensate(estimates, A, delay_steps):
    """A student's correct eq. (7)."""
    return predict_ahead(estimates, A, delay_steps)


@pytest.mark.parametrize("delay", [0.1, 0.0, 0.37])
@pytest.mark.slow
def test_the_students_functions_draw_what_the_engine_draws(delay):
    calls = {"filter": 0, "compensate": 0}

    def counted_filter(y, A, C, Q, R, z0, P0):
        calls["filter"] += 1
        return my_filter(y, A, C, Q, R, z0, P0)

    def counted_compensate(estimates, A, delay_steps):
        calls["compensate"] += 1
        return compensate(estimates, A, delay_steps)

    theirs = explore_delay(filter=counted_filter, compensate=counted_compensate)
    ours = explore_delay()
    for explorer in (theirs, ours):
        explorer.sliders["delay"].value = delay
    assert theirs.problem == ""
    mine, engine = _lines(theirs.figure), _lines(ours.figure)
    assert set(mine) == set(engine)
    for gid in engine:
        np.testing.assert_allclose(mine[gid], engine[gid], rtol=0, atol=1e-9, err_msg=gid)
    assert "(your counted_filter and your counted_compensate)" in theirs.numbers
    assert "(the pack's engine)" in ours.numbers
    assert theirs.numbers.split(":", 1)[1] == ours.numbers.split(":", 1)[1]
    # The filter ran once (a delay only shifts its output); the compensation at each draw.
    assert calls == {"filter": 1, "compensate": 1 + (delay != DEFAULT.delay)}
    _check_figure(theirs.figure, theirs.numbers, delay,
                  EXPLORER_SCENARIO.unit_noise(sensors=("vision",)))


def test_either_function_alone_is_named_with_the_pack_for_the_other():
    assert "(your my_filter and the pack's eq. (7))" in explore_delay(filter=my_filter).numbers
    assert ("(the pack's filter and your compensate)"
            in explore_delay(compensate=compensate).numbers)


def test_a_broken_compensate_shows_one_line_and_the_next_move_draws_again():
    def compensate(estimates, A, delay_steps):
        if delay_steps > 20:
            return estimates[delay_steps:] @ np.linalg.matrix_power(A, delay_steps).T
        return predict_ahead(estimates, A, delay_steps)

    explorer = explore_delay(compensate=compensate)
    assert explorer.problem == ""
    picture = explorer.png
    explorer.sliders["delay"].value = 0.3
    assert explorer.problem.startswith("compensate returned an array of shape (970, 3)")
    assert explorer.numbers == explorer.problem and "\n" not in explorer.problem
    assert explorer.png == picture                      # the last picture stays
    explorer.sliders["delay"].value = 0.2
    assert explorer.problem == ""
    _check_figure(explorer.figure, explorer.numbers, 0.2,
                  EXPLORER_SCENARIO.unit_noise(sensors=("vision",)))


def test_a_compensate_with_nan_after_the_delay_is_named():
    def compensate(estimates, A, delay_steps):
        out = predict_ahead(estimates, A, delay_steps)
        out[delay_steps] = np.nan                        # one row too many left empty
        return out

    explorer = explore_delay(compensate=compensate)
    assert explorer.problem == ("compensate returned NaN in row 10 with δ = 10: eq. (7) gives "
                                "a prediction in every row j >= δ")


def test_a_broken_filter_shows_one_line_from_the_start():
    def my_filter(y, A, C, Q, R, z0, P0):
        return kalman_filter(y, A, C, Q, R, z0, P0).estimates[:, 0]      # positions only

    explorer = explore_delay(filter=my_filter)
    assert explorer.problem.startswith("my_filter returned")
    assert "shape (1000,)" in explorer.problem and "(1000, 3)" in explorer.problem
    assert explorer.png.startswith(b"\x89PNG")           # the empty axes, no traceback

    def raises(y, A, C, Q, R, z0, P0):
        return np.linalg.inv(C)                          # C is 1 × 3: not invertible

    problem = explore_delay(filter=raises).problem
    assert problem.startswith("raises raised LinAlgError"), problem
    assert "(in raises, line" in problem


def test_functions_not_written_yet_say_so():
    def my_filter(y, A, C, Q, R, z0, P0):
        raise NotImplementedError

    def compensate(estimates, A, delay_steps):
        raise NotImplementedError

    assert explore_delay(filter=my_filter).problem.startswith("my_filter is not written yet")
    explorer = explore_delay(compensate=compensate)
    assert explorer.problem.startswith("compensate is not written yet")
    assert "then run the Explore cell again" in explorer.problem


@pytest.mark.parametrize("name", ["filter", "compensate"])
def test_a_function_argument_that_is_not_a_function_is_refused(name):
    with pytest.raises(ValueError, match=rf"{name} must be None .*or a function.*got a ndarray"):
        explore_delay(**{name: np.zeros(3)})
    with pytest.raises(ValueError, match=rf"{name} must be None .*or a function"):
        draw_delay(fresh_figure(), delay=0.1, **{name: "my_filter"})


def test_draw_function_runs_the_students_functions():
    figure = fresh_figure()
    numbers = draw_delay(figure, delay=0.17, filter=my_filter, compensate=compensate)
    assert "(your my_filter and your compensate)" in numbers
    _check_figure(figure, numbers, 0.17, DEFAULT.unit_noise(sensors=("vision",)))


@pytest.mark.slow
def test_the_explorer_draws_the_students_numbers_not_the_engines():
    """A filter 1 cm off and a compensation 2 cm off show up in the lines and the MSEs."""
    def my_filter(y, A, C, Q, R, z0, P0):
        return kalman_filter(y, A, C, Q, R, z0, P0).estimates + np.array([1.0, 0.0, 0.0])

    def compensate(estimates, A, delay_steps):
        return predict_ahead(estimates, A, delay_steps) + np.array([2.0, 0.0, 0.0])

    theirs = explore_delay(filter=my_filter, compensate=compensate)
    engine = _lines(explore_delay().figure)
    mine = _lines(theirs.figure)
    arrived = slice(DEFAULT.delay_steps(DEFAULT.delay), None)
    np.testing.assert_allclose((mine["delayed"] - engine["delayed"])[arrived], 1.0, atol=1e-9)
    np.testing.assert_allclose((mine["prediction"] - engine["prediction"])[arrived], 3.0,
                               atol=1e-9)
    np.testing.assert_array_equal(mine["vision"], engine["vision"])      # the same readings
    noise = EXPLORER_SCENARIO.unit_noise(sensors=("vision",))
    expected = _independent(DEFAULT.delay, noise)
    skip = max(DEFAULT.burn_in_steps, expected["steps"])
    shifted = expected["lines"]["prediction"][skip:] + 3.0 - DEFAULT.truth[skip:, 0]
    assert f"compensated {three_figures(np.mean(shifted ** 2))} cm²" in theirs.numbers


def test_functions_not_saved_yet_say_so_in_one_line(tmp_path, monkeypatch):
    """The notebook's explorer cell loads the saved functions: before they exist, one line."""
    from lqe_helpers import student_code

    monkeypatch.chdir(tmp_path)                      # no my_functions/ here
    filter_, compensate_ = student_code.load("my_filter"), student_code.load("compensate")
    explorer = explore_delay(filter=filter_, compensate=compensate_)
    assert explorer.problem.startswith("my_filter is not saved yet: my_functions/my_filter.py "
                                       "does not exist")
    explorer = explore_delay(compensate=compensate_)
    assert explorer.problem.startswith("compensate is not saved yet")
    assert "\n" not in explorer.problem
