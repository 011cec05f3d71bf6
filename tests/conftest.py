"""Shared test configuration."""

from __future__ import annotations

import os

from hypothesis import settings

# CI must be reproducible: the same examples every run. Local runs keep exploring new
# examples (and remember failures in .hypothesis/).
settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("thorough", max_examples=2000)
_default_profile = "ci" if os.environ.get("CI") else "default"
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", _default_profile))
