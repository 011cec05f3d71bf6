"""Figures shown with a description: the bundle every reader gets, and its determinism."""

from __future__ import annotations

import base64
import html

import matplotlib
import pytest

from lqe_helpers import plotting

matplotlib.use("Agg")
import matplotlib.pyplot as plt

DESCRIPTION = 'Position against time, 0–10 s: true path & "noisy" vision <σ_v = 1.5 cm>'


def small_figure():
    figure, axes = plt.subplots(figsize=(2, 1.5))
    axes.plot([0, 1, 2], [0, 1, 0], **plotting.style("estimate"))
    return figure


def test_bundle_carries_the_description_in_every_form():
    figure = small_figure()
    try:
        png = plotting.figure_png(figure)
        data, metadata = plotting.figure_bundle(figure, f"  {DESCRIPTION}\n")
    finally:
        plt.close(figure)
    assert set(data) == {"text/html", "image/png", "text/plain"}
    assert base64.b64decode(data["image/png"]) == png
    assert png.startswith(b"\x89PNG")
    assert data["text/plain"] == DESCRIPTION
    assert metadata == {"image/png": {"alt": DESCRIPTION}}
    # JupyterLab shows the text/html form: the same PNG, with the description as alt.
    assert data["text/html"] == (f'<img src="data:image/png;base64,{data["image/png"]}" '
                                 f'alt="{html.escape(DESCRIPTION)}">')
    assert "&quot;noisy&quot;" in data["text/html"] and "&lt;σ_v" in data["text/html"]


def test_bundle_is_identical_when_drawn_again():
    # nbval compares text/html, so the embedded PNG must not change between runs.
    bundles = []
    for _ in range(2):
        figure = small_figure()
        bundles.append(plotting.figure_bundle(figure, DESCRIPTION))
        plt.close(figure)
    assert bundles[0] == bundles[1]


@pytest.mark.parametrize("description", ["", "   \n", None, 3])
def test_a_missing_description_is_refused(description):
    figure = small_figure()
    try:
        with pytest.raises(ValueError, match=r"description must be a non-empty sentence, got"):
            plotting.figure_bundle(figure, description)
        with pytest.raises(ValueError, match="description"):
            plotting.show_figure(figure, description)
        assert plt.fignum_exists(figure.number)  # left open: nothing was shown
    finally:
        plt.close(figure)


def test_show_figure_displays_the_bundle_and_closes_the_figure(monkeypatch):
    shown = []
    monkeypatch.setattr("IPython.display.display",
                        lambda data, **kwargs: shown.append((data, kwargs)))
    figure = small_figure()
    expected = plotting.figure_bundle(figure, DESCRIPTION)
    plotting.show_figure(figure, DESCRIPTION)
    assert not plt.fignum_exists(figure.number)
    [(data, kwargs)] = shown
    assert (data, kwargs["metadata"]) == expected
    assert kwargs["raw"] is True
