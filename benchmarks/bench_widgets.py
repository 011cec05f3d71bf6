"""How long a slider move takes: value set → new figure rendered, for every explorer.

Run: ``.venv/bin/python benchmarks/bench_widgets.py`` (or ``make bench``).

For each explorer and each of its sliders, the slider is moved back and forth between
two valid values and the time from setting ``.value`` to the PNG being ready is
recorded (the redraw runs synchronously in the slider's observer). The peer, run in
the same process, is the cost of rendering a plain matplotlib figure of the same size
with a 1 000-point line: the floor any redraw pays. Target: median <= 100 ms.
"""

from __future__ import annotations

import importlib
import io
import statistics
import time

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

#: (notebook, module, factory) of every explorer in the pack.
EXPLORERS = [
    ("00 background", "lqe_helpers.explorers.background", "explore_background"),
    ("01 vision only", "lqe_helpers.explorers.vision", "explore_vision"),
    ("02 initial covariance", "lqe_helpers.explorers.initial_covariance",
     "explore_initial_covariance"),
    ("03 fusion", "lqe_helpers.explorers.fusion", "explore_fusion"),
    ("04 noisier proprioception", "lqe_helpers.explorers.noisier_proprioception",
     "explore_noisier_proprioception"),
    ("05 sensory delay", "lqe_helpers.explorers.delay", "explore_delay"),
    ("06 bias and input", "lqe_helpers.explorers.bias", "explore_bias"),
]
MOVES = 10
TARGET_MS = 100.0


def peer_render_ms(figsize: tuple[float, float], dpi: int, repeats: int = 10) -> float:
    """Median time (ms) to draw and render a plain 1 000-point line figure."""
    t = np.linspace(0.0, 10.0, 1000)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        figure = Figure(figsize=figsize, dpi=dpi)
        FigureCanvasAgg(figure)
        ax = figure.add_subplot()
        ax.plot(t, np.sin(t))
        ax.set_xlabel("time (s)")
        figure.savefig(io.BytesIO(), format="png", dpi=dpi)
        times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


def other_value(slider) -> float:
    """A valid value of ``slider``, a quarter (or three quarters) along its range."""
    logarithmic = hasattr(slider, "base")  # FloatLogSlider: min, max, step are exponents
    current = np.log(slider.value) / np.log(slider.base) if logarithmic else slider.value
    target = slider.min + 0.25 * (slider.max - slider.min)
    if abs(target - current) < slider.step:
        target = slider.min + 0.75 * (slider.max - slider.min)
    target = slider.min + slider.step * round((target - slider.min) / slider.step)
    return float(slider.base**target) if logarithmic else float(target)


def time_slider_moves(explorer, name: str) -> list[float]:
    """Times (ms) of MOVES value changes of one slider, restoring it afterwards."""
    slider = explorer.sliders[name]
    original = slider.value
    values = [other_value(slider), original]
    times = []
    for i in range(MOVES):
        start = time.perf_counter()
        slider.value = values[i % 2]
        times.append(1e3 * (time.perf_counter() - start))
    slider.value = original
    return times


def main() -> None:
    print(f"Explorer redraw: slider value set -> PNG ready, median of {MOVES} moves "
          f"(target <= {TARGET_MS:.0f} ms)")
    worst = 0.0
    for notebook, module_name, factory in EXPLORERS:
        explorer = getattr(importlib.import_module(module_name), factory)()
        size = tuple(explorer.figure.get_size_inches())
        peer = peer_render_ms(size, explorer.dpi)
        for name in explorer.sliders:
            median = statistics.median(time_slider_moves(explorer, name))
            worst = max(worst, median)
            verdict = "ok" if median <= TARGET_MS else "SLOW"
            print(f"  {notebook:27s} {name:14s} {median:6.1f} ms  "
                  f"({median / peer:4.1f}x a plain {size[0]:.0f}x{size[1]:.0f} in figure, "
                  f"{peer:.1f} ms)  {verdict}")
    print(f"slowest median: {worst:.1f} ms")


if __name__ == "__main__":
    main()
