"""A measured acceleration with a bias, used as a known input (Lesson 0.5, bonus notebook).

State ``z = [p, v, b]``: position (cm), velocity (cm/s) and the bias b (cm/s²) of an
acceleration signal ``a_r = a + b + noise``. The signal is not measured against the
state; it drives the prediction as an input, ``z_{j+1} = F z_j + G u_j`` (Lesson 0.5
eq. (4)), and vision, which reads the position, corrects what the input gets wrong.

In the nervous system the input could be an efference copy of the motor command or
the otoliths' linear acceleration signal, both of which can carry a slowly varying
offset; here the moving target is the hand of :data:`~lqe_helpers.scenario.DEFAULT`,
whose path is the tutorial's sinusoid.

Time convention (that of :func:`~lqe_helpers.filter.kalman_filter`): ``u_j`` is the
reading over the step that ends at sample j, from ``t_j − Δt`` to ``t_j``, and the
filter's ``z0`` is the estimate of the state at ``t = −Δt``.

Two modules, every name importable from here (``bias_model.track_with_input``):
:mod:`~lqe_helpers.bias_model.equations` (the matrices, the hand, the signal, dead
reckoning) and :mod:`~lqe_helpers.bias_model.tracking` (the filter's model and its runs).
"""

from .equations import (
    DEFAULT_BIAS,
    DEFAULT_SIGMA_A,
    NOISE_COLUMNS,
    acceleration_readings,
    bias_drift,
    dead_reckoning,
    dead_reckoning_spread,
    initial_state,
    input_matrix,
    process_noise_covariance,
    step_accelerations,
    transition_matrix,
    true_states,
    unit_noise,
)
from .tracking import (
    DEFAULT_BIAS_PRIOR_STD,
    InputTracking,
    UnbiasedRun,
    track_with_input,
    unbiased_run,
)

__all__ = [
    "DEFAULT_BIAS", "DEFAULT_BIAS_PRIOR_STD", "DEFAULT_SIGMA_A", "NOISE_COLUMNS",
    "InputTracking", "UnbiasedRun", "acceleration_readings", "bias_drift", "dead_reckoning",
    "dead_reckoning_spread", "initial_state", "input_matrix",
    "process_noise_covariance", "step_accelerations", "track_with_input", "transition_matrix",
    "true_states", "unbiased_run", "unit_noise",
]
