"""A slider's value is checked once on its way to the filter: at the public entry it enters.

A slider checks its range when it is made; a move then calls the explorer's drawing,
which passes the value to the experiment's public entry (``experiments.track``,
``bias_model.unbiased_run``), which checks it and builds the filter's model without
checking it again (``lqe_helpers._matrices``). What is counted: every check in
``lqe_helpers.validation`` of a parameter that carries the slider's value (or its
square), made by the pack's own layers during the move. The engine's own public
functions (``simulation.measure``, ``kalman_filter``, ``steady_state``) check their
inputs too, as any caller's entry; they are not counted.
"""

from __future__ import annotations

import functools
import inspect

import numpy as np
import pytest

from lqe_helpers import validation
from lqe_helpers.explorers import bias, fusion, initial_covariance, noisier_proprioception, vision

#: Parameter names a slider's value travels under on its way to the filter.
CARRIERS = {"sigma_v", "sigma_p", "sigmas", "assumed_sigmas", "p0_variance", "variance", "R",
            "P0"}
#: Modules of the engine, whose public functions check their own inputs.
ENGINE = {"lqe_helpers.simulation", "lqe_helpers.filter", "lqe_helpers.steady_state"}
CHECKS = ("positive", "non_negative", "finite_number", "finite_array", "positive_array",
          "numeric_array", "covariance", "shaped_array")


def _holds(value: object, target: float) -> bool:
    """True if ``value`` holds ``target`` or its square (R and P0 carry variances)."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return bool(np.any(np.isclose(array, target, rtol=1e-12, atol=0)
                       | np.isclose(array, target**2, rtol=1e-12, atol=0)))


@pytest.fixture
def checks_of(monkeypatch):
    """checks_of(target) → the (module, function) of every outermost check of ``target``."""
    found: list[tuple[str, str, str]] = []
    state = {"depth": 0, "target": None}

    def watch(name: str):
        original = getattr(validation, name)

        @functools.wraps(original)
        def watched(parameter, value, *args, **kwargs):
            if (state["depth"] == 0 and state["target"] is not None and parameter in CARRIERS
                    and _holds(value, state["target"])):
                caller = inspect.currentframe().f_back
                found.append((caller.f_globals["__name__"], caller.f_code.co_name, parameter))
            state["depth"] += 1
            try:
                return original(parameter, value, *args, **kwargs)
            finally:
                state["depth"] -= 1
        return watched

    for name in CHECKS:
        monkeypatch.setattr(validation, name, watch(name))

    def start(target: float) -> list[tuple[str, str, str]]:
        found.clear()
        state["target"] = target
        return found
    return start


@pytest.mark.parametrize(("module", "factory", "slider", "value", "filters"), [
    (vision, "explore_vision", "sigma_v", 2.3, 1),
    (initial_covariance, "explore_initial_covariance", "p0_variance", 10**1.25, 1),
    (fusion, "explore_fusion", "sigma_v", 2.25, 2),       # the vision-only and the fused run
    (fusion, "explore_fusion", "sigma_p", 2.75, 1),       # the vision-only run is kept
    (noisier_proprioception, "explore_noisier_proprioception", "sigma_p", 7.5, 1),
    (bias, "explore_bias", "sigma_v", 3.5, 2),            # with the signal, and vision only
], ids=["vision σ_v", "P0", "fusion σ_v", "fusion σ_p", "noisier σ_p", "bias σ_v"])
@pytest.mark.slow
def test_a_slider_value_is_checked_once_per_filter_it_reaches(checks_of, module, factory,
                                                             slider, value, filters) -> None:
    explorer = getattr(module, factory)()
    found = checks_of(value)
    explorer.sliders[slider].value = value
    assert len(found) == filters, found
    assert {check[1] for check in found} <= {"_sensor_sigmas", "track", "_checked"}, found


def test_the_count_sees_a_check_made_twice(checks_of) -> None:
    """The counter is not blind: a public draw function checks σ_v, and so does track."""
    from matplotlib.figure import Figure

    found = checks_of(2.3)
    vision.draw_vision(Figure(), sigma_v=2.3)
    ours = [check for check in found if check[0] not in ENGINE]
    assert [check[1] for check in ours] == ["draw_vision", "_sensor_sigmas"]


def test_bad_input_still_meets_the_check_at_each_public_entry() -> None:
    """Checking once does not mean checking never: every public way in still refuses."""
    import dataclasses

    from lqe_helpers import experiments, simulation
    from lqe_helpers.filter import kalman_filter
    from lqe_helpers.scenario import DEFAULT
    from lqe_helpers.steady_state import steady_state

    model = experiments.filter_model(DEFAULT)
    bad_r = np.array([[-1.0]])
    by_hand = dataclasses.replace(model, R=bad_r)        # not built by filter_model
    y = np.zeros((DEFAULT.n_steps, 1))
    for call in (lambda: by_hand.steady_state(), lambda: by_hand.filter(y),
                 lambda: model.filter(np.full((DEFAULT.n_steps, 1), np.nan)),
                 lambda: kalman_filter(y, model.A, model.C, model.Q, bad_r, model.z0,
                                       model.P0),
                 lambda: steady_state(model.A, model.C, model.Q, bad_r)):
        with pytest.raises(ValueError, match=r"^(R|y) must"):
            call()
    with pytest.raises(ValueError, match=r"sigmas must all be > 0 cm, got \[-1\.5\]"):
        simulation.measure(DEFAULT.truth[:, 0], y, [-1.5])
    with pytest.raises(ValueError, match=r"^sigmas .*-1\.5"):
        experiments.track(DEFAULT, sigmas=[-1.5])
    with pytest.raises(ValueError, match=r"^sigma_v .*-1\.5"):
        vision.draw_vision(None, sigma_v=-1.5)


def test_a_model_built_by_filter_model_skips_only_the_second_check() -> None:
    """Its steady state from the core equals the checked entry's, to the bit."""
    from lqe_helpers import experiments
    from lqe_helpers.scenario import DEFAULT
    from lqe_helpers.steady_state import steady_state

    model = experiments.filter_model(DEFAULT, ("vision", "proprioception"), [1.5, 4.5])
    fast, checked = model.steady_state(), steady_state(model.A, model.C, model.Q, model.R)
    for name in ("covariance", "gain", "estimate_covariance"):
        np.testing.assert_array_equal(getattr(fast, name), getattr(checked, name))
