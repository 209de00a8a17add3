"""A figure's Agg pixels as a PNG file, encoded with numpy and zlib.

matplotlib's ``savefig`` hands the (h, w, 4) RGBA buffer to Pillow, whose PNG encoder
chooses a row filter per row by trying all five (slow at any zlib level). The figures are
opaque line art on white: rows unfiltered, RGB when every pixel is opaque, compress faster
into smaller files, with the same pixels.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.files import write_atomic

__all__ = ["encode_png", "write_png"]

_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_INCH = 0.0254  # [m]


def _chunk(kind: bytes, data: bytes) -> bytes:
    """One PNG chunk: length, type, data, CRC-32 of type and data."""
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def encode_png(rgba: np.ndarray, dpi: float, level: int) -> bytes:
    """The bytes of a PNG file of an image.

    Parameters
    ----------
    rgba: (h, w, 4) uint8 RGBA pixels, top row first (an Agg canvas' ``buffer_rgba()``).
    dpi: resolution stored in the file (``pHYs``) [dots per inch].
    level: zlib compression level, 0 (none) … 9.

    Returns
    -------
    The PNG file: 8-bit RGB (colour type 2) when every pixel is opaque, else RGBA (6);
    rows unfiltered (filter type 0); no text chunks.
    """
    pixels = np.ascontiguousarray(rgba, dtype=np.uint8)
    h, w = pixels.shape[:2]
    opaque = int(pixels[..., 3].min()) == 255
    channels = 3 if opaque else 4
    rows = np.empty((h, 1 + w * channels), dtype=np.uint8)
    rows[:, 0] = 0  # filter type 0 (none) for every row
    rows[:, 1:].reshape(h, w, channels)[...] = pixels[..., :channels]  # a view: no copy
    ppm = int(dpi / _INCH + 0.5)  # pixels per metre, as Pillow rounds them
    header = struct.pack(">IIBBBBB", w, h, 8, 2 if opaque else 6, 0, 0, 0)
    return b"".join(
        [
            _SIGNATURE,
            _chunk(b"IHDR", header),
            _chunk(b"pHYs", struct.pack(">IIB", ppm, ppm, 1)),
            _chunk(b"IDAT", zlib.compress(rows.data, level)),
            _chunk(b"IEND", b""),
        ]
    )


def write_png(fig: Any, path: Path, level: int) -> Path:
    """Draw ``fig`` (a matplotlib figure on an Agg canvas) and write it to ``path`` as a
    PNG at the figure's own dpi, atomically (:func:`adept_traj.files.write_atomic`);
    return ``path``. ``level``: zlib compression level, 0 … 9."""
    fig.canvas.draw()
    data = encode_png(np.asarray(fig.canvas.buffer_rgba()), fig.dpi, level)
    return write_atomic(path, lambda tmp: tmp.write_bytes(data))
