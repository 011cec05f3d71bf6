"""Figures the notebooks draw: one module per notebook, one for what several share.

Each function takes arrays (positions in cm, times in s, MSEs in cm²) and returns a
matplotlib Figure in the pack's Okabe–Ito roles (:func:`lqe_helpers.plotting.style`);
a notebook shows it with :func:`lqe_helpers.plotting.show_figure`. Every figure is
importable from here (``figures.delay_figure(...)``) and lives in the module of its
notebook, mirroring :mod:`lqe_helpers.explorers`: ``background`` (00), ``vision`` (01),
``initial_covariance`` (02), ``fusion`` (03), ``noisier_proprioception`` (04),
``delay`` (05), ``bias`` (06); ``common`` holds the figures and pieces several share.
Each module also holds the painter of its notebook's explorer (``vision_panel``,
``fusion_panels``, …, taking the Figure to draw on): it builds the explorer's artists once,
with no data, and :mod:`lqe_helpers.explorers` refills them on every slider move.
Nothing runs on import.
"""

from .background import (
    jerk_choice_figure,
    jerk_sweep_figure,
    mse_intervals_figure,
    open_loop_figure,
    tracking_panels_figure,
    uncertainty_growth_figure,
)
from .bias import (
    acceleration_signal_figure,
    bias_learning_figure,
    bias_settling_figure,
    drift_figure,
    noise_sweep_figure,
)
from .common import paired_mse_figure, tracking_comparison_figure
from .delay import (
    delay_figure,
    delay_sweep_figure,
    late_eye_figure,
    prediction_error_sources_figure,
)
from .fusion import frequency_response_figure
from .initial_covariance import (
    belief_and_error_figure,
    gains_figure,
    p0_sweep_figure,
    squared_error_figure,
    start_up_figure,
)
from .noisier_proprioception import assumed_noise_figure, proprioception_sweep_figure
from .vision import estimate_error_figure, lag_figure

__all__ = [
    "acceleration_signal_figure",
    "assumed_noise_figure",
    "belief_and_error_figure",
    "bias_learning_figure",
    "bias_settling_figure",
    "delay_figure",
    "delay_sweep_figure",
    "drift_figure",
    "estimate_error_figure",
    "frequency_response_figure",
    "gains_figure",
    "jerk_choice_figure",
    "jerk_sweep_figure",
    "lag_figure",
    "late_eye_figure",
    "mse_intervals_figure",
    "noise_sweep_figure",
    "open_loop_figure",
    "p0_sweep_figure",
    "paired_mse_figure",
    "prediction_error_sources_figure",
    "proprioception_sweep_figure",
    "squared_error_figure",
    "start_up_figure",
    "tracking_comparison_figure",
    "tracking_panels_figure",
    "uncertainty_growth_figure",
]
