"""One drawing function per picture: the notebooks' and the explorers' trial (03, 04, 05).

A trial's signals over its errors are drawn by :func:`lqe_helpers.figures.common.trial_column`
only: the notebooks' figure (``tracking_comparison_figure``, ``fusion_trial_figure``,
``Tracking.figure``) calls it with data, the explorers of 03, 04 and 05 call it once with
no data and then refill its lines.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import pytest

from lqe_helpers import experiments
from lqe_helpers.explorers import delay, fusion, noisier_proprioception
from lqe_helpers.figures import common
from lqe_helpers.scenario import DEFAULT


@pytest.fixture
def painted(monkeypatch) -> list[dict]:
    """The ``lines`` of every call of ``trial_column``, wherever it is called from."""
    calls: list[dict] = []
    original = common.trial_column

    def recording(signals, errors, times, lines, *args, **kwargs):
        calls.append(dict(lines))
        return original(signals, errors, times, lines, *args, **kwargs)

    monkeypatch.setattr(common, "trial_column", recording)
    import lqe_helpers.explorers.common as explorer_common
    monkeypatch.setattr(explorer_common, "trial_column", recording)
    monkeypatch.setattr(delay, "trial_column", recording)
    return calls


def test_the_notebooks_trial_figure_is_painted_by_trial_column(painted) -> None:
    vision = experiments.track(DEFAULT)
    fused = experiments.track(DEFAULT, ("vision", "proprioception"))
    fig = fused.figure("fused", against={"vision only": vision})
    plt.close(fig)
    assert len(painted) == 1
    lines = painted[0]
    assert lines["truth"] == (0, "truth", "true position")
    assert lines["estimate: fused"] == (0, "estimate", "fused")
    assert lines["error: vision only"] == (1, "alternative", "vision only")


@pytest.mark.parametrize("factory", [fusion.explore_fusion,
                                     noisier_proprioception.explore_noisier_proprioception,
                                     delay.explore_delay])
def test_the_explorers_trial_is_painted_by_the_same_function(painted, factory) -> None:
    explorer = factory()
    assert len(painted) == 1
    drawn = {line.get_gid() for ax in explorer.figure.axes for line in ax.get_lines()}
    assert set(painted[0]) <= drawn
