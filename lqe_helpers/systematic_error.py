"""A linear filter's systematic error: its outputs on noise-free readings, drawn (notebook 01).

A filter whose gains do not depend on the readings has an error that splits exactly into a
systematic part, the error of the same filter fed the true positions (the same in every
run), and a noise part. :class:`NoiseFreeOutputs` holds such noise-free outputs by σ_v and
draws them beside the truth (:meth:`NoiseFreeOutputs.figure`: a lag shows as a curve
shifted right); :func:`error_figure`, behind
:meth:`lqe_helpers.experiments.Tracking.error_figure`, draws one run's errors with the
filter's own ±2σ band and the systematic error. Both only hand their arrays to the
painters of :mod:`lqe_helpers.figures.vision` (imported when a figure is asked for).
:func:`lqe_helpers.own_runs.noise_free` wraps a student's own outputs in a
:class:`NoiseFreeOutputs`. Inputs are checked once, at :func:`error_figure` and
:func:`~lqe_helpers.own_runs.noise_free`, by :func:`positions_by_sigma`.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from . import experiments, validation
from .scenario import Scenario

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Style roles of :func:`error_figure`'s panels, one per σ_v, in the sweep's order.
PANEL_ROLES = ("estimate", "alternative", "reference")


def is_sigma_key(key: object) -> bool:
    """Whether ``key`` may stand for a σ_v in a mapping: a real number, not a bool or text."""
    return isinstance(key, numbers.Real) and not isinstance(key, bool)


def positions_by_sigma(name: str, values: object, n: int,
                       sigmas: Sequence[float] | None = None) -> dict[float, np.ndarray]:
    """``values``, a mapping σ_v (cm) → positions (cm) of shape (n,), checked.

    With ``sigmas`` (cm), the keys must be those σ_v (to 1e-9 cm), and the result is in
    their order; without, any σ_v > 0. The positions must be finite.

    Returns
    -------
    dict
        float σ_v (cm) → float array of shape (n,), a copy.

    Raises
    ------
    ValueError
        Naming ``name``, what it holds and what is allowed.
    """
    wanted = "σ_v > 0 (cm)" if sigmas is None else (
        "each σ_v of the run (" + ", ".join(f"{sigma:g}" for sigma in sigmas) + " cm)")
    keys = list(values) if isinstance(values, Mapping) else []
    numbers = [float(key) for key in keys if is_sigma_key(key)]
    if len(numbers) != len(keys):
        numbers = []
    if not numbers or not all(np.isfinite(numbers)) or min(numbers) <= 0 or (
            sigmas is not None and (len(numbers) != len(sigmas) or not all(
                np.any(np.isclose(numbers, sigma, rtol=0, atol=1e-9)) for sigma in sigmas))):
        got = f"keys {keys}" if isinstance(values, Mapping) else type(values).__name__
        raise ValueError(f"{name} must map {wanted} to positions (cm) of shape ({n},), got "
                         f"{got}")
    order = numbers if sigmas is None else [
        numbers[int(np.argmin(np.abs(np.subtract(numbers, sigma))))] for sigma in sigmas]
    checked = {}
    for number in order:
        key = keys[numbers.index(number)]
        array = validation.numeric_array(f"{name}[{key!r}]", values[key]).copy()
        if array.shape != (n,) or not np.all(np.isfinite(array)):
            raise ValueError(f"{name}[{key!r}] must be finite positions (cm) of shape ({n},), "
                             f"got shape {array.shape}"
                             + ("" if array.shape != (n,) else " with NaN or infinite values"))
        checked[number] = array
    return checked


@dataclass(frozen=True)
class NoiseFreeOutputs:
    """Filters' outputs on noise-free readings (the true positions), by σ_v.

    Attributes
    ----------
    scenario : Scenario
        The trial: times (s) and true path.
    outputs : dict
        σ_v (cm) → {legend label → (positions (cm), shape (n,); style role such as
        ``"estimate"`` or ``"alternative"``)}, in the order drawn.

    Built by :func:`lqe_helpers.own_runs.noise_free` from a student's arrays.
    """

    scenario: Scenario
    outputs: dict[float, dict[str, tuple[np.ndarray, str]]]

    def figure(self, window: tuple[float, float] = (4.1, 5.1)) -> Figure:
        """The outputs beside the true path over ``window`` (start, end, s), one panel per σ_v.

        Built by :func:`lqe_helpers.figures.lag_figure` (panels titled "σ_v = 1.5 cm", …).
        Raises ValueError if ``window`` is not inside the trial.
        """
        from . import figures

        panels = {f"σ_v = {sigma:g} cm": dict(curves) for sigma, curves in self.outputs.items()}
        return figures.lag_figure(self.scenario.times, self.scenario.truth[:, 0], panels,
                                  window=window)


def error_figure(tracking: experiments.Tracking, noise_free: Mapping[float, np.ndarray], *,
                 run: int | tuple[int, ...] | None = 0) -> Figure:
    """One run's error at each σ_v of a sweep, its own ±2σ band, and the systematic error.

    Parameters
    ----------
    tracking : Tracking
        Runs of vision alone over a sweep of σ_v (model R of shape (s, 1, 1), 1 ≤ s ≤ 3;
        positions (..., s, n)), e.g. ``experiments.track(DEFAULT, sigmas=[[1.5], [4.5]],
        runs=300)``.
    noise_free : mapping
        σ_v (cm) of each panel → the positions (cm), shape (n,), of the same filter fed
        noise-free readings; their error is the systematic error.
    run : int or tuple of int, optional
        Which run of the leading axes (default 0); None when there are none.

    Returns
    -------
    Figure
        :func:`lqe_helpers.figures.estimate_error_figure`: one panel per σ_v (the model's,
        in the sweep's order; roles :data:`PANEL_ROLES`), the burn-in shaded.

    Raises
    ------
    ValueError
        If ``tracking`` is not such a sweep, ``run`` does not pick one run, or
        ``noise_free`` does not map each σ_v of the sweep to finite positions of shape (n,).
    """
    validation.instance("tracking", tracking, experiments.Tracking, "e.g. experiments.track()")
    R = tracking.model.R
    count = R.shape[0] if R.ndim == 3 else 0
    if (tracking.sensors != ("vision",) or not 1 <= count <= len(PANEL_ROLES)
            or tracking.positions.shape[-2:-1] != (count,)):
        raise ValueError(
            f"tracking must be runs of vision alone over a sweep of 1 to {len(PANEL_ROLES)} "
            f"σ_v (R of shape (s, 1, 1), positions (..., s, n)), got sensors "
            f"{tracking.sensors}, R of shape {R.shape}, positions of shape "
            f"{tracking.positions.shape}")
    positions = validation.one_run(tracking.positions, run, trailing=2)
    variances = validation.one_run(tracking.position_variances, run, trailing=2)
    sigmas = np.sqrt(R[:, 0, 0])
    scenario = tracking.scenario
    noise_free = positions_by_sigma("noise_free", noise_free, scenario.n_steps, sigmas)
    truth = scenario.truth[:, 0]
    from . import figures

    panels = {f"σ_v = {sigma:g} cm": (positions[i] - truth, np.sqrt(variances[i]),
                                      noise_free[key] - truth, role)
              for i, (sigma, key, role) in enumerate(zip(sigmas, noise_free, PANEL_ROLES[:count],
                                                        strict=True))}
    return figures.estimate_error_figure(scenario.times, panels, skipped=scenario.burn_in)
