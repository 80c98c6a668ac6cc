"""The one-pass tight PNG of run previews: cropped to the ink plus the 0.1 inch margin."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from albot1.report.tight_png import ink_box, opaque_or_rgba, save_tight_png


def test_ink_box_is_the_rows_and_columns_that_differ_from_the_background() -> None:
    pixels = np.full((10, 12, 4), 255, dtype=np.uint8)
    pixels[3, 4] = (0, 0, 0, 255)
    pixels[6, 9] = (255, 0, 0, 255)
    assert ink_box(pixels) == (3, 7, 4, 10)
    assert ink_box(np.full((5, 6, 4), 255, dtype=np.uint8)) == (0, 5, 0, 6)  # background only: whole picture


def test_saved_png_is_the_ink_with_a_margin(tmp_path: Path) -> None:
    from matplotlib.figure import Figure  # here, not at collection: matplotlib costs every test run's collection
    from matplotlib.patches import Rectangle

    fig = Figure(figsize=(4, 4), dpi=50)  # 200 x 200 pixels
    ax = fig.add_axes((0.25, 0.25, 0.5, 0.5))  # a frame from pixel 50 to 150 each way
    ax.set_axis_off()
    ax.add_patch(Rectangle((0, 0), 1, 1, color="k", antialiased=False))
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    path = tmp_path / "tmp-name-without-suffix"
    save_tight_png(fig, path)
    with Image.open(path) as image:
        assert image.format == "PNG"
        width, height = image.size
        pixels = np.asarray(image.convert("RGBA"))
    assert (width, height) == (110, 110)  # 100 pixels of ink and 5 (0.1 inch at 50 dpi) on each side
    assert (pixels[5:105, 5:105, :3] == 0).all()
    assert (pixels[:5, :, :3] == 255).all() and (pixels[-5:, :, :3] == 255).all()


@given(
    st.integers(1, 9),
    st.integers(1, 9),
    st.lists(st.tuples(st.integers(0, 8), st.integers(0, 8), st.integers(0, 3), st.integers(0, 254)), max_size=4),
)
@settings(max_examples=200, deadline=None)
def test_ink_box_sees_a_change_in_any_one_channel(
    height: int, width: int, changes: list[tuple[int, int, int, int]]
) -> None:
    """The RGBA fast path (one 32-bit word per pixel) finds what comparing the channels one by one finds."""
    pixels = np.full((height, width, 4), 255, dtype=np.uint8)
    for row, col, channel, value in changes:
        pixels[row % height, col % width, channel] = value
    ink = (pixels != pixels[0, 0]).any(axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    expected = (rows[0], rows[-1] + 1, cols[0], cols[-1] + 1) if len(rows) else (0, height, 0, width)
    assert ink_box(pixels) == expected


def test_saved_png_keeps_the_drawn_pixels(tmp_path: Path) -> None:
    """Compressed at level 1, the PNG decodes to exactly the canvas's pixels (cropped)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 2), dpi=50)
    ax = fig.add_subplot()
    ax.plot([0, 1, 0.3], [0, 1, 0.8], color="tab:blue")
    ax.set_title("t", fontsize=9)
    path = tmp_path / "p.png"
    save_tight_png(fig, path)
    canvas = np.asarray(fig.canvas.buffer_rgba())
    top, bottom, left, right = ink_box(canvas)
    pad = 5  # 0.1 inch at 50 dpi
    crop = canvas[max(0, top - pad) : bottom + pad, max(0, left - pad) : right + pad]
    with Image.open(path) as image:
        np.testing.assert_array_equal(np.asarray(image.convert("RGBA")), crop)


def test_an_opaque_picture_is_written_as_rgb_with_the_same_colours(tmp_path: Path) -> None:
    """A figure on its opaque background loses nothing without the alpha channel (255 everywhere): RGB, same pixels.

    Every preview is such a picture: three channels to filter and compress instead of four (session 24).
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 2), dpi=50)
    ax = fig.add_subplot()
    ax.scatter([0, 1, 0.3], [0, 1, 0.8], s=3, c="0.35", linewidths=0)
    ax.set_xlabel("x (m)")
    path = tmp_path / "p.png"
    save_tight_png(fig, path)
    canvas = np.asarray(fig.canvas.buffer_rgba())
    assert (canvas[..., 3] == 255).all()
    top, bottom, left, right = ink_box(canvas)
    crop = canvas[max(0, top - 5) : bottom + 5, max(0, left - 5) : right + 5]
    with Image.open(path) as image:
        assert image.mode == "RGB"
        np.testing.assert_array_equal(np.asarray(image), crop[..., :3])


def test_a_picture_with_transparent_pixels_keeps_its_alpha_channel() -> None:
    pixels = np.full((3, 4, 4), 255, dtype=np.uint8)
    assert opaque_or_rgba(pixels).shape == (3, 4, 3)
    pixels[1, 2, 3] = 128  # one half-transparent pixel: the alpha channel says something
    kept = opaque_or_rgba(pixels[:, 1:])
    assert kept.shape == (3, 3, 4) and kept.flags.c_contiguous
    np.testing.assert_array_equal(kept, pixels[:, 1:])
