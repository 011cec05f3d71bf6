"""lqe_helpers.explorers.png, the PNG writer, read back by an independent decoder (Pillow)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from lqe_helpers.explorers import png


@pytest.mark.parametrize("shape", [(1, 1, 3), (7, 5, 3), (3, 11, 4), (64, 48, 4)])
def test_pillow_reads_back_every_pixel(shape):
    pixels = np.random.default_rng(sum(shape)).integers(0, 256, shape, dtype=np.uint8)
    image = Image.open(io.BytesIO(png.encode(pixels, 90)))
    assert image.mode == ("RGB" if shape[2] == 3 else "RGBA")
    np.testing.assert_array_equal(np.asarray(image), pixels)


@pytest.mark.parametrize("level", [0, 1, 9])
def test_every_level_gives_the_same_picture(level):
    pixels = np.full((20, 30, 3), 255, dtype=np.uint8)
    pixels[5:8, :, 0] = 10  # a red-free stripe: long runs, as in a plot
    np.testing.assert_array_equal(
        np.asarray(Image.open(io.BytesIO(png.encode(pixels, 72, level)))), pixels)


@pytest.mark.parametrize("dpi", [60, 90, 150.0])
def test_resolution_is_recorded(dpi):
    image = Image.open(io.BytesIO(png.encode(np.zeros((2, 2, 3), np.uint8), dpi)))
    assert image.info["dpi"] == pytest.approx((dpi, dpi), abs=0.02)


def test_equal_pictures_give_equal_bytes():
    pixels = np.random.default_rng(3).integers(0, 256, (9, 9, 3), dtype=np.uint8)
    assert png.encode(pixels, 90) == png.encode(pixels.copy(), 90)


@pytest.mark.parametrize(("pixels", "dpi", "level", "message"), [
    (np.zeros((2, 2, 3), np.float64), 90, 1, "pixels must be a uint8 array"),
    (np.zeros((2, 2), np.uint8), 90, 1, "got uint8 of shape (2, 2)"),
    (np.zeros((2, 2, 2), np.uint8), 90, 1, "shape (h, w, 3) or (h, w, 4)"),
    (np.zeros((0, 2, 3), np.uint8), 90, 1, "h, w >= 1"),
    ([[[0, 0, 0]]], 90, 1, "got list"),
    (np.zeros((2, 2, 3), np.uint8), 0, 1, "dpi must be a finite number > 0, got 0"),
    (np.zeros((2, 2, 3), np.uint8), float("nan"), 1, "dpi must be"),
    (np.zeros((2, 2, 3), np.uint8), 90, 10, "level must be an integer from 0 to 9, got 10"),
    (np.zeros((2, 2, 3), np.uint8), 90, True, "level must be an integer"),
])
def test_bad_input_is_named(pixels, dpi, level, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        png.encode(pixels, dpi, level)
