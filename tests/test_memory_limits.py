"""Absurd sizes are refused before anything is allocated (issue 19 §2).

Each call below would need far more than validation.MEMORY_LIMIT_BYTES; it must raise a
ValueError naming the parameter and the estimate while tracemalloc (which sees numpy's
allocations) records no more than the inputs' own size (under 64 MiB here).
"""

from __future__ import annotations

import dataclasses
import time
import tracemalloc

import numpy as np
import pytest

from lqe_helpers import (
    experiments,
    lowpass,
    metrics,
    model,
    prediction,
    simulation,
    smoothing,
    validation,
)
from lqe_helpers.filter import kalman_filter
from lqe_helpers.scenario import DEFAULT, Scenario
from lqe_helpers.steady_state import steady_state

VISION = np.array([[1.0, 0.0, 0.0]])
rng = np.random.default_rng


def huge(*shape: int, value: float = 1.0) -> np.ndarray:
    """A read-only view of the given shape that holds one number (costs nothing)."""
    return np.broadcast_to(np.full((1,) * len(shape), value), shape)


# Arguments made once here, outside the traced window of the test.
ZEROS_RUNS = np.zeros((300, 1, 1000))
NOISE_RUNS = np.zeros((300, 1, 1000, 1))
LOWPASS = lowpass.steady_lowpass(DEFAULT.A, VISION, DEFAULT.Q, [[1.0]], 0.01)


CASES = {
    "track runs": (lambda: experiments.track(DEFAULT, runs=10**7),
                   r"^runs = 10000000 would need about 298 GiB"),
    "scenario unit noise": (lambda: DEFAULT.unit_noise(10**7),
                            r"^runs = 10000000 would need about 298 GiB"),
    "scenario duration": (lambda: Scenario(duration=1e7),
                          r"^duration = 10000000.0 s \(1000000000 steps of dt = 0.01 s\) would "
                          r"need about 477 GiB"),
    "unit noise": (lambda: simulation.unit_noise(rng(0), 10**9, 2, runs=10),
                   r"^runs = 10, n_steps = 1000000000, n_sensors = 2 would need about 298 GiB"),
    "model states": (lambda: simulation.simulate_model_states(
        rng(0), DEFAULT.A, DEFAULT.Q, np.zeros(3), np.eye(3), 10**9, 1),
        r"^runs = 1 and n_steps = 1000000000 would need about 67.1 GiB"),
    "sinusoid states": (lambda: simulation.sinusoid_states(huge(10**9), 1.0, 1.0),
                        r"^times of shape \(1000000000,\) would need about 29.8 GiB as float64 "
                        r"numbers and their temporaries"),
    "measure sweep": (lambda: simulation.measure(DEFAULT.truth[:, 0], NOISE_RUNS,
                                                 huge(10**6, 1)),
                      r"^positions of shape \(1000,\), noise of shape \(300, 1, 1000, 1\) and "
                      r"sigmas of shape \(1000000, 1\) would need about 4.47e\+03 GiB"),
    "filter sigma rows": (lambda: kalman_filter(np.zeros((1000, 1)), DEFAULT.A, VISION,
                                                DEFAULT.Q, huge(10**6, 1, 1, value=2.25),
                                                np.zeros(3), np.eye(3)),
                          r"^y of shape \(1000, 1\), R of shape \(1000000, 1, 1\), z0 of shape "
                          r"\(3,\) and P0 of shape \(3, 3\) would need about 5\d\d GiB"),
    "filter horizon": (lambda: kalman_filter(huge(10**9, 1), DEFAULT.A, VISION, DEFAULT.Q,
                                             [[1.0]], np.zeros(3), np.eye(3)),
                       r"^y of shape \(1000000000, 1\) would need about 29.8 GiB as float64"),
    "steady state sweep": (lambda: steady_state(DEFAULT.A, VISION, DEFAULT.Q,
                                                huge(10**8, 1, 1)),
                           r"^R of shape \(100000000, 1, 1\) would need about 2.98 GiB"),
    "propagate": (lambda: prediction.propagate_covariance(np.eye(3), DEFAULT.A, DEFAULT.Q,
                                                          10**9),
                  r"^steps \(1000000000 steps\) with a start of shape \(3, 3\) would need "
                  r"about 67.1 GiB"),
    "open loop": (lambda: prediction.open_loop(DEFAULT, np.zeros(3), np.eye(3), 1e7),
                  r"^duration = 10000000.0 s \(1000000000 steps of 0.01 s\) would need about "
                  r"96.9 GiB"),
    "predict ahead": (lambda: prediction.predict_ahead(huge(10**6, 1000, 3), DEFAULT.A, 1),
                      r"^estimates of shape \(1000000, 1000, 3\) would need about 89.4 GiB "
                      r"as float64"),
    "delay": (lambda: simulation.delay_signal(huge(10**6, 1000, 1), 1),
              r"^signal of shape \(1000000, 1000, 1\) would need about 29.8 GiB as float64"),
    "bootstrap": (lambda: metrics.convergence_time_ci95(np.ones((300, 100)), 0.01, rng(0),
                                                        resamples=10**8),
                  r"^resamples = 100000000 with squared_errors of shape \(300, 100\) would "
                  r"need about 596 GiB"),
    "smoother grid": (lambda: smoothing.exponential_smoother(ZEROS_RUNS,
                                                             huge(10**5, value=0.5)),
                      r"^y of shape \(300, 1, 1000\) and alpha of shape \(100000,\) would need "
                      r"about 447 GiB"),
    "moving average grid": (lambda: smoothing.moving_average(ZEROS_RUNS,
                                                             huge(10**5).astype(int)),
                            r"^y of shape \(300, 1, 1000\) and window of shape \(100000,\) "
                            r"would need about 894 GiB"),
    "frequency grid": (lambda: lowpass.position_response(LOWPASS, huge(10**8, value=0.5)),
        r"^frequency of shape \(100000000,\) would need about 2.98 GiB as float64"),
    "diagonal covariance": (lambda: model.diagonal_covariance(1.0, size=10**6),
                            r"^size = 1000000 with variance of shape \(\) would need about "
                            r"1.49e\+04 GiB"),
}


@pytest.mark.parametrize("name", CASES)
def test_absurd_sizes_are_refused_before_allocation(name: str) -> None:
    call, message = CASES[name]
    tracemalloc.start()
    try:
        with pytest.raises(ValueError, match=message) as error:
            call()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert "more than the limit of 2 GiB (validation.MEMORY_LIMIT_BYTES)" in str(error.value)
    # Checking the inputs may make temporaries of their own size (30 MiB for a million
    # R matrices), never anything of the size refused.
    assert peak < 64 * 2**20, f"{peak / 2**20:.1f} MiB allocated before the refusal"


@pytest.mark.slow
def test_the_packs_largest_call_fits_under_the_limit() -> None:
    # Notebook 04's sweep: 25 σ_p values over 300 runs of 1 000 samples, two senses.
    sigma_p = np.geomspace(0.3, 100, 25)
    sweep = np.stack([np.full_like(sigma_p, 1.5), sigma_p], axis=-1)
    tracemalloc.start()
    try:
        tracking = experiments.track(DEFAULT, ("vision", "proprioception"), sigmas=sweep,
                                     runs=DEFAULT.mc_runs)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert tracking.positions.shape == (300, 25, 1000)
    assert peak < validation.MEMORY_LIMIT_BYTES / 2


def test_a_scenario_one_hour_long_is_still_allowed() -> None:
    scenario = dataclasses.replace(DEFAULT, duration=3600.0)
    assert scenario.n_steps == 360_000


# ------------------------------------------------------------------------------------------
# Issue 27: sizes that used to be accepted (a run of days) or failed with numpy's MemoryError
# ------------------------------------------------------------------------------------------


def test_a_grid_of_sigma_j_beyond_its_limit_is_refused_at_once() -> None:
    from lqe_helpers import jerk_tuning

    grid = np.linspace(1, 2000, 10**7)
    start = time.monotonic()
    with pytest.raises(ValueError, match=r"^jerk_stds must hold at most 200 values "
                                         r"\(jerk_tuning.MAX_GRID_SIZE: .*\), got 10000000 "
                                         r"values$"):
        jerk_tuning.tune_jerk_std(DEFAULT, grid)
    assert time.monotonic() - start < 0.5
    assert jerk_tuning.MAX_GRID_SIZE == 200


def _refused_before_allocation(call, message: str) -> None:
    tracemalloc.start()
    try:
        with pytest.raises(ValueError, match=message):
            call()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 64 * 1024**2


def test_r_sized_from_the_number_of_sigmas_is_refused_before_it_is_made() -> None:
    sigmas = np.ones(10**5)
    _refused_before_allocation(
        lambda: model.measurement_noise_covariance(sigmas),
        r"^sigmas of shape \(100000,\) would need about 74.5 GiB for R, one row and column per "
        r"sensor, more than the limit of 2 GiB")


def test_the_kronecker_products_of_a_large_filter_are_refused_before_they_are_made() -> None:
    k = 100    # k⁴ = 10⁸ numbers per product
    large = lowpass.steady_lowpass(0.5 * np.eye(k), np.eye(1, k), np.eye(k), [[1.0]], 0.01)
    _refused_before_allocation(
        lambda: lowpass.noise_variance(large),
        r"^a filter of k = 100 states with a batch of shape \(\) would need about 2.24 GiB for "
        r"its Kronecker products")
