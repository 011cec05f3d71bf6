"""Instant feedback for the tasks of the notebooks: one ``check_…`` after each task.

A check that passes prints one line starting with "✓ " saying what was verified and to
what tolerance. A check that fails raises :class:`CheckFailed` (an ``AssertionError``, so
"Run All" stops at the wrong step) with one message that says what is wrong, and names
the likely cause, without giving the code; Jupyter shows it under the student's own cell
with no library source.

Function checks (:func:`check_filter`, :func:`check_compensation`, ...) call the student's
function through :func:`lqe_helpers.student_code.call` (copies of the inputs, a time
limit) on several small random models drawn from a fixed seed, so that a hard-coded answer
cannot pass, and compare with the pack's engine, computed before the student's code runs.
Number checks recompute what the task asks from the task's own inputs and draws and judge
the student's value with :func:`judging.judge` against a catalogue of likely mistakes.

One module per notebook, as in :mod:`lqe_helpers.explorers`; this package re-exports
every ``check_…`` and the tolerances:

- ``background`` (00; its Going further in ``background_further`` and
  ``background_jerk_choice``), ``vision`` (01, with ``filter_models``, ``vision_smoothers`` and
  ``vision_further`` for its Going further), ``initial_covariance`` (02, with
  ``initial_covariance_further``), ``fusion`` (03, with ``fusion_further``),
  ``noisier_proprioception`` (04, with ``noisier_proprioception_further`` and
  ``misjudged_noise``), ``delay`` (05, with
  ``compensation_cases``; its Going further in ``delay_sweep`` and ``delay_further``),
  ``bias`` (06; its Going further in ``bias_further``);
- ``machinery``: :class:`CheckFailed`, the tolerances, calling the student's code,
  validating what a student passes;
- ``judging``: :func:`judging.judge`, :func:`judging.judge_interval`,
  :func:`judging.judge_seconds` (a time read off a curve) and the usual mistakes of an
  MSE, a burn-in and a paired difference;
- ``shared_runs``: the engine's Monte Carlo runs that checks of several notebooks compare
  with, made once per kernel.
"""

from .background import (
    check_covariance_step,
    check_eyes_closed,
    check_jerk_stds,
    check_transition_matrix,
)
from .background_further import (
    check_one_step_error,
    check_uncertainty_growth,
    check_white_jerk,
)
from .background_jerk_choice import (
    check_jerk_from_readings,
    check_jerk_sweep,
    check_jerk_sweep_reading,
)
from .bias import check_bias_model, check_signal_worth
from .bias_further import (
    check_bias_and_vision,
    check_bias_precision,
    check_dead_reckoning,
    check_sigma_a_sweep,
)
from .delay import check_compensation, check_delay_difference, check_delay_signals
from .delay_further import check_late_eye, check_short_delays
from .delay_sweep import (
    check_compensation_regimes,
    check_delay_sweep,
    check_error_sources,
    check_prediction_theory,
)
from .fusion import check_fusion, check_fusion_difference, check_fusion_trial
from .fusion_further import (
    THEORY_RTOL,
    check_equivalent_sensor,
    check_gain_shares,
    check_halving,
    check_noise_free_fits,
    check_settled_filter,
    check_settled_variances,
)
from .initial_covariance import (
    check_convergence_times,
    check_initial_covariance,
    check_start_and_after,
    check_start_of_trial,
)
from .initial_covariance_further import (
    BOOTSTRAP_ATOL,
    check_convergence_intervals,
    check_first_gains,
    check_flight_scales,
    check_overconfidence,
    check_p0_sweep,
)
from .machinery import (
    FUNCTION_RTOL,
    INTERVAL_RTOL,
    MATRIX_RTOL,
    MSE_RTOL,
    SEED,
    TIME_ATOL,
    CheckFailed,
)
from .misjudged_noise import check_assumed_sweep, check_misjudged, check_misjudged_nis
from .noisier_proprioception import (
    check_noisier_difference,
    check_noisier_sense,
    check_noisier_trial,
)
from .noisier_proprioception_further import (
    check_noisier_theory,
    check_proprioception_sweep,
    check_sweep_reading,
)
from .vision import check_filter, check_vision_trial
from .vision_further import (
    check_nis,
    check_sampling_ratio,
    check_steady_state,
    check_systematic_error,
)
from .vision_smoothers import check_smoother, check_smoother_comparison

__all__ = [
    "BOOTSTRAP_ATOL",
    "FUNCTION_RTOL",
    "INTERVAL_RTOL",
    "MATRIX_RTOL",
    "MSE_RTOL",
    "SEED",
    "THEORY_RTOL",
    "TIME_ATOL",
    "CheckFailed",
    "check_assumed_sweep",
    "check_bias_and_vision",
    "check_bias_model",
    "check_bias_precision",
    "check_compensation",
    "check_compensation_regimes",
    "check_convergence_intervals",
    "check_convergence_times",
    "check_covariance_step",
    "check_dead_reckoning",
    "check_delay_difference",
    "check_delay_signals",
    "check_delay_sweep",
    "check_equivalent_sensor",
    "check_error_sources",
    "check_eyes_closed",
    "check_filter",
    "check_first_gains",
    "check_flight_scales",
    "check_fusion",
    "check_fusion_difference",
    "check_fusion_trial",
    "check_gain_shares",
    "check_halving",
    "check_initial_covariance",
    "check_jerk_from_readings",
    "check_jerk_stds",
    "check_jerk_sweep",
    "check_jerk_sweep_reading",
    "check_late_eye",
    "check_misjudged",
    "check_misjudged_nis",
    "check_nis",
    "check_noise_free_fits",
    "check_noisier_difference",
    "check_noisier_sense",
    "check_noisier_theory",
    "check_noisier_trial",
    "check_one_step_error",
    "check_overconfidence",
    "check_p0_sweep",
    "check_prediction_theory",
    "check_proprioception_sweep",
    "check_sampling_ratio",
    "check_settled_filter",
    "check_settled_variances",
    "check_short_delays",
    "check_sigma_a_sweep",
    "check_signal_worth",
    "check_smoother",
    "check_smoother_comparison",
    "check_start_and_after",
    "check_start_of_trial",
    "check_steady_state",
    "check_sweep_reading",
    "check_systematic_error",
    "check_transition_matrix",
    "check_uncertainty_growth",
    "check_vision_trial",
    "check_white_jerk",
]

from . import own_work

# Every check judges what its current task cell made (own_work.judged: a task cell that
# stopped with an error, ran the pack's answer or bypassed the student's my_filter).
for _name in [name for name in __all__ if name.startswith("check_")]:
    globals()[_name] = own_work.judged(globals()[_name])
del _name
