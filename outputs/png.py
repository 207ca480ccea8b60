r"""RGBA images as PNG files that stack without being decoded or compressed again.

A flight figure is a column of strips, each drawn by another job (:mod:`.figures`).
Decoding the strips and compressing the figure again took most of the time the
figures took, so a strip is written in a form whose compressed rows can be copied
into the figure as they are (`PNG <https://www.w3.org/TR/png-3/>`_, `deflate
<https://www.rfc-editor.org/rfc/rfc1951>`_, `zlib <https://www.rfc-editor.org/rfc/rfc1950>`_):

- every row is filtered with *Sub*, :math:`F(x) = R(x) - R(x - 4)` (mod 256), which
  reads its own row only, so a row means the same under any row above it;
- the rows are deflated on their own (raw deflate, level 1) and ended by a *sync
  flush*, which ends on a byte boundary with no block marked last, so a column's
  deflate stream is its strips' streams one after the other, then an empty last
  block;
- the zlib check of a column, the Adler-32 of its filtered rows, follows from its
  strips' checks and lengths (:func:`adler32_combine`, as zlib's ``adler32_combine``).

Each strip is a valid PNG of its own (``<strip>.png`` opens in any viewer), and
:func:`stack` writes the column as one valid PNG, pixel for pixel the strips one
above the other.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

__all__ = ["adler32_combine", "stack", "write_png"]

_SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: zlib's header for deflate with a 32 KiB window (the fastest level), and the empty
#: deflate block marked last
_ZLIB_HEADER, _LAST_BLOCK = b"\x78\x01", b"\x03\x00"
_BASE = 65521          # Adler-32's modulus


def _chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data)))


def _deflated(rgba: np.ndarray) -> tuple[bytes, int, int]:
    """The rows of ``rgba`` (h, w, 4) Sub-filtered and deflated to a sync flush: the
    deflate data, and the Adler-32 and length of the filtered rows."""
    rows = np.ascontiguousarray(rgba, dtype=np.uint8).reshape(rgba.shape[0], -1)
    filtered = np.empty((rows.shape[0], rows.shape[1] + 1), dtype=np.uint8)
    filtered[:, 0] = 1                                       # filter type Sub
    filtered[:, 1:5] = rows[:, :4]
    np.subtract(rows[:, 4:], rows[:, :-4], out=filtered[:, 5:])   # R(x) - R(x - 4)
    data = filtered.tobytes()
    deflate = zlib.compressobj(1, zlib.DEFLATED, -15)
    return deflate.compress(data) + deflate.flush(zlib.Z_SYNC_FLUSH), zlib.adler32(data), len(data)


def _png(width: int, height: int, stream: bytes, dpi: float) -> bytes:
    ppm = int(dpi / 0.0254 + 0.5)                             # pixels per metre
    return (_SIGNATURE
            + _chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
            + _chunk(b"pHYs", struct.pack(">IIB", ppm, ppm, 1))
            + _chunk(b"IDAT", stream) + _chunk(b"IEND", b""))


def write_png(rgba: np.ndarray, path: str | Path, dpi: float) -> None:
    """Write the image ``rgba`` (h, w, 4, uint8) to ``path`` as a PNG that
    :func:`stack` can stack without decoding it."""
    data, adler, _ = _deflated(rgba)
    stream = _ZLIB_HEADER + data + _LAST_BLOCK + struct.pack(">I", adler)
    Path(path).write_bytes(_png(rgba.shape[1], rgba.shape[0], stream, dpi))


def _strip(path: Path) -> tuple[int, int, bytes, int]:
    """Width, height, deflate data and Adler-32 of a PNG :func:`write_png` wrote."""
    blob = path.read_bytes()
    pos, idat, size = len(_SIGNATURE), [], None
    while pos < len(blob):
        (n,) = struct.unpack_from(">I", blob, pos)
        kind, data = blob[pos + 4:pos + 8], blob[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            size = struct.unpack_from(">II", data)
            if data[8:] != b"\x08\x06\x00\x00\x00":
                raise ValueError(f"{path}: not an 8-bit RGBA PNG")
        elif kind == b"IDAT":
            idat.append(data)
        pos += 12 + n
    stream = b"".join(idat)
    if (size is None or stream[:2] != _ZLIB_HEADER
            or stream[-6:-4] != _LAST_BLOCK):
        raise ValueError(f"{path}: not a strip written by write_png")
    return size[0], size[1], stream[2:-6], struct.unpack(">I", stream[-4:])[0]


def adler32_combine(adler1: int, adler2: int, len2: int) -> int:
    """The Adler-32 of two byte strings one after the other, from their checks and the
    second one's length."""
    rem = len2 % _BASE
    sum1 = ((adler1 & 0xFFFF) + (adler2 & 0xFFFF) + _BASE - 1) % _BASE
    sum2 = (rem * (adler1 & 0xFFFF) + (adler1 >> 16) + (adler2 >> 16) + _BASE - rem) % _BASE
    return sum1 | (sum2 << 16)


def stack(parts: list, path: str | Path, dpi: float) -> None:
    """Write to ``path`` the PNG of ``parts`` one above the other, top first: each an
    image (h, w, 4, uint8) or the path of a PNG :func:`write_png` wrote, all ``w``
    wide. The strips' compressed rows are copied, not decoded."""
    width, height, adler, pieces = None, 0, 1, []
    for part in parts:
        if isinstance(part, np.ndarray):
            w, h = part.shape[1], part.shape[0]
            data, check, _ = _deflated(part)
        else:
            w, h, data, check = _strip(Path(part))
        if width is not None and w != width:
            raise ValueError(f"a part {w} pixels wide, under parts {width} wide: {part}")
        width, height = w, height + h
        adler = adler32_combine(adler, check, h * (4 * w + 1))
        pieces.append(data)
    stream = _ZLIB_HEADER + b"".join(pieces) + _LAST_BLOCK + struct.pack(">I", adler)
    Path(path).write_bytes(_png(width, height, stream, dpi))
