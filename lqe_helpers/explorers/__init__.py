"""The explorers: one module per notebook, on one framework.

Framework: :mod:`~lqe_helpers.explorers.base` (the :class:`Explorer`),
:mod:`~lqe_helpers.explorers.sliders`, :mod:`~lqe_helpers.explorers.panels` (panels
built once and refilled), :mod:`~lqe_helpers.explorers.layers` (repaint only what
changed), :mod:`~lqe_helpers.explorers.png` (the PNG writer),
:mod:`~lqe_helpers.explorers.cache` (what an explorer keeps between moves) and
:mod:`~lqe_helpers.explorers.common` (the trial layout notebooks 03 and 04 share).
Each notebook's module (``background``, ``vision``, ``initial_covariance``, ``fusion``,
``noisier_proprioception``, ``delay``, ``bias``) declares its sliders and its drawing:
a public ``draw_*`` that checks its inputs by name, the ``_draw`` the sliders call
(their range was checked when they were made) and an ``explore_*`` factory that draws
its fixed noise from the scenario's explorer seed.

``from lqe_helpers.explorers import Explorer, float_slider, log_slider`` is all a
notebook needs to build an explorer of its own.
"""

from .base import Explorer
from .sliders import float_slider, log_slider

__all__ = ["Explorer", "float_slider", "log_slider"]
