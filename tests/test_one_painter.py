"""One drawing function per picture: explorers are drawn by painters in figures/ (issue 25).

Each explorer's picture is built by the painters its row of docs/architecture.md's pictures
table names (``draw_fusion``: ``fusion_panels``, ``trial_panels``, ``trial_column``), and
by no other; ``explorers/`` holds no matplotlib drawing call outside its framework, so a
second painter written there fails here. A notebook's figure drawn by a result's method
(``Tracking.error_figure``, ``NoiseFreeOutputs.figure``, …) is drawn by the one painter
its entry in the table names. A trial's signals over its errors is drawn by
:func:`lqe_helpers.figures.common.trial_column` only, for the notebooks' figure and for the
explorers of 01, 03, 04 and 05.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import re
from pathlib import Path

import matplotlib.pyplot as plt
import pytest

import lqe_helpers.figures as figures_package
from lqe_helpers import experiments
from lqe_helpers.scenario import DEFAULT

ROOT = Path(__file__).resolve().parent.parent
EXPLORERS = ROOT / "lqe_helpers" / "explorers"
#: The explorers' framework: it builds no picture (it caches, repaints and encodes one).
FRAMEWORK = {"__init__", "base", "cache", "layers", "panels", "png", "sliders",
             "student_functions"}
#: Matplotlib calls that draw or lay out a picture: a painter's job, in figures/.
DRAWING_CALLS = {"plot", "fill_between", "bar", "barh", "scatter", "errorbar", "imshow",
                 "axhline", "axvline", "axvspan", "axhspan", "annotate", "text", "legend",
                 "set_title", "set_xlabel", "set_ylabel", "set_xscale", "set_yscale",
                 "set_xticks", "set_yticks", "add_subplot", "subplots", "add_gridspec",
                 "subplots_adjust", "align_ylabels", "suptitle"}
FACTORIES = {
    "draw_background": ("background", "explore_background"),
    "draw_vision": ("vision", "explore_vision"),
    "draw_initial_covariance": ("initial_covariance", "explore_initial_covariance"),
    "draw_fusion": ("fusion", "explore_fusion"),
    "draw_noisier_proprioception": ("noisier_proprioception",
                                    "explore_noisier_proprioception"),
    "draw_delay": ("delay", "explore_delay"),
    "draw_bias": ("bias", "explore_bias"),
}


def painters_in_table() -> dict[str, set[str]]:
    """By explorer draw function, the painters its row of the pictures table names."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text[text.index("## Each picture and its one drawing function"):
                   text.index("## Where to change what")]
    rows = re.findall(r"^\| \d\d \|.*\| `(draw_\w+)`: ([^|]+) \|$", section, re.MULTILINE)
    return {drawer: set(re.findall(r"`(\w+)`", painters)) for drawer, painters in rows}


def figure_functions() -> dict[str, tuple[object, str]]:
    """Every painter of figures/ (a public function whose first parameter is the Figure or
    Axes it draws on), by name: (module, name)."""
    found = {}
    for info in pkgutil.iter_modules(figures_package.__path__):
        module = importlib.import_module(f"lqe_helpers.figures.{info.name}")
        for name, value in vars(module).items():
            if (inspect.isfunction(value) and not name.startswith("_")
                    and value.__module__ == module.__name__ and _draws_on(value)):
                found[name] = (module, name)
    return found


def _draws_on(function: object) -> bool:
    """True if ``function``'s first parameter is a matplotlib Figure or Axes."""
    parameters = list(inspect.signature(function).parameters.values())
    return bool(parameters) and str(parameters[0].annotation) in {"Figure", "Axes"}


@pytest.fixture
def painted(monkeypatch) -> list[tuple[str, dict | None]]:
    """(name, lines or None) of every call of a figures/ function, wherever called from."""
    import sys

    calls: list[tuple[str, dict | None]] = []
    for name, (module, attribute) in figure_functions().items():
        original = getattr(module, attribute)

        def recording(*args, __name=name, __original=original, **kwargs):
            lines = args[3] if __name == "trial_column" else None
            calls.append((__name, dict(lines) if lines is not None else None))
            return __original(*args, **kwargs)

        # Everywhere the function is bound by name: its module and every importer.
        for loaded in list(sys.modules.values()):
            if (getattr(loaded, "__name__", "").startswith("lqe_helpers")
                    and getattr(loaded, name, None) is original):
                monkeypatch.setattr(loaded, name, recording)
    return calls


def test_the_table_names_a_painter_for_every_explorer() -> None:
    table = painters_in_table()
    assert set(table) == set(FACTORIES)
    known = figure_functions()
    for drawer, painters in table.items():
        assert painters, f"{drawer}: no painter named"
        assert painters <= set(known), f"{drawer}: not a function of figures/: {painters}"


@pytest.mark.parametrize("drawer", sorted(FACTORIES))
def test_each_explorer_is_drawn_by_the_painters_its_row_names(painted, drawer) -> None:
    module, factory = FACTORIES[drawer]
    explorer = getattr(importlib.import_module(f"lqe_helpers.explorers.{module}"), factory)()
    assert {name for name, _ in painted} == painters_in_table()[drawer]
    # A slider move refills the artists: no painter runs again.
    before = len(painted)
    name, slider = next(iter(explorer.sliders.items()))
    slider.value = slider.max if not hasattr(slider, "base") else slider.base ** slider.max
    assert explorer.problem == "" and len(painted) == before, name


def test_the_notebooks_trial_figure_is_painted_by_trial_column(painted) -> None:
    vision = experiments.track(DEFAULT)
    fused = experiments.track(DEFAULT, ("vision", "proprioception"))
    fig = fused.figure("fused", against={"vision only": vision})
    plt.close(fig)
    trials = [lines for name, lines in painted if name == "trial_column"]
    assert len(trials) == 1
    assert trials[0]["truth"] == (0, "truth", "true position")
    assert trials[0]["estimate: fused"] == (0, "estimate", "fused")
    assert trials[0]["error: vision only"] == (1, "alternative", "vision only")


@pytest.mark.parametrize("drawer", ["draw_vision", "draw_fusion", "draw_noisier_proprioception",
                                    "draw_delay"])
def test_the_explorers_trial_is_painted_by_the_same_function(painted, drawer) -> None:
    module, factory = FACTORIES[drawer]
    explorer = getattr(importlib.import_module(f"lqe_helpers.explorers.{module}"), factory)()
    trials = [lines for name, lines in painted if name == "trial_column"]
    assert len(trials) == 1
    drawn = {line.get_gid() for ax in explorer.figure.axes for line in ax.get_lines()}
    assert set(trials[0]) <= drawn


def result_methods_in_table() -> dict[str, str]:
    """By ``Result.method`` the table names for a notebook's figure, the painter it names."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text[text.index("## Each picture and its one drawing function"):
                   text.index("## Where to change what")]
    rows = re.findall(r"^\| \d\d \|(.*)\| `draw_\w+`", section, re.MULTILINE)
    return dict(pair for row in rows
                for pair in re.findall(r"`(\w+\.\w+)` \(`(\w+)`", row))


def _draw_result_figure(method: str) -> plt.Figure:
    """The figure ``method`` (``Result.method``) draws of a small result of the pack."""
    from lqe_helpers import bias_model, jerk_tuning, own_runs
    from lqe_helpers.prediction import open_loop

    truth = DEFAULT.truth[:, 0]
    clean = {sigma: truth + 0.1 * sigma for sigma in (1.5, 4.5)}
    delayed = experiments.delay_and_compensate(experiments.track(DEFAULT), 0.1)
    run = experiments.track(DEFAULT)
    blind = open_loop(DEFAULT, run.result.estimates[200], run.result.estimate_covariances[200],
                      0.5)
    sweep = experiments.track(DEFAULT, p0_variance=[1.0, 1e5], runs=2)
    labels = ("P0 = diag(1)", "P0 = diag(1e5)")
    calls = {
        "Tracking.open_loop_figure": lambda: run.open_loop_figure(blind, 200,
                                                                  blind.position_stds),
        "Tracking.panels_figure": lambda: run.panels_figure({"same": run}, (2.0, 5.0)),
        "Tracking.gains_figure": lambda: sweep.gains_figure(labels),
        "Tracking.belief_figure": lambda: sweep.belief_figure(
            (sweep.positions - truth).mean(axis=0) ** 2, (0.3, 0.5), 0.1, labels),
        "InputTracking.signal_figure": lambda: bias_model.track_with_input(
            DEFAULT).signal_figure(),
        "InputTracking.settling_figure": lambda: bias_model.InputTracking.settling_figure(
            {20.0: bias_model.track_with_input(DEFAULT, runs=2)},
            {1.5: bias_model.track_with_input(DEFAULT, sigma_v=1.5, runs=2)}),
        "Tracking.figure": lambda: experiments.track(DEFAULT).figure(),
        "Tracking.error_figure": lambda: experiments.track(
            DEFAULT, sigmas=[[1.5], [4.5]], runs=2).error_figure(clean),
        "NoiseFreeOutputs.figure": lambda: own_runs.noise_free(
            clean, clean, {1.5: 0.1, 4.5: 0.05}).figure(),
        "DelayedTracking.figure": delayed.figure,
        "DelayedTracking.comparison_figure": delayed.comparison_figure,
        "InputTracking.learning_figure": lambda: bias_model.track_with_input(
            DEFAULT).learning_figure(bias_model.track_with_input(DEFAULT, runs=2)),
        "JerkChoice.figure": lambda: jerk_tuning.tune_jerk_std(
            DEFAULT, [300.0, 1000.0, 3000.0], runs=2).figure(
                {"likelihood": 1000.0, "NIS": 1000.0, "MSE": 1000.0}),
    }
    return calls[method]()


def test_the_table_names_the_result_methods_of_notebook_01s_figures() -> None:
    table = result_methods_in_table()
    assert table["Tracking.figure"] == "tracking_comparison_figure"
    assert table["NoiseFreeOutputs.figure"] == "lag_figure"
    assert table["Tracking.error_figure"] == "estimate_error_figure"


def test_the_table_names_the_result_methods_of_notebooks_00_02_and_06() -> None:
    """The given cells of 00, 02 and 06 that passed a result's arrays now call these."""
    table = result_methods_in_table()
    assert table["Tracking.open_loop_figure"] == "open_loop_figure"
    assert table["Tracking.panels_figure"] == "tracking_panels_figure"
    assert table["Tracking.gains_figure"] == "gains_figure"
    assert table["Tracking.belief_figure"] == "belief_and_error_figure"
    assert table["InputTracking.signal_figure"] == "acceleration_signal_figure"
    assert table["InputTracking.settling_figure"] == "bias_settling_figure"
    assert table["JerkChoice.figure"] == "jerk_choice_figure"


@pytest.mark.slow
@pytest.mark.parametrize("method", sorted(result_methods_in_table()))
def test_each_result_method_hands_its_data_to_the_painter_its_entry_names(
        monkeypatch, method) -> None:
    """A result draws itself through one painter of figures/, the one the table names."""
    called = []
    for name in figures_package.__all__:
        original = getattr(figures_package, name)

        def recording(*args, __name=name, __original=original, **kwargs):
            called.append(__name)
            return __original(*args, **kwargs)

        monkeypatch.setattr(figures_package, name, recording)
    fig = _draw_result_figure(method)
    plt.close(fig)
    assert called == [result_methods_in_table()[method]]


def drawing_calls(path: Path) -> list[str]:
    """``name:line`` of every matplotlib drawing call (``x.plot(...)``, …) in ``path``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [f"{node.func.attr}:{node.lineno}" for node in ast.walk(tree)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and node.func.attr in DRAWING_CALLS]


def test_explorers_hold_no_drawing_code_of_their_own() -> None:
    found = {path.stem: calls for path in sorted(EXPLORERS.glob("*.py"))
             if path.stem not in FRAMEWORK and (calls := drawing_calls(path))}
    assert found == {}, "draw these in a painter in figures/, the explorer refills it"


def test_a_second_painter_in_an_explorer_would_fail(tmp_path) -> None:
    source = (EXPLORERS / "vision.py").read_text(encoding="utf-8")
    second = tmp_path / "vision.py"
    second.write_text(source + "\n\ndef _again(ax):\n    ax.fill_between([0], [0], [1])\n",
                      encoding="utf-8")
    assert drawing_calls(EXPLORERS / "vision.py") == []
    assert [call.split(":")[0] for call in drawing_calls(second)] == ["fill_between"]
