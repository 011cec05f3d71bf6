"""The scenario object: derived values and validation."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from lqe_helpers import model
from lqe_helpers.scenario import DEFAULT, Scenario, matched_jerk_std


def test_defaults_make_the_delay_a_whole_number_of_steps() -> None:
    assert DEFAULT.n_steps == 1000
    assert DEFAULT.delay_steps(DEFAULT.delay) == 10
    np.testing.assert_allclose(DEFAULT.times[:3], [0.0, 0.01, 0.02])
    assert DEFAULT.burn_in_steps == 100


def test_matched_jerk_std_equates_random_walk_and_sinusoid_spreads() -> None:
    sigma = matched_jerk_std(10.0, 0.5, 0.01)
    omega = np.pi
    quarter_period = 0.5
    # Random-walk spread of acceleration over a quarter period equals A ω².
    assert np.sqrt(sigma**2 * 0.01 * quarter_period) == pytest.approx(10.0 * omega**2)
    assert DEFAULT.process_jerk_std == pytest.approx(sigma)
    np.testing.assert_allclose(DEFAULT.Q, model.process_noise_covariance(0.01, sigma))
    assert replace(DEFAULT, jerk_std=5.0).process_jerk_std == 5.0


@pytest.mark.parametrize("period_fraction", [1 / 8, 1 / 2, 1.0])
def test_matched_jerk_std_over_another_time_scale(period_fraction: float) -> None:
    sigma = matched_jerk_std(10.0, 0.5, 0.01, period_fraction=period_fraction)
    time_scale = period_fraction / 0.5
    assert np.sqrt(sigma**2 * 0.01 * time_scale) == pytest.approx(10.0 * np.pi**2)
    # Twice the time scale, √2 less jerk noise.
    quarter = matched_jerk_std(10.0, 0.5, 0.01)
    assert sigma / quarter == pytest.approx(np.sqrt(0.25 / period_fraction))


def test_matched_jerk_std_rejects_a_time_scale_that_is_not_positive() -> None:
    with pytest.raises(ValueError, match=r"period_fraction must be .* > 0, got 0"):
        matched_jerk_std(10.0, 0.5, 0.01, period_fraction=0.0)


def test_truth_is_the_sinusoid() -> None:
    np.testing.assert_allclose(DEFAULT.truth[:, 0], 10 * np.sin(np.pi * DEFAULT.times))


def test_peak_speed_is_the_largest_speed_of_the_path() -> None:
    assert DEFAULT.peak_speed == pytest.approx(10.0 * np.pi)
    assert DEFAULT.peak_speed == pytest.approx(np.max(np.abs(DEFAULT.truth[:, 1])))
    assert replace(DEFAULT, amplitude=4.0, frequency=2.0).peak_speed == pytest.approx(16 * np.pi)


@pytest.mark.parametrize(
    "change",
    [{}, {"duration": 0.3, "burn_in": 0.1, "delay": 0.1}, {"duration": 30.0},
     {"dt": 0.001}, {"dt": 0.002, "duration": 0.7, "burn_in": 0.006, "delay": 0.014}],
)
def test_times_that_are_whole_steps_up_to_rounding_are_accepted(change: dict) -> None:
    scenario = replace(DEFAULT, **change)
    assert scenario.n_steps * scenario.dt == pytest.approx(scenario.duration)
    assert scenario.burn_in_steps * scenario.dt == pytest.approx(scenario.burn_in)
    assert scenario.delay_steps(scenario.delay) * scenario.dt == pytest.approx(scenario.delay)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"dt": 0.0}, "dt must be a finite number > 0 s, got 0.0"),
        ({"duration": 0.01}, "duration must be at least two time steps"),
        (
            {"duration": 10.005},
            r"duration must be a whole number of time steps dt = 0.01 s, got 10.005 s",
        ),
        ({"dt": 0.03}, "duration must be a whole number of time steps dt = 0.03 s, got 10.0 s"),
        (
            {"burn_in": 0.004},
            r"burn_in must be a whole number of time steps dt = 0.01 s, got 0.004 s \(0.4 steps\)",
        ),
        ({"burn_in": "long"}, "burn_in must be a number >= 0 s, got 'long'"),
        ({"frequency": 60.0}, "frequency must be below the Nyquist limit"),
        ({"delay": 0.105}, "delay must be a whole number of time steps dt = 0.01 s, got 0.105 s"),
        ({"delay": -0.1}, "delay must be a finite number >= 0 s, got -0.1"),
        ({"delay": 10.0}, r"delay must be shorter than the trial \(10.0 s\), got 10.0 s"),
        ({"sigma_v": -1.5}, "sigma_v must be a finite number > 0 cm, got -1.5"),
        ({"sigma_p": 0.0}, "sigma_p must be a finite number > 0 cm, got 0.0"),
        ({"p0_variance": 0.0}, "p0_variance must be a finite number > 0 cm²"),
        ({"jerk_std": -3.0}, "jerk_std must be a finite number > 0 cm/s³, got -3.0"),
        ({"z0": (0.0, 0.0)}, r"z0 must hold 3 numbers \[p, v, a\]"),
        ({"mc_runs": 1}, "mc_runs must be a whole number >= 2, got 1"),
        ({"seed": -1}, "seed must be a whole number >= 0, got -1"),
        ({"burn_in": 20.0}, "burn_in must be shorter than duration = 10.0 s, got 20.0"),
    ],
)
def test_bad_values_are_refused(change: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        Scenario(**change)


def test_unit_noise_refuses_unknown_sensors() -> None:
    with pytest.raises(ValueError, match="sensors must be distinct names"):
        DEFAULT.unit_noise(sensors=("touch",))


def test_matched_jerk_std_says_what_it_computes_not_question_3s_conclusion() -> None:
    """Issue 23 §5: the docstring ships to students before 00's Question 3 answers it."""
    doc = " ".join(matched_jerk_std.__doc__.split())
    assert "σ_j = A ω² / √(Δt T)" in doc
    for conclusion in ("modelling choice", "not physics", "optimum", "MSE", "order of magnitude"):
        assert conclusion not in doc, conclusion
