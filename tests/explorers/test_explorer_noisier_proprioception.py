"""The σ_p explorer of notebook 04 draws what a plain filter run and the theory compute."""

from __future__ import annotations

import dataclasses
import html
import re

import numpy as np
import pytest
from explorer_checks import EXPLORER_SCENARIO, explorer_draw, fresh_figure
from explorer_checks import lines_by_gid as _lines
from matplotlib.figure import Figure
from matplotlib.text import Text

from lqe_helpers.explorers.noisier_proprioception import (
    CURVE_RANGE,
    FUSED,
    QUESTION_SIGMA_P,
    SIGMA_P_RANGE,
    START_SIGMA_P,
    THEORY_TITLE,
    draw_noisier_proprioception,
    explore_noisier_proprioception,
    steady_position_variances,
)
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT, Scenario
from lqe_helpers.steady_state import steady_state
from lqe_helpers.student_code import StudentCodeError


def _sig(value: float, digits: int) -> str:
    """``value`` to ``digits`` significant figures, trailing zeros kept (numpy's formatter)."""
    return np.format_float_positional(value, precision=digits, unique=False, fractional=False,
                                      trim="k").rstrip(".")

TRIAL_GIDS = {"truth", "vision-only", "fused", "vision-only error", "fused error"}
ONE_ROW = np.array([[1.0, 0.0, 0.0]])
TWO_ROWS = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])


def _filter(readings: np.ndarray, sigmas: list[float], scenario: Scenario):
    C = TWO_ROWS if len(sigmas) == 2 else ONE_ROW
    return kalman_filter(readings, scenario.A, C, scenario.Q, np.diag(np.square(sigmas)),
                         np.asarray(scenario.z0, float), scenario.p0_variance * np.eye(3))


def _check_figure(figure: Figure, numbers: str, sigma_p: float, noise: np.ndarray,
                  scenario: Scenario = DEFAULT, whose: str = "the pack's engine") -> None:
    """``figure`` and the ``numbers`` its drawing returned show this trial, computed anew."""
    sigma_v = scenario.sigma_v
    truth = scenario.truth[:, 0]
    readings = truth[:, None] + noise * [sigma_v, sigma_p]
    alone = _filter(readings[:, :1], [sigma_v], scenario).estimates[:, 0]
    fused = _filter(readings, [sigma_v, sigma_p], scenario)
    both = fused.estimates[:, 0]
    expected = {"truth": truth, "vision-only": alone, "fused": both,
                "vision-only error": alone - truth, "fused error": both - truth}
    lines = _lines(figure)
    assert TRIAL_GIDS <= set(lines)
    for gid, values in expected.items():
        np.testing.assert_array_equal(lines[gid][0], scenario.times)
        np.testing.assert_allclose(lines[gid][1], values, rtol=1e-9, atol=1e-9, err_msg=gid)
    # The marker sits on the theory curve at the slider's σ_p: the filter's own
    # converged position variance (an independent route to the Riccati fixed point).
    x, y = lines["theory now"]
    assert x == pytest.approx([sigma_p])
    assert y == pytest.approx([fused.estimate_covariances[-1, 0, 0]], rel=1e-7)
    # The numbers beside the figure carry both σ's, this trial's MSEs after the burn-in
    # and proprioception's weight, its share of the reliabilities 1/σ²; the figure has
    # no title of its own and the right panel's never changes.
    weight = sigma_v**2 / (sigma_v**2 + sigma_p**2)
    skip = scenario.burn_in_steps
    mse_vision, mse_fused = (np.mean((estimate[skip:] - truth[skip:]) ** 2)
                             for estimate in (alone, both))
    # At question (d)'s σ_p the weight is withheld: Going further 1 computes it (issue 23 §5).
    weight_text = (f"Proprioception's weight in the steady state at σ_p = {QUESTION_SIGMA_P:g} cm: "
                   f"Going further 1 asks you to compute it." if sigma_p == QUESTION_SIGMA_P
                   else f"Proprioception's weight in the steady state: {_sig(100 * weight, 3)} %.")
    assert numbers == (f"σ_v = {sigma_v:g} cm, σ_p = {sigma_p:g} cm. MSE of this trial after "
                       f"{scenario.burn_in:g} s: vision only {_sig(mse_vision, 4)} cm², "
                       f"fused {_sig(mse_fused, 4)} cm². {weight_text} Estimates from "
                       f"{whose}."), numbers
    assert figure.get_suptitle() == ""
    assert figure.axes[2].get_title() == THEORY_TITLE


def test_slider_conventions():
    explorer = explore_noisier_proprioception()
    assert list(explorer.sliders) == ["sigma_p"]
    slider = explorer.sliders["sigma_p"]
    low, high, step = SIGMA_P_RANGE
    assert slider.description == "σ_p (cm)"
    assert (slider.min, slider.max, slider.step) == pytest.approx((low, high, step))
    assert slider.min > 0
    assert slider.continuous_update is False
    assert slider.readout_format == ".1f"
    # It starts near question (d)'s σ_p, not at it (issue 15: at 4.5 cm the weight in the
    # numbers line is a task's answer in notebook 04), and 4.5 cm is one step away.
    assert QUESTION_SIGMA_P == 4.5
    assert slider.value == pytest.approx(START_SIGMA_P) == pytest.approx(6.0)
    for value in (1.5, 4.5, START_SIGMA_P):
        assert (value - low) / step == pytest.approx(round((value - low) / step))


@pytest.mark.slow
def test_initial_figure_is_near_question_d_on_the_explorers_draw():
    explorer = explore_noisier_proprioception()
    _check_figure(explorer.figure, explorer.numbers, START_SIGMA_P,
                  EXPLORER_SCENARIO.unit_noise(sensors=FUSED))
    assert explorer.png.startswith(b"\x89PNG")


@pytest.mark.parametrize("sigma_p", [0.5, 1.5, 9.0, 30.0])
@pytest.mark.slow
def test_slider_value_redraws_the_direct_computation(sigma_p):
    explorer = explore_noisier_proprioception()
    before = explorer.png
    explorer.sliders["sigma_p"].value = sigma_p
    _check_figure(explorer.figure, explorer.numbers, sigma_p,
                  EXPLORER_SCENARIO.unit_noise(sensors=FUSED))
    assert explorer.png != before


def test_noise_stays_fixed_across_slider_moves():
    explorer = explore_noisier_proprioception()
    first = _lines(explorer.figure)
    for sigma_p in (12.0, 0.5, START_SIGMA_P):
        explorer.sliders["sigma_p"].value = sigma_p
        lines = _lines(explorer.figure)
        # Vision and its filter do not depend on σ_p at all.
        np.testing.assert_array_equal(lines["vision-only"][1], first["vision-only"][1])
    # Back at the start the same noise gives the same fused estimate, bit for bit.
    np.testing.assert_array_equal(lines["fused"][1], first["fused"][1])


def test_theory_curve_matches_separate_riccati_solves():
    figure = fresh_figure()
    draw_noisier_proprioception(figure, sigma_p=4.5)
    lines = _lines(figure)
    x, y = lines["theory fused"]
    np.testing.assert_allclose(x[[0, -1]], CURVE_RANGE)
    assert np.all(np.diff(np.log(x)) > 0)
    for i in (0, 40, 85, x.size - 1):
        one = steady_state(DEFAULT.A, TWO_ROWS, DEFAULT.Q, np.diag([1.5**2, x[i] ** 2]))
        assert y[i] == pytest.approx(one.estimate_covariance[0, 0], rel=1e-9)
    alone = steady_state(DEFAULT.A, ONE_ROW, DEFAULT.Q, np.array([[1.5**2]]))
    level = alone.estimate_covariance[0, 0]
    _, level_y = lines["theory vision-only"]
    np.testing.assert_allclose(level_y, level, rtol=1e-12)
    # An extra, correctly modelled sensor never hurts, and helps less as it gets noisier.
    assert np.all(y < level)
    assert np.all(np.diff(y) > 0)
    assert y[-1] == pytest.approx(level, rel=1e-3)


def test_steady_position_variances_against_the_filter_run_to_convergence():
    sigma_p = np.array([0.8, 4.5, 20.0])
    level, fused = steady_position_variances(DEFAULT, 1.5, sigma_p)
    long_run = dataclasses.replace(DEFAULT, duration=30.0)
    y = np.zeros((long_run.n_steps, 2))
    for s, value in enumerate(sigma_p):
        run = _filter(y, [1.5, value], long_run)
        assert fused[s] == pytest.approx(run.estimate_covariances[-1, 0, 0], rel=1e-7)
    run = _filter(y[:, :1], [1.5], long_run)
    assert level == pytest.approx(run.estimate_covariances[-1, 0, 0], rel=1e-7)


@pytest.mark.slow
def test_redraw_reuses_the_panels_and_matches_a_fresh_draw():
    explorer = explore_noisier_proprioception()
    axes = list(explorer.figure.axes)
    for sigma_p in (2.0, 25.0, 7.5):
        explorer.sliders["sigma_p"].value = sigma_p
    assert explorer.figure.axes == axes
    assert len(axes) == 3
    fresh = fresh_figure()
    numbers = draw_noisier_proprioception(fresh, sigma_p=7.5,
                                          noise=EXPLORER_SCENARIO.unit_noise(sensors=FUSED))
    reused, drawn = _lines(explorer.figure), _lines(fresh)
    assert set(reused) == set(drawn)
    for gid in drawn:
        for a, b in zip(reused[gid], drawn[gid], strict=True):
            np.testing.assert_array_equal(a, b, err_msg=gid)
    assert explorer.numbers == numbers


def test_no_text_in_the_figure_changes_with_the_slider():
    """Text is the costliest artist to repaint: the numbers live beside the figure."""
    explorer = explore_noisier_proprioception()

    def texts() -> list[str]:
        return [text.get_text() for text in explorer.figure.findobj(Text)]

    before, numbers = texts(), explorer.numbers
    explorer.sliders["sigma_p"].value = 12.0
    assert texts() == before
    assert explorer.numbers != numbers


def test_draw_function_on_a_fresh_figure_with_given_noise():
    figure = fresh_figure()
    noise = np.random.default_rng(3).standard_normal((DEFAULT.n_steps, 2))
    numbers = draw_noisier_proprioception(figure, sigma_p=2.5, noise=noise)
    _check_figure(figure, numbers, 2.5, noise)


def test_draw_function_clears_a_foreign_figure():
    figure = fresh_figure()
    figure.subplots(1, 4)
    numbers = draw_noisier_proprioception(figure, sigma_p=4.5)
    assert len(figure.axes) == 3
    _check_figure(figure, numbers, 4.5, DEFAULT.unit_noise(sensors=FUSED))


def test_explorer_follows_its_scenario():
    scenario = dataclasses.replace(DEFAULT, sigma_v=3.0, seed=2)
    explorer = explore_noisier_proprioception(scenario)
    _check_figure(explorer.figure, explorer.numbers, START_SIGMA_P,
                  explorer_draw(scenario).unit_noise(sensors=FUSED), scenario)


@pytest.mark.parametrize("sigma_p", [0.0, -4.5, float("inf")])
def test_bad_sigma_p_raises(sigma_p):
    with pytest.raises(ValueError, match="sigma_p"):
        draw_noisier_proprioception(fresh_figure(), sigma_p=sigma_p)


def test_bad_inputs_to_the_theory_raise():
    with pytest.raises(ValueError, match="sigma_p"):
        steady_position_variances(DEFAULT, 1.5, np.array([1.0, -2.0]))
    with pytest.raises(ValueError, match="sigma_v"):
        steady_position_variances(DEFAULT, 0.0, np.array([1.0]))
    with pytest.raises(ValueError, match="noise must have shape"):
        draw_noisier_proprioception(fresh_figure(), sigma_p=4.5, noise=np.zeros((3, 2)))


def test_static_display_carries_the_picture_and_names_the_sliders():
    explorer = explore_noisier_proprioception()
    bundle = explorer._repr_mimebundle_()
    assert bundle["text/plain"].startswith("Interactive explorer")
    for description in ("σ_p (cm)",):
        assert description in bundle["text/html"]
    assert explorer.png.startswith(b"\x89PNG")
    # A reader of the static page gets the trial's MSEs and the weight too, in the caption.
    assert explorer.numbers.startswith("σ_v = 1.5 cm, σ_p = 6 cm. MSE of this trial")
    assert html.escape(explorer.numbers) in bundle["text/html"]


def test_theory_axis_has_plain_labels_and_the_numbers_keep_three_significant_figures():
    figure = fresh_figure()
    numbers = draw_noisier_proprioception(figure, sigma_p=30.0)
    theory_ax = figure.axes[2]
    figure.canvas.draw()
    labels = [label.get_text() for label in theory_ax.get_xticklabels()]
    assert labels == ["0.3", "1", "3", "10", "30", "100"]
    assert theory_ax.get_xticklabels(minor=True) == []
    # At σ_p = 30 cm proprioception still has a weight, 2.25 / (2.25 + 900) = 0.249 %, and
    # the fused MSE differs from the vision-only one in the fourth significant figure.
    assert numbers.endswith("Proprioception's weight in the steady state: 0.249 %. Estimates "
                            "from the pack's engine.")
    vision, fused = re.findall(r"(?:vision only|fused) ([0-9.]+) cm²", numbers)
    assert len(vision.replace("0.", "", 1)) == 4 and vision != fused


# ------------------------------------------------------------------------------------------
# The student's own filter (issue 15 §4)
# ------------------------------------------------------------------------------------------


def my_filter(y, A, C, Q, R, z0, P0):
    """A student's filter: notebook 01's signature and output, (n, k) estimates.

    Its numbers come from the engine (this file ships with the student pack, which holds
    no worked eq. (5)); what is tested is that the explorer runs it and draws its output.
    """
    return kalman_filter(y, A, C, Q, R, z0, P0).estimates


@pytest.mark.slow
def test_the_students_filter_drives_both_estimates_and_equals_the_engine():
    explorer = explore_noisier_proprioception(filter=my_filter)
    noise = EXPLORER_SCENARIO.unit_noise(sensors=FUSED)
    _check_figure(explorer.figure, explorer.numbers, START_SIGMA_P, noise,
                  whose="your my_filter")
    for sigma_p in (2.0, 0.5):
        explorer.sliders["sigma_p"].value = sigma_p
        _check_figure(explorer.figure, explorer.numbers, sigma_p, noise, whose="your my_filter")
    assert explorer.problem == ""
    assert "(your my_filter)" in explorer.description


def test_the_students_filter_is_what_the_explorer_runs():
    """Not the engine in disguise: a filter off by a constant shows that constant."""
    calls = []

    def my_filter(y, A, C, Q, R, z0, P0):
        calls.append(y.shape)
        return kalman_filter(y, A, C, Q, R, z0, P0).estimates + 0.5

    figure = fresh_figure()
    draw_noisier_proprioception(figure, sigma_p=3.0, filter=my_filter)
    lines = _lines(figure)
    truth = DEFAULT.truth[:, 0]
    engine = fresh_figure()
    draw_noisier_proprioception(engine, sigma_p=3.0)
    for gid in ("vision-only", "fused"):
        np.testing.assert_allclose(lines[gid][1], _lines(engine)[gid][1] + 0.5, rtol=0,
                                   atol=1e-9)
    np.testing.assert_allclose(lines["fused error"][1], lines["fused"][1] - truth, atol=1e-12)
    assert sorted(calls) == [(DEFAULT.n_steps, 1), (DEFAULT.n_steps, 2)]


def test_a_broken_filter_shows_one_line_and_the_next_move_tries_again():
    state = {"broken": False}

    def my_filter(y, A, C, Q, R, z0, P0):
        if state["broken"]:
            return kalman_filter(y, A, C, Q, R, z0, P0).estimates[:, :, None]
        return kalman_filter(y, A, C, Q, R, z0, P0).estimates

    explorer = explore_noisier_proprioception(filter=my_filter)
    picture = explorer.png
    state["broken"] = True
    explorer.sliders["sigma_p"].value = 9.0
    assert explorer.problem.startswith("my_filter returned an array of shape (1000, 3, 1)")
    assert explorer.problem.endswith("it must return the estimates ẑ, an array of shape (n, k) = "
                                     "(1000, 3) (on the explorer's trial with both senses, "
                                     "σ_p = 9 cm)")
    assert "\n" not in explorer.problem and explorer.numbers == explorer.problem
    assert explorer.png == picture                       # the last picture stays
    state["broken"] = False
    explorer.sliders["sigma_p"].value = 10.0
    assert explorer.problem == ""
    _check_figure(explorer.figure, explorer.numbers, 10.0,
                  EXPLORER_SCENARIO.unit_noise(sensors=FUSED), whose="your my_filter")


def test_a_filter_that_raises_names_its_own_line():
    def my_filter(y, A, C, Q, R, z0, P0):
        K = P0 @ C @ np.linalg.inv(R)                    # C where Cᵀ belongs
        return K

    explorer = explore_noisier_proprioception(filter=my_filter)
    assert explorer.problem.startswith("my_filter raised ValueError")
    assert "K = P0 @ C @ np.linalg.inv(R)" in explorer.problem
    assert "the explorer's trial with vision alone" in explorer.problem
    assert explorer.png.startswith(b"\x89PNG")


def test_a_filter_not_written_yet_says_so():
    def my_filter(y, A, C, Q, R, z0, P0):
        raise NotImplementedError("Replace this line with your code")

    explorer = explore_noisier_proprioception(filter=my_filter)
    assert explorer.problem.startswith("my_filter is not written yet")
    assert explorer.problem.endswith("then run the Explore cell again")


def test_a_filter_that_never_returns_is_stopped(monkeypatch):
    from lqe_helpers.student_code import calling

    monkeypatch.setattr(calling, "TIME_LIMIT", 0.2)

    def my_filter(y, A, C, Q, R, z0, P0):
        while True:
            pass

    figure = fresh_figure()
    with pytest.raises(StudentCodeError, match=r"my_filter did not return within 0\.2 s"):
        draw_noisier_proprioception(figure, sigma_p=4.5, filter=my_filter)


def test_filter_must_be_a_function():
    with pytest.raises(ValueError,
                       match=r"filter must be None .*or a function, e.g. your my_filter"):
        explore_noisier_proprioception(filter="my_filter")
    with pytest.raises(ValueError, match=r"filter must be None .*or a function"):
        draw_noisier_proprioception(fresh_figure(), sigma_p=4.5, filter=np.zeros(3))
