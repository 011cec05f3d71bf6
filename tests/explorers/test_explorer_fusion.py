"""The fusion explorer of notebook 03 draws what a plain filter run computes, on fixed noise,
with the pack's engine or with a student's own filter."""

from __future__ import annotations

import dataclasses
import html
import time

import numpy as np
import pytest
import reference_loops as reference
from explorer_checks import EXPLORER_SCENARIO, explorer_draw, fresh_figure, lines_by_gid
from matplotlib.figure import Figure
from matplotlib.text import Text

from lqe_helpers.explorers.fusion import (
    FUSED,
    SHARES_TITLE,
    SIGMA_RANGE,
    draw_fusion,
    explore_fusion,
    vision_only,
)
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT, Scenario
from lqe_helpers.student_code import StudentCodeError, calling


def _sig(value: float, digits: int) -> str:
    """``value`` to ``digits`` significant figures, trailing zeros kept (numpy's formatter)."""
    return np.format_float_positional(value, precision=digits, unique=False, fractional=False,
                                      trim="k").rstrip(".")


LINE_GIDS = {"vision readings", "proprioception readings", "truth", "vision-only", "fused",
             "vision-only error", "fused error"}


def _lines(figure: Figure, scenario: Scenario = DEFAULT) -> dict[str, np.ndarray]:
    """y data of every line with a gid, by gid; every line runs over the whole trial."""
    found = {}
    for gid, (x, y) in lines_by_gid(figure).items():
        np.testing.assert_array_equal(x, scenario.times, err_msg=gid)
        found[gid] = y
    return found


def _weights(figure: Figure) -> dict[str, float]:
    return {patch.get_gid(): patch.get_height() for ax in figure.axes for patch in ax.patches
            if patch.get_gid() is not None and patch.get_gid().startswith("weight")}


def _independent(sigma_v: float, sigma_p: float, noise: np.ndarray,
                 scenario: Scenario = DEFAULT) -> dict[str, np.ndarray]:
    """The lines the figure must show, from hand-built C, R and readings."""
    truth = scenario.truth[:, 0]
    readings = truth[:, None] + noise * [sigma_v, sigma_p]
    z0, P0 = np.asarray(scenario.z0, float), scenario.p0_variance * np.eye(3)
    alone = kalman_filter(readings[:, :1], scenario.A, np.array([[1.0, 0.0, 0.0]]), scenario.Q,
                          np.array([[sigma_v**2]]), z0, P0).estimates[:, 0]
    both = kalman_filter(readings, scenario.A, np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]),
                         scenario.Q, np.diag([sigma_v**2, sigma_p**2]), z0, P0).estimates[:, 0]
    return {
        "vision readings": readings[:, 0],
        "proprioception readings": readings[:, 1],
        "truth": truth,
        "vision-only": alone,
        "fused": both,
        "vision-only error": alone - truth,
        "fused error": both - truth,
    }


def _check_figure(figure: Figure, numbers: str, sigma_v: float, sigma_p: float,
                  noise: np.ndarray, scenario: Scenario = DEFAULT,
                  whose: str = "the pack's engine") -> None:
    """``figure`` and the ``numbers`` its drawing returned show this trial, computed anew."""
    expected = _independent(sigma_v, sigma_p, noise, scenario)
    lines = _lines(figure, scenario)
    assert set(lines) == LINE_GIDS
    for gid, values in expected.items():
        np.testing.assert_allclose(lines[gid], values, rtol=1e-9, atol=1e-9, err_msg=gid)
    # Reliability weighting: the shares of the position gain are (1/σ_v², 1/σ_p²) normalised.
    share_v = sigma_p**2 / (sigma_v**2 + sigma_p**2)
    weights = _weights(figure)
    assert weights["weight vision"] == pytest.approx(share_v, rel=1e-9)
    assert weights["weight proprioception"] == pytest.approx(1 - share_v, rel=1e-9)
    texts = [text.get_text() for ax in figure.axes for text in ax.texts]
    assert texts == [f"{_sig(100 * share_v, 2)} %", f"{_sig(100 * (1 - share_v), 2)} %"]
    # The numbers beside the figure carry both σ's and this trial's MSEs after the
    # burn-in; the figure has no title of its own and the right panel's never changes.
    skip = scenario.burn_in_steps
    mse_vision, mse_fused = (np.mean(expected[gid][skip:] ** 2)
                             for gid in ("vision-only error", "fused error"))
    assert numbers == (f"σ_v = {sigma_v:g} cm, σ_p = {sigma_p:g} cm. MSE of this trial after "
                       f"{scenario.burn_in:g} s: vision only {_sig(mse_vision, 4)} cm², "
                       f"fused {_sig(mse_fused, 4)} cm². Filter: {whose}."), numbers
    assert figure.get_suptitle() == ""
    assert figure.axes[2].get_title() == SHARES_TITLE
    # It says what is drawn, not the rule the shares follow (notebook 03's Going further 5).
    assert "reliab" not in SHARES_TITLE and "∝" not in SHARES_TITLE


def test_slider_conventions():
    explorer = explore_fusion()
    assert list(explorer.sliders) == ["sigma_v", "sigma_p"]
    low, high, step = SIGMA_RANGE
    for name, description in (("sigma_v", "σ_v (cm)"), ("sigma_p", "σ_p (cm)")):
        slider = explorer.sliders[name]
        assert slider.description == description
        assert (slider.min, slider.max, slider.step) == pytest.approx((low, high, step))
        assert slider.min > 0  # every position is a valid σ
        assert slider.continuous_update is False
        assert slider.readout_format == ".2f"
    # The question's values: both sliders start at 1.5 cm, and 4.5 cm is on the grid.
    assert explorer.values == pytest.approx({"sigma_v": 1.5, "sigma_p": 1.5})
    for value in (1.5, 4.5):
        assert (value - low) / step == pytest.approx(round((value - low) / step))


@pytest.mark.slow
def test_initial_figure_is_question_c():
    explorer = explore_fusion()
    _check_figure(explorer.figure, explorer.numbers, 1.5, 1.5,
                  EXPLORER_SCENARIO.unit_noise(sensors=FUSED))
    assert explorer.png.startswith(b"\x89PNG")


@pytest.mark.parametrize(("sigma_v", "sigma_p"), [(1.5, 4.5), (4.5, 1.5), (0.5, 6.0), (3.0, 3.0)])
@pytest.mark.slow
def test_slider_values_redraw_the_direct_computation(sigma_v, sigma_p):
    explorer = explore_fusion()
    before = explorer.png
    explorer.sliders["sigma_v"].value = sigma_v
    explorer.sliders["sigma_p"].value = sigma_p
    _check_figure(explorer.figure, explorer.numbers, sigma_v, sigma_p,
                  EXPLORER_SCENARIO.unit_noise(sensors=FUSED))
    assert explorer.png != before


@pytest.mark.slow
def test_noise_stays_fixed_across_slider_moves():
    explorer = explore_fusion()
    truth = DEFAULT.truth[:, 0]
    expected = EXPLORER_SCENARIO.unit_noise(sensors=FUSED)
    for sigma_v, sigma_p in ((2.0, 1.5), (2.0, 5.0), (0.75, 5.0)):
        explorer.sliders["sigma_v"].value = sigma_v
        explorer.sliders["sigma_p"].value = sigma_p
        lines = _lines(explorer.figure)
        np.testing.assert_allclose((lines["vision readings"] - truth) / sigma_v, expected[:, 0],
                                   rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose((lines["proprioception readings"] - truth) / sigma_p,
                                   expected[:, 1], rtol=1e-9, atol=1e-9)


def test_moving_sigma_p_leaves_the_vision_only_filter_alone():
    explorer = explore_fusion()
    first = _lines(explorer.figure)
    explorer.sliders["sigma_p"].value = 5.0
    second = _lines(explorer.figure)
    np.testing.assert_array_equal(second["vision-only"], first["vision-only"])
    np.testing.assert_array_equal(second["vision readings"], first["vision readings"])
    assert not np.allclose(second["fused"], first["fused"])


@pytest.mark.slow
def test_redraw_reuses_the_panels_and_matches_a_fresh_draw():
    explorer = explore_fusion()
    axes = list(explorer.figure.axes)
    for sigma_v in (3.0, 0.5, 2.25):
        explorer.sliders["sigma_v"].value = sigma_v
    assert explorer.figure.axes == axes
    assert len(axes) == 3
    bands = [c for c in axes[1].collections if c.get_gid() == "fused band"]
    assert len(bands) == 1
    fresh = fresh_figure()
    numbers = draw_fusion(fresh, sigma_v=2.25, sigma_p=1.5,
                          noise=EXPLORER_SCENARIO.unit_noise(sensors=FUSED))
    reused, drawn = _lines(explorer.figure), _lines(fresh)
    for gid in LINE_GIDS:
        np.testing.assert_array_equal(reused[gid], drawn[gid], err_msg=gid)
    assert _weights(explorer.figure) == _weights(fresh)
    assert explorer.numbers == numbers


def _texts(figure: Figure) -> list[str]:
    return [text.get_text() for text in figure.findobj(Text)]


@pytest.mark.slow
def test_only_the_shares_on_the_bars_change_among_the_figures_texts():
    """Text is the costliest artist to repaint: the numbers live beside the figure."""
    explorer = explore_fusion()
    before, numbers = _texts(explorer.figure), explorer.numbers
    explorer.sliders["sigma_v"].value = 3.0
    explorer.sliders["sigma_p"].value = 0.75
    share_v = 0.75**2 / (3.0**2 + 0.75**2)
    changed = [(old, new) for old, new in zip(before, _texts(explorer.figure), strict=True)
               if old != new]
    assert changed == [("50 %", f"{_sig(100 * share_v, 2)} %"),
                       ("50 %", f"{_sig(100 * (1 - share_v), 2)} %")]
    assert explorer.numbers != numbers


@pytest.mark.slow
def test_the_right_panels_title_stays_in_the_cached_background():
    """Clear of the bars' axes area, so a move repaints the bars but not the title."""
    explorer = explore_fusion()
    title = explorer.figure.axes[2].title
    for sigma_v, sigma_p in ((0.5, 6.0), (6.0, 0.5), (0.75, 6.0), (0.5, 5.75)):
        explorer.sliders["sigma_v"].value = sigma_v
        explorer.sliders["sigma_p"].value = sigma_p
    assert explorer.layers.fast_renders >= 1
    repainted = explorer.layers.repainted  # the artists a move repaints
    assert any(patch.get_gid() == "weight vision" for patch in repainted)
    assert title not in repainted


def test_band_is_the_fused_filters_own_two_standard_deviations():
    figure = fresh_figure()
    draw_fusion(figure, sigma_v=1.5, sigma_p=3.0)
    (band,) = [c for c in figure.axes[1].collections if c.get_gid() == "fused band"]
    vertices = band.get_paths()[0].vertices
    variances = kalman_filter(
        DEFAULT.truth[:, :1] + DEFAULT.unit_noise(sensors=FUSED) * [1.5, 3.0], DEFAULT.A,
        np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), DEFAULT.Q, np.diag([1.5**2, 3.0**2]),
        np.zeros(3), np.eye(3),
    ).estimate_covariances[:, 0, 0]
    # The band is centred on zero error and reaches ±2 SD of the filter's own variance.
    upper = _upper_edge(vertices)
    np.testing.assert_allclose(upper, 2 * np.sqrt(variances), rtol=1e-9)
    # Two sensors, σ_v = 1.5 and σ_p = 3 cm: the settled variance is below the
    # combined reading's 1 / (1/1.5² + 1/3²) = 1.8 cm² (the filter also averages in time).
    assert variances[-1] < 1 / (1 / 1.5**2 + 1 / 3.0**2)


def _upper_edge(vertices: np.ndarray) -> np.ndarray:
    """Upper edge of a fill_between polygon at each sample time (the largest y there)."""
    return np.array([vertices[np.isclose(vertices[:, 0], t), 1].max() for t in DEFAULT.times])


def test_draw_function_on_a_fresh_figure_with_given_noise():
    figure = fresh_figure()
    noise = np.random.default_rng(7).standard_normal((DEFAULT.n_steps, 2))
    numbers = draw_fusion(figure, sigma_v=2.5, sigma_p=1.0, noise=noise)
    _check_figure(figure, numbers, 2.5, 1.0, noise)
    numbers = draw_fusion(figure, sigma_v=2.5, sigma_p=1.0)
    _check_figure(figure, numbers, 2.5, 1.0, DEFAULT.unit_noise(sensors=FUSED))


def test_draw_function_clears_a_foreign_figure():
    figure = fresh_figure()
    figure.subplots(2, 2)
    numbers = draw_fusion(figure, sigma_v=1.5, sigma_p=4.5)
    assert len(figure.axes) == 3
    _check_figure(figure, numbers, 1.5, 4.5, DEFAULT.unit_noise(sensors=FUSED))


def test_explorer_follows_its_scenario():
    scenario = dataclasses.replace(DEFAULT, sigma_v=2.0, sigma_p=3.0, seed=11)
    explorer = explore_fusion(scenario)
    assert explorer.values == pytest.approx({"sigma_v": 2.0, "sigma_p": 3.0})
    _check_figure(explorer.figure, explorer.numbers, 2.0, 3.0,
                  explorer_draw(scenario).unit_noise(sensors=FUSED), scenario)


@pytest.mark.parametrize(("sigma_v", "sigma_p", "name"),
                         [(0.0, 1.5, "sigma_v"), (-1.0, 1.5, "sigma_v"),
                          (1.5, float("nan"), "sigma_p"), (1.5, 0.0, "sigma_p")])
def test_bad_sigma_raises(sigma_v, sigma_p, name):
    with pytest.raises(ValueError, match=name):
        draw_fusion(fresh_figure(), sigma_v=sigma_v, sigma_p=sigma_p)


def test_bad_noise_raises():
    with pytest.raises(ValueError, match="noise must have shape"):
        draw_fusion(fresh_figure(), sigma_v=1.5, sigma_p=1.5,
                    noise=np.zeros((DEFAULT.n_steps, 1)))


@pytest.mark.slow
def test_vision_only_run_is_correct_and_kept_while_only_sigma_p_moves():
    noise = DEFAULT.unit_noise(sensors=FUSED)
    np.testing.assert_allclose(vision_only(DEFAULT, 2.0, noise).positions,
                               _independent(2.0, 1.0, noise)["vision-only"],
                               rtol=1e-9, atol=1e-9)
    other = np.random.default_rng(1).standard_normal(noise.shape)
    np.testing.assert_allclose(vision_only(DEFAULT, 2.0, other).positions,
                               _independent(2.0, 1.0, other)["vision-only"],
                               rtol=1e-9, atol=1e-9)
    # The explorer keeps the vision-only run while σ_v stays: σ_p's moves reuse it.
    explorer = explore_fusion()
    kept = explorer.draw.keywords["vision_runs"]
    assert kept.computed == 1
    for sigma_p in (3.0, 4.5, 0.75):
        explorer.sliders["sigma_p"].value = sigma_p
    assert kept.computed == 1
    explorer.sliders["sigma_v"].value = 2.5
    assert kept.computed == 2
    assert not kept(2.5).positions.flags.writeable


def test_static_display_carries_the_picture_and_names_the_sliders():
    explorer = explore_fusion()
    bundle = explorer._repr_mimebundle_()
    assert bundle["text/plain"].startswith("Interactive explorer")
    for description in ("σ_v (cm)", "σ_p (cm)"):
        assert description in bundle["text/html"]
    assert explorer.png.startswith(b"\x89PNG")
    # A reader of the static page gets the trial's MSEs too, in the caption.
    assert explorer.numbers.startswith("σ_v = 1.5 cm, σ_p = 1.5 cm. MSE of this trial")
    assert html.escape(explorer.numbers) in bundle["text/html"]


@pytest.mark.parametrize(("field", "value"), [("sigma_v", 0.25), ("sigma_p", 7.0)])
def test_scenario_outside_the_slider_range_is_refused(field: str, value: float) -> None:
    """Not clipped into the range: the explorer would show another σ than asked for."""
    scenario = dataclasses.replace(DEFAULT, **{field: value})
    with pytest.raises(ValueError, match=rf"scenario\.{field} .*\[0\.5, 6\] cm, got {value:g}"):
        explore_fusion(scenario)


# ------------------------------------------------------------------------------------------
# The student's own filter drives the explorer (issue 15 §4)
# ------------------------------------------------------------------------------------------


def my_filter(y, A, C, Q, R, z0, P0):
    """A student's filter as notebook 01 asks for it: eq. (5) as a loop with an inverse."""
    return reference.student_lqe_filter(y, A, C, Q, R, z0, P0)


@pytest.mark.slow
def test_a_student_filter_draws_the_engines_picture_and_says_whose_it_is():
    explorer = explore_fusion(filter=my_filter)
    engine = explore_fusion()
    noise = EXPLORER_SCENARIO.unit_noise(sensors=FUSED)
    for sigma_v, sigma_p in ((1.5, 1.5), (2.0, 4.5), (4.5, 0.75)):
        for each in (explorer, engine):
            each.sliders["sigma_v"].value = sigma_v
            each.sliders["sigma_p"].value = sigma_p
        # The student's lines equal the independent computation to 1e-9 ...
        _check_figure(explorer.figure, explorer.numbers, sigma_v, sigma_p, noise,
                      whose="your my_filter")
        # ... and the engine's picture, line for line and bar for bar.
        ours, theirs = _lines(explorer.figure), _lines(engine.figure)
        for gid in LINE_GIDS:
            np.testing.assert_allclose(ours[gid], theirs[gid], rtol=1e-9, atol=1e-9,
                                       err_msg=gid)
        assert _weights(explorer.figure) == pytest.approx(_weights(engine.figure), rel=1e-12)
    assert explorer.numbers.endswith("Filter: your my_filter.")
    assert engine.numbers.endswith("Filter: the pack's engine.")
    assert explorer.title.endswith("(your my_filter)")


@pytest.mark.slow
def test_the_sliders_really_run_the_students_filter():
    calls = []

    def counted(y, A, C, Q, R, z0, P0):
        calls.append(y.shape)
        return my_filter(y, A, C, Q, R, z0, P0)

    explorer = explore_fusion(filter=counted)
    assert calls == [(DEFAULT.n_steps, 1), (DEFAULT.n_steps, 2)]
    explorer.sliders["sigma_p"].value = 3.0      # the kept vision-only run is reused
    assert calls[2:] == [(DEFAULT.n_steps, 2)]
    explorer.sliders["sigma_v"].value = 2.0
    assert calls[3:] == [(DEFAULT.n_steps, 1), (DEFAULT.n_steps, 2)]


def test_a_students_wrong_filter_shows_its_own_numbers():
    def no_update(y, A, C, Q, R, z0, P0):      # forgets to correct with the readings
        z, rows = np.array(z0, dtype=float), []
        for _ in y:
            z = A @ z
            rows.append(z)
        return np.array(rows)

    explorer = explore_fusion(filter=no_update)
    assert explorer.problem == ""
    assert np.all(_lines(explorer.figure)["fused"] == 0.0)
    assert explorer.numbers.endswith("Filter: your no_update.")


def test_a_broken_student_filter_is_one_line_and_the_next_move_tries_again():
    state = {"broken": True}

    def sometimes(y, A, C, Q, R, z0, P0):
        if state["broken"]:
            return y                              # shape (n, m): not the estimates
        return my_filter(y, A, C, Q, R, z0, P0)

    explorer = explore_fusion(filter=sometimes)
    assert explorer.problem.startswith("sometimes returned an array of shape (1000, 1), not of "
                                       "shape (1000, 3)")
    assert "\n" not in explorer.problem and explorer.numbers == explorer.problem
    assert explorer.png.startswith(b"\x89PNG")  # a picture, even after a failed first draw
    state["broken"] = False
    explorer.sliders["sigma_p"].value = 3.0
    assert explorer.problem == ""
    _check_figure(explorer.figure, explorer.numbers, 1.5, 3.0,
                  EXPLORER_SCENARIO.unit_noise(sensors=FUSED), whose="your sometimes")


def test_a_filter_that_raises_names_its_line():
    def raises(y, A, C, Q, R, z0, P0):
        return A @ y

    explorer = explore_fusion(filter=raises)
    assert explorer.problem.startswith("raises raised ValueError: matmul")
    assert "on the explorer's trial of vision" in explorer.problem


def test_a_filter_not_written_yet_says_so():
    def my_filter(y, A, C, Q, R, z0, P0):
        raise NotImplementedError("write the filter of eq. (5)")

    explorer = explore_fusion(filter=my_filter)
    assert explorer.problem == (
        "my_filter is not written yet: replace the line `raise NotImplementedError` with your "
        "code, run its cell, then run its check, then run the Explore cell again")
    with pytest.raises(StudentCodeError, match="my_filter is not written yet"):
        draw_fusion(fresh_figure(), sigma_v=1.5, sigma_p=1.5, filter=my_filter)


def test_a_hanging_filter_is_stopped(monkeypatch):
    monkeypatch.setattr(calling, "TIME_LIMIT", 0.3)

    def hangs(y, A, C, Q, R, z0, P0):
        while True:
            pass

    start = time.monotonic()
    explorer = explore_fusion(filter=hangs)
    assert time.monotonic() - start < 5
    assert explorer.problem.startswith("hangs did not return within 0.3 s")


@pytest.mark.parametrize("bad", ["my_filter", 3, np.eye(3)])
def test_filter_must_be_a_function(bad):
    with pytest.raises(ValueError, match=r"filter must be None .*or a function"):
        explore_fusion(filter=bad)
    with pytest.raises(ValueError, match=r"filter must be None .*or a function"):
        draw_fusion(fresh_figure(), sigma_v=1.5, sigma_p=1.5, filter=bad)
