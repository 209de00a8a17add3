"""adept_traj.viz.plots._png: the PNG files decode (by Pillow, which shares no code with
the encoder) to exactly the pixels given, and a figure's file holds exactly the pixels
matplotlib's own ``savefig`` gives."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from adept_traj.viz.plots._png import encode_png
from adept_traj.viz.plots.common import new_figure, save_figure


def _decoded(data: bytes) -> tuple[np.ndarray, Image.Image]:
    image = Image.open(io.BytesIO(data))
    image.load()
    return np.asarray(image), image


def test_an_opaque_image_is_rgb_and_decodes_to_its_pixels() -> None:
    rng = np.random.default_rng(3)
    rgba = rng.integers(0, 256, size=(37, 53, 4), dtype=np.uint8)
    rgba[..., 3] = 255
    pixels, image = _decoded(encode_png(rgba, dpi=110.0, level=1))
    assert image.mode == "RGB"
    np.testing.assert_array_equal(pixels, rgba[..., :3])
    assert image.info["dpi"] == pytest.approx((110.0074, 110.0074))  # 4331 px/m, as Pillow
    assert set(image.info) == {"dpi"}  # no text chunk (no software version)


def test_a_translucent_image_keeps_its_alpha() -> None:
    rng = np.random.default_rng(4)
    rgba = rng.integers(0, 256, size=(20, 9, 4), dtype=np.uint8)
    for level in (0, 6):
        pixels, image = _decoded(encode_png(rgba, dpi=72.0, level=level))
        assert image.mode == "RGBA"
        np.testing.assert_array_equal(pixels, rgba)


def test_a_figure_file_holds_the_pixels_of_savefig(tmp_path: Path) -> None:
    fig = new_figure(3.0, 2.0)
    ax = fig.add_subplot()
    ax.plot([0.0, 1.0, 2.0], [1.0, -1.0, 0.5], label="a line")
    ax.set_title("title ×10³")
    ax.legend()
    fig.savefig(tmp_path / "savefig.png", dpi=fig.dpi)
    ours = save_figure(fig, tmp_path / "ours.png")
    expected = np.asarray(Image.open(tmp_path / "savefig.png").convert("RGB"))
    np.testing.assert_array_equal(np.asarray(Image.open(ours)), expected)
