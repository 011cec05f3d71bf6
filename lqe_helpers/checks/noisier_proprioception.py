"""Checks of notebook 04, question (d): proprioception three times noisier.

Its tasks use :func:`lqe_helpers.checks.fusion.check_fusion` (C and R) and, until they
get checks of their own here, the shared :func:`lqe_helpers.checks.numbers.check_paired_difference`.
"""

from __future__ import annotations

__tracebackhide__ = True  # pytest: leave the checks' frames out of a failure's traceback
