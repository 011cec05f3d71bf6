"""Issue 19's attack on the API: overflow, huge and tiny values, odd types.

Each case failed before (an OverflowError, a LinAlgError, NaN or inf with only a
RuntimeWarning, or an error naming the wrong parameter) and is now one ValueError that
names the input, or a correct finite result.
"""

from __future__ import annotations

import numpy as np
import pytest

from lqe_helpers import (
    cue_combination,
    distributions,
    experiments,
    lowpass,
    metrics,
    model,
    prediction,
    simulation,
    validation,
)
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT, Scenario, matched_jerk_std
from lqe_helpers.steady_state import steady_state

VISION = np.array([[1.0, 0.0, 0.0]])
Y = np.random.default_rng(1).normal(size=(50, 1))


def run_filter(**changes):
    args = {"y": Y, "A": DEFAULT.A, "C": VISION, "Q": DEFAULT.Q, "R": [[2.25]],
            "z0": np.zeros(3), "P0": np.eye(3)} | changes
    return kalman_filter(**args)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        # Before: NaN estimates with "overflow encountered in dot" (issue 19: A*1e200).
        (lambda: run_filter(A=DEFAULT.A * 1e200),
         r"^the covariance P overflowed the float64 range \(reached inf or NaN\) at step 0: "
         r"A, Q, R, P0 are too large .* largest magnitudes are A 1e\+200"),
        (lambda: run_filter(C=VISION * 1e200),
         r"overflowed the float64 range .* C 1e\+200"),
        # Before: OverflowError "cannot convert float infinity to integer".
        (lambda: Scenario(duration=1e308),
         r"^duration must be at most 9e\+15 time steps dt = 0.01 s, got 1e\+308 s"),
        (lambda: Scenario(dt=1e-308), r"^duration must be at most 9e\+15 time steps"),
        (lambda: DEFAULT.delay_steps(1e308), r"^delay must be at most 9e\+15 time steps"),
        (lambda: prediction.open_loop(DEFAULT, np.zeros(3), np.eye(3), 1e308),
         r"^duration must be at most 9e\+15 time steps"),
        # Before: "P0 must be positive semidefinite" for open_loop's covariance.
        (lambda: prediction.open_loop(DEFAULT, np.zeros(3), -np.eye(3), 0.5),
         r"^covariance must be positive semidefinite"),
        (lambda: prediction.open_loop(DEFAULT, np.zeros(3), [[np.nan] * 3] * 3, 0.5),
         r"^covariance must contain only finite numbers"),
        # Before: numpy.linalg.LinAlgError "SVD did not converge".
        (lambda: steady_state(DEFAULT.A * 1e200, VISION, DEFAULT.Q, [[2.25]]),
         r"^the Riccati recursion has no finite fixed point .* largest magnitudes: A 1e\+200"),
        # Before: "max_doublings = 200 was too few", which no number of doublings cures.
        (lambda: steady_state(DEFAULT.A, VISION * 1e-300, DEFAULT.Q, [[2.25]]),
         r"^C and R must leave the readings some information"),
        # Before: NaN or inf returned.
        (lambda: prediction.predict_ahead(np.ones((20, 3)), DEFAULT.A * 1e200, 5),
         r"^the predictions overflowed the float64 range"),
        (lambda: prediction.propagate_covariance(np.eye(3), DEFAULT.A * 1e200, DEFAULT.Q, 5),
         r"^the covariance overflowed the float64 range .* A 1e\+200"),
        (lambda: simulation.simulate_model_states(np.random.default_rng(0), DEFAULT.A * 1e200,
                                                  DEFAULT.Q, np.zeros(3), np.eye(3), 20, 2),
         r"^the simulated states overflowed the float64 range"),
        (lambda: simulation.sinusoid_states(np.arange(3.0), 1e308, 0.5),
         r"^amplitude and frequency give an acceleration amplitude"),
        (lambda: simulation.measure(np.full(3, 1e308), np.ones((3, 1)), [1e308]),
         r"^the readings overflowed the float64 range"),
        (lambda: metrics.mse(np.full(5, 1e200), np.zeros(5)),
         r"^estimate and truth differ by more than the float64 range allows squaring"),
        (lambda: metrics.convergence_time(np.linspace(5, 1, 50), 1e308),
         r"^dt = 1e\+308 s times \d+ samples overflows"),
        (lambda: metrics.fit_sinusoid(np.arange(10.0), np.zeros(10), 1e308),
         r"^frequency = 1e\+308 Hz times the times"),
        (lambda: matched_jerk_std(1e308, 0.5, 0.01), r"^amplitude, frequency, dt and "
                                                     r"period_fraction give σ_j"),
        (lambda: lowpass.sinusoid_mse(
            lowpass.steady_lowpass(DEFAULT.A, VISION, DEFAULT.Q, [[1.0]], 0.01), 1e308, 0.5),
         r"^amplitude = 1e\+308 cm is too large"),
        (lambda: distributions.chi2_quantile(1e-308, 2), r"^probability must be in"),
        # Before: a dt of 1e308 was reported as "two time steps (inf s)".
        (lambda: Scenario(dt=1e308), r"^duration must be at least two time steps of dt = "
                                     r"1e\+308 s, got 10.0$"),
        # Before: the masked entry's hidden value was used as a number.
        (lambda: metrics.mean_ci95(np.ma.masked_array([1.0, 2.0, 1e9], mask=[0, 0, 1])),
         r"(?s)^samples must be a numeric array, .*: a masked array with masked entries"),
    ],
)
def test_attack_is_one_value_error_naming_the_input(call, message: str) -> None:
    with pytest.raises(ValueError, match=message) as error:
        call()
    assert type(error.value) is ValueError  # not LinAlgError, a subclass


def test_huge_and_tiny_values_give_correct_finite_results() -> None:
    # Before: the interval of samples near 1e200 was inf; weights of σ near 1e200 were
    # 0/0 = NaN and near 1e-300 inf/inf; numpy warned that Q ~ 1e200 is not PSD.
    samples = np.arange(10.0)
    scaled = metrics.mean_ci95(samples * 1e200)
    plain = metrics.mean_ci95(samples)
    np.testing.assert_allclose([scaled.mean, scaled.low, scaled.high],
                               np.array([plain.mean, plain.low, plain.high]) * 1e200,
                               rtol=1e-13)
    sigmas = np.array([1.5, 4.5])
    for scale in (1e200, 1e-300):
        np.testing.assert_allclose(cue_combination.reliability_weights(sigmas * scale),
                                   cue_combination.reliability_weights(sigmas), rtol=1e-14)
        np.testing.assert_allclose(cue_combination.combined_sigma(sigmas * scale),
                                   cue_combination.combined_sigma(sigmas) * scale, rtol=1e-14)
    states = simulation.simulate_model_states(np.random.default_rng(0), DEFAULT.A,
                                              DEFAULT.Q * 1e200, np.zeros(3), np.eye(3), 20, 2)
    assert np.all(np.isfinite(states))
    low, high = metrics.nis_band(2**70, 10)  # absurd but finite: a band, not a crash
    assert 0 < low < 2**70 < high


def test_default_draws_are_unchanged_by_the_overflow_guards() -> None:
    # check_valid="ignore" skips a check only: the draws are numpy's, bit for bit.
    ours = simulation.simulate_model_states(np.random.default_rng(3), DEFAULT.A, DEFAULT.Q,
                                            np.zeros(3), np.eye(3), 30, 4)
    rng = np.random.default_rng(3)
    first = rng.multivariate_normal(DEFAULT.A @ np.zeros(3), np.eye(3), size=4, method="eigh")
    kicks = rng.multivariate_normal(np.zeros(3), DEFAULT.Q, size=(4, 29), method="eigh")
    expected = [first]
    for j in range(29):
        expected.append(expected[-1] @ DEFAULT.A.T + kicks[:, j])
    np.testing.assert_array_equal(ours, np.stack(expected, axis=1))


CONTAINERS = {
    "np.matrix": lambda: np.matrix(np.eye(3)),
    "non-contiguous": lambda: np.eye(6)[::2, ::2],
    "float32": lambda: np.eye(3, dtype=np.float32),
    "object": lambda: np.eye(3).astype(object),
    "masked, nothing masked": lambda: np.ma.masked_array(np.eye(3), mask=np.zeros((3, 3), bool)),
    "negative zeros": lambda: np.where(np.eye(3) == 0, -0.0, 1.0),
    "nested lists": lambda: np.eye(3).tolist(),
}


@pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")  # np.matrix itself
@pytest.mark.parametrize("name", CONTAINERS)
def test_equivalent_containers_of_a_covariance_give_the_same_result(name: str) -> None:
    result = kalman_filter(Y, DEFAULT.A, VISION, DEFAULT.Q, [[2.25]], np.zeros(3),
                           CONTAINERS[name]())
    expected = kalman_filter(Y, DEFAULT.A, VISION, DEFAULT.Q, [[2.25]], np.zeros(3), np.eye(3))
    np.testing.assert_array_equal(result.estimates, expected.estimates)
    assert type(result.estimates) is np.ndarray


def test_validation_refuses_a_broadcast_view_too_large_to_compute_with() -> None:
    view = np.broadcast_to(np.ones(1), (10**9,))
    with pytest.raises(ValueError, match=r"^signal of shape \(1000000000,\) would need about "
                                         r"29.8 GiB"):
        validation.numeric_array("signal", view)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        # Before: NaN/inf matrices, OverflowError "(34, 'Numerical result out of range')",
        # or an error naming R when track was given σ = 1e200 cm.
        (lambda: model.transition_matrix(1e308), r"^dt = 1e\+308 s give numbers beyond"),
        (lambda: model.jerk_input_matrix(1e200), r"^dt = 1e\+200 s give numbers beyond"),
        (lambda: model.process_noise_covariance(0.01, 1e308),
         r"^jerk_std = 1e\+308 cm/s³ with dt = 0.01 s give numbers beyond"),
        (lambda: model.measurement_noise_covariance([1.5, 1e200]),
         r"^sigmas \(largest 1e\+200 cm, smallest 1.5 cm\) give numbers beyond"),
        (lambda: model.measurement_noise_covariance([1e-300]), r"^sigmas .* give numbers beyond"),
        (lambda: experiments.track(DEFAULT, sigmas=[1e200]), r"^sigmas .* give numbers beyond"),
        (lambda: model.diagonal_covariance(1.0, size=10**6), r"^size = 1000000 with variance "
                                                             r"of shape \(\) would need"),
    ],
)
def test_model_matrices_name_the_input_that_leaves_the_float_range(call, message) -> None:
    with pytest.raises(ValueError, match=message):
        call()
