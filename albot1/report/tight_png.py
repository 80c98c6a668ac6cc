"""Save a figure as a PNG cropped to what was drawn, laying the figure out once.

``savefig(bbox_inches="tight")`` lays the figure out three times (a dry draw
to place the text, the tight box of every artist, which places the ticks
again, then the real draw): for a run's preview that is most of its cost,
and every cell of ``albot1 bench`` draws one. Here the figure is drawn once
on the Agg canvas and the picture is cropped to the pixels that differ from
the figure's background, with the same 0.1 inch margin ``bbox_inches="tight"``
leaves (``savefig.pad_inches``). The picture is the same drawing; only its
margins may differ by a pixel or two from Matplotlib's text-box estimate.

The PNG is compressed at zlib level 1 (``PNG_COMPRESS_LEVEL``) rather than
Pillow's default 6: the same pixels, 2-3x less time encoding and files about
as large for these mostly white pictures (docs/benchmarking.md, "Cell
start-up and the rest of a cell"). A picture with no transparent pixel (a
figure on its opaque background: every preview) is written as RGB, without
the alpha channel, which is 255 everywhere: a quarter fewer bytes to filter
and compress, the same colours read back (docs/benchmarking.md, "Session 24").
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

#: zlib level of the saved PNG: 1 (fastest) instead of Pillow's default 6; the decoded pixels are the same.
PNG_COMPRESS_LEVEL = 1


def save_tight_png(fig: Any, path: Path) -> None:
    """Draw ``fig`` (a Matplotlib figure) once and write it to ``path`` as a PNG cropped to its ink plus a margin."""
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    canvas = FigureCanvasAgg(fig)
    canvas.draw()  # type: ignore[no-untyped-call]
    pixels = np.asarray(canvas.buffer_rgba())  # type: ignore[no-untyped-call]
    top, bottom, left, right = ink_box(pixels)
    pad = int(round(float(matplotlib.rcParams["savefig.pad_inches"]) * fig.dpi))
    top, left = max(0, top - pad), max(0, left - pad)
    bottom, right = min(pixels.shape[0], bottom + pad), min(pixels.shape[1], right + pad)
    image = Image.fromarray(opaque_or_rgba(pixels[top:bottom, left:right]))
    dpi = (round(fig.dpi), round(fig.dpi))
    with path.open("wb") as handle:  # a file object: the caller's temporary name may lack ".png"
        image.save(handle, format="png", dpi=dpi, compress_level=PNG_COMPRESS_LEVEL)


def opaque_or_rgba(pixels: np.ndarray) -> np.ndarray:
    """``pixels`` (h, w, 4, uint8 RGBA) as (h, w, 3) RGB when every alpha is 255, else as they are; contiguous.

    An opaque picture loses nothing without its alpha channel, and Pillow
    encodes three channels in about three quarters of the time of four.
    """
    if pixels.ndim == 3 and pixels.shape[2] == 4 and bool((pixels[..., 3] == 255).all()):
        return np.ascontiguousarray(pixels[..., :3])
    return np.ascontiguousarray(pixels)


def ink_box(pixels: np.ndarray) -> tuple[int, int, int, int]:
    """(top, bottom, left, right), bottom and right exclusive: the rows and columns that differ from the corner.

    The top-left pixel is the figure's background; a picture of background
    only keeps its whole extent. An RGBA picture is compared as one 32-bit
    word per pixel (a view, no copy when contiguous): 50x faster than
    comparing the four channels apart on a 770 x 770 preview.
    """
    if pixels.ndim == 3 and pixels.shape[2] == 4 and pixels.dtype == np.uint8:
        words = np.ascontiguousarray(pixels).view(np.uint32)[..., 0]
        ink = words != words[0, 0]
    else:
        ink = (pixels != pixels[0, 0]).any(axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if not len(rows):
        return 0, pixels.shape[0], 0, pixels.shape[1]
    return int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
