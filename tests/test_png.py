"""Strips written by write_png stack into one PNG without being decoded: any PNG reader
sees the strips one above the other, pixel for pixel."""

import zlib

import numpy as np
import pytest
from PIL import Image

from alfa_bench.outputs.png import adler32_combine, stack, write_png


def image(h: int, w: int, seed: int) -> np.ndarray:
    """White with coloured strokes, and noise in one corner: runs and surprises."""
    rng = np.random.default_rng(seed)
    rgba = np.full((h, w, 4), 255, dtype=np.uint8)
    rgba[rng.integers(0, h, 40), :, :3] = rng.integers(0, 255, (40, 1, 3), dtype=np.uint8)
    rgba[: h // 3, : w // 3] = rng.integers(0, 256, (h // 3, w // 3, 4), dtype=np.uint8)
    return rgba


def test_a_strip_is_a_png_any_reader_reads(tmp_path):
    rgba = image(37, 61, 0)
    write_png(rgba, tmp_path / "s.png", 110)
    with Image.open(tmp_path / "s.png") as im:
        assert im.mode == "RGBA" and np.array_equal(np.asarray(im), rgba)
        assert im.info["dpi"] == pytest.approx((110, 110), abs=0.01)


def test_stacked_strips_and_images_are_the_column_of_their_pixels(tmp_path):
    parts = [image(h, 61, seed) for seed, h in enumerate([5, 1, 37, 200])]
    paths = []
    for k, rgba in enumerate(parts[1:3]):
        paths.append(tmp_path / f"{k}.png")
        write_png(rgba, paths[-1], 110)
    stack([parts[0], *paths, parts[3]], tmp_path / "column.png", 110)
    with Image.open(tmp_path / "column.png") as im:
        assert np.array_equal(np.asarray(im), np.vstack(parts))


def test_parts_of_another_width_or_another_writer_are_refused(tmp_path):
    write_png(image(4, 8, 0), tmp_path / "narrow.png", 110)
    with pytest.raises(ValueError, match="8 pixels wide, under parts 9 wide"):
        stack([image(4, 9, 1), tmp_path / "narrow.png"], tmp_path / "x.png", 110)
    Image.fromarray(image(4, 9, 1)).save(tmp_path / "pil.png")
    with pytest.raises(ValueError, match="not a strip written by write_png"):
        stack([tmp_path / "pil.png"], tmp_path / "x.png", 110)


def test_adler32_combine_is_zlibs():
    rng = np.random.default_rng(1)
    for n1, n2 in [(0, 0), (1, 0), (0, 5), (100, 70000), (65521, 65521), (3, 200000)]:
        a, b = rng.bytes(n1), rng.bytes(n2)
        assert adler32_combine(zlib.adler32(a), zlib.adler32(b), n2) == zlib.adler32(a + b)
