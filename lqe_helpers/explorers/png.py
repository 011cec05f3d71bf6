"""PNG bytes of an RGB(A) picture, fast: no row filters, zlib's fastest level.

Pillow applies adaptive row filtering to every RGB picture, whatever the compression
level; on the explorers' plots (large flat areas, thin lines) that costs more than the
compression and gives larger files. A slider move encodes one picture, so
:func:`encode` writes the PNG itself with the standard library: filter type 0 (None)
on every row, one deflate stream (``benchmarks/bench_widgets.py --encoders`` measures
both). The format is the PNG specification's (ISO/IEC 15948): signature, IHDR, pHYs,
IDAT, IEND, each chunk with its CRC-32.
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

#: zlib level of the picture data (0 = none … 9 = smallest).
COMPRESS_LEVEL = 1

_SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: IHDR colour types by channel count: 3 = truecolour (RGB), 4 = truecolour with alpha.
_COLOUR_TYPE = {3: 2, 4: 6}
_METRES_PER_INCH = 0.0254


def _chunk(kind: bytes, data: bytes) -> bytes:
    """One PNG chunk: length, type, data, CRC-32 of type and data."""
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data)))


def encode(pixels: np.ndarray, dpi: float, level: int = COMPRESS_LEVEL) -> bytes:
    """The picture ``pixels`` as PNG bytes, with its resolution recorded.

    Parameters
    ----------
    pixels : ndarray of uint8, shape (h, w, 3) or (h, w, 4)
        RGB or RGBA rows, top row first.
    dpi : float
        Resolution stored in the pHYs chunk (dots per inch), > 0.
    level : int
        zlib compression level, 0 … 9.

    Raises
    ------
    ValueError
        If ``pixels`` is not uint8 of shape (h, w, 3 or 4) with h, w >= 1, or ``dpi``
        or ``level`` is out of range.
    """
    if (not isinstance(pixels, np.ndarray) or pixels.dtype != np.uint8 or pixels.ndim != 3
            or pixels.shape[2] not in _COLOUR_TYPE or 0 in pixels.shape):
        raise ValueError(
            "pixels must be a uint8 array of shape (h, w, 3) or (h, w, 4) with h, w >= 1, "
            f"got {getattr(pixels, 'dtype', type(pixels).__name__)} of shape "
            f"{getattr(pixels, 'shape', None)}")
    if not (isinstance(dpi, (int, float, np.floating)) and np.isfinite(dpi) and dpi > 0):
        raise ValueError(f"dpi must be a finite number > 0, got {dpi!r}")
    if isinstance(level, bool) or level not in range(10):
        raise ValueError(f"level must be an integer from 0 to 9, got {level!r}")
    height, width, channels = pixels.shape
    rows = np.zeros((height, 1 + width * channels), dtype=np.uint8)  # byte 0: filter None
    rows[:, 1:] = pixels.reshape(height, width * channels)
    header = struct.pack(">IIBBBBB", width, height, 8, _COLOUR_TYPE[channels], 0, 0, 0)
    per_metre = round(dpi / _METRES_PER_INCH)
    return b"".join([
        _SIGNATURE,
        _chunk(b"IHDR", header),
        _chunk(b"pHYs", struct.pack(">IIB", per_metre, per_metre, 1)),
        _chunk(b"IDAT", zlib.compress(rows.tobytes(), level)),
        _chunk(b"IEND", b""),
    ])


def encode_picture(rgba: np.ndarray, dpi: float) -> bytes:
    """The picture ``rgba`` (uint8, shape (h, w, 4)) as PNG bytes, fast rather than small.

    An opaque picture is stored as RGB, a quarter fewer bytes to compress; :func:`encode`
    skips row filters and uses zlib's fastest level, since for a widget on the same
    machine encoding time matters more than bytes. No metadata besides the resolution,
    so equal pictures give equal bytes.
    """
    opaque = bool(rgba[..., 3].min() == 255)
    return encode(np.ascontiguousarray(rgba[..., :3] if opaque else rgba), dpi)
