"""The explorers' one caching pattern: LastResults keeps the last results, read-only."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lqe_helpers import experiments
from lqe_helpers.explorers.cache import LastResults, read_only
from lqe_helpers.scenario import DEFAULT


class Counted:
    """A computation that records each call and returns a fresh array."""

    def __init__(self) -> None:
        self.calls: list[tuple] = []

    def __call__(self, *key: float) -> np.ndarray:
        self.calls.append(key)
        return np.array(key, dtype=float) * 2


def test_a_key_asked_again_is_not_computed_again() -> None:
    compute = Counted()
    kept = LastResults(compute)
    first = kept(1.5, 2.0)
    assert kept(1.5, 2.0) is first
    assert kept(1.5 + 0.0, 2) is first  # keys compare with ==, as slider floats do
    np.testing.assert_array_equal(first, [3.0, 4.0])
    assert compute.calls == [(1.5, 2.0)]
    assert kept.computed == 1


def test_one_entry_by_default_so_going_back_pays_again() -> None:
    compute = Counted()
    kept = LastResults(compute)
    for key in (1.0, 2.0, 1.0, 1.0):
        kept(key)
    assert compute.calls == [(1.0,), (2.0,), (1.0,)]


def test_the_least_recently_asked_key_goes_first() -> None:
    compute = Counted()
    kept = LastResults(compute, size=2)
    for key in (1.0, 2.0, 1.0, 3.0, 1.0, 2.0):  # 3.0 pushes out 2.0, asked less recently
        kept(key)
    assert compute.calls == [(1.0,), (2.0,), (3.0,), (2.0,)]


def test_no_argument_keeps_one_result_for_good() -> None:
    run = LastResults(lambda: experiments.track(DEFAULT))
    assert run() is run() and run.computed == 1


def test_kept_results_are_read_only_all_the_way_down() -> None:
    kept = LastResults(lambda sigma: experiments.track(DEFAULT, sigmas=[sigma]))
    tracking = kept(2.0)
    arrays = [tracking.measurements, tracking.result.estimates, tracking.result.gains,
              tracking.result.covariances, tracking.result.estimate_covariances,
              tracking.model.R, tracking.model.P0]
    for array in arrays:
        assert not array.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        tracking.positions[0] = 0.0
    nested = read_only({"a": [np.zeros(2), (np.ones(3),)]})
    assert not nested["a"][0].flags.writeable and not nested["a"][1][0].flags.writeable


def test_two_explorers_never_share_a_result() -> None:
    first, second = LastResults(Counted()), LastResults(Counted())
    assert first(1.0) is not second(1.0)


@pytest.mark.parametrize("size", [0, -1, 1.5, True])
def test_size_must_be_a_whole_number_of_at_least_one(size) -> None:
    with pytest.raises(ValueError, match="size must be a whole number >= 1"):
        LastResults(Counted(), size=size)


def test_a_kept_run_is_the_run_computed_anew() -> None:
    """What an explorer keeps is what it would compute: the same values, bit for bit."""
    scenario = dataclasses.replace(DEFAULT, seed=DEFAULT.explorer_seed)
    noise = scenario.unit_noise(sensors=("vision",))
    kept = LastResults(lambda sigma: experiments.track(DEFAULT, sigmas=[sigma], noise=noise))
    kept(1.5)
    np.testing.assert_array_equal(kept(1.5).positions,
                                  experiments.track(DEFAULT, sigmas=[1.5], noise=noise).positions)
