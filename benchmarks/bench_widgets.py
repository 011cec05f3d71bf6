"""How long a slider move takes: value set → new picture ready to send, for every explorer.

Run: ``.venv/bin/python benchmarks/bench_widgets.py`` (or ``make bench``); with
``--encoders``, it also compares the pack's PNG writer with Pillow's on every
explorer's picture.

For each explorer and each of its sliders, the slider is moved back and forth between
two valid values and the time from setting ``.value`` to the PNG bytes being ready is
recorded (the redraw runs synchronously in the slider's observer). The peer, measured
in the same process and interleaved with the moves (so both see the same machine
load), is the cost of drawing and rendering a plain matplotlib figure of the same
size and dpi with a 1 000-point line to PNG: what a redraw that repaints everything
would at least pay. Target (issue 12): every median ≤ 0.7× its peer and ≤ 40 ms on a
quiet 2-core machine. The worst ratio is printed last.
"""

from __future__ import annotations

import argparse
import importlib
import io
import statistics
import time

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from lqe_helpers.explorers import png

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
MOVES = 12
TARGET_RATIO = 0.7
TARGET_MS = 40.0


def peer_render_ms(figsize: tuple[float, float], dpi: float) -> float:
    """Time (ms) to draw and render a plain 1 000-point line figure to PNG, once."""
    t = np.linspace(0.0, 10.0, 1000)
    start = time.perf_counter()
    figure = Figure(figsize=figsize, dpi=dpi)
    FigureCanvasAgg(figure)
    ax = figure.add_subplot()
    ax.plot(t, np.sin(t))
    ax.set_xlabel("time (s)")
    figure.savefig(io.BytesIO(), format="png", dpi=dpi)
    return 1e3 * (time.perf_counter() - start)


def other_value(slider) -> float:
    """A valid value of ``slider``, a quarter (or three quarters) along its range."""
    logarithmic = hasattr(slider, "base")  # FloatLogSlider: min, max, step are exponents
    current = np.log(slider.value) / np.log(slider.base) if logarithmic else slider.value
    target = slider.min + 0.25 * (slider.max - slider.min)
    if abs(target - current) < slider.step:
        target = slider.min + 0.75 * (slider.max - slider.min)
    target = slider.min + slider.step * round((target - slider.min) / slider.step)
    return float(slider.base**target) if logarithmic else float(target)


def time_slider_moves(explorer, name: str) -> tuple[list[float], list[float]]:
    """Times (ms) of MOVES value changes of one slider and of MOVES peer renders.

    Each move is followed by one peer render, so slow and busy moments of a shared
    machine fall on both alike. The slider is restored afterwards.
    """
    slider = explorer.sliders[name]
    original = slider.value
    values = [other_value(slider), original]
    size = tuple(explorer.figure.get_size_inches())
    slider.value = values[0]  # warm up: the first move may build the cached layer
    slider.value = original
    moves, peers = [], []
    for i in range(MOVES):
        start = time.perf_counter()
        slider.value = values[i % 2]
        moves.append(1e3 * (time.perf_counter() - start))
        peers.append(peer_render_ms(size, explorer.dpi))
    slider.value = original
    return moves, peers


def compare_encoders() -> None:
    """Median time (ms) of Pillow's PNG encoder and of the pack's on each default picture."""
    print("\nPNG encoding of each explorer's picture (RGB), median of 10: Pillow at "
          f"compress_level={png.COMPRESS_LEVEL} (adaptive row filters) against "
          "lqe_helpers.explorers.png.encode (no row filters)")
    for notebook, module_name, factory in EXPLORERS:
        explorer = getattr(importlib.import_module(module_name), factory)()
        rgb = np.ascontiguousarray(np.asarray(explorer.layers.render())[..., :3])
        image = Image.fromarray(rgb)

        def pillow(image=image) -> bytes:
            buffer = io.BytesIO()
            image.save(buffer, format="png", compress_level=png.COMPRESS_LEVEL)
            return buffer.getvalue()

        times = {}
        sizes = {}
        for name, encode in (("Pillow", pillow), ("pack", lambda rgb=rgb: png.encode(rgb, 90))):
            runs = []
            for _ in range(10):
                start = time.perf_counter()
                sizes[name] = len(encode())
                runs.append(1e3 * (time.perf_counter() - start))
            times[name] = statistics.median(runs)
        print(f"  {notebook:27s} Pillow {times['Pillow']:6.1f} ms ({sizes['Pillow'] // 1024} KiB), "
              f"pack {times['pack']:6.1f} ms ({sizes['pack'] // 1024} KiB): "
              f"{times['pack'] / times['Pillow']:.2f}x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--encoders", action="store_true",
                        help="also compare the PNG writers on each explorer's picture")
    arguments = parser.parse_args()
    if arguments.encoders:
        compare_encoders()
    print(f"Explorer redraw: slider value set -> PNG ready, median of {MOVES} moves, against "
          f"a plain figure of the same size rendered in between (target <= "
          f"{TARGET_RATIO}x and <= {TARGET_MS:.0f} ms on a quiet 2-core machine)")
    worst = (0.0, "")
    for notebook, module_name, factory in EXPLORERS:
        explorer = getattr(importlib.import_module(module_name), factory)()
        width, height = explorer.figure.get_size_inches()
        for name in explorer.sliders:
            full_before = explorer.layers.full_renders
            moves, peers = time_slider_moves(explorer, name)
            median, peer = statistics.median(moves), statistics.median(peers)
            ratio = median / peer
            full = explorer.layers.full_renders - full_before
            worst = max(worst, (ratio, f"{notebook} {name}"))
            verdict = "ok" if ratio <= TARGET_RATIO else "SLOW"
            print(f"  {notebook:27s} {name:12s} {median:6.1f} ms = {ratio:4.2f}x a plain "
                  f"{width:.0f}x{height:.0f} in figure ({peer:6.1f} ms); full repaints "
                  f"{full}/{MOVES + 3}  {verdict}")
    print(f"worst ratio: {worst[0]:.2f}x ({worst[1]})")


if __name__ == "__main__":
    main()
