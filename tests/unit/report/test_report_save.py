"""plots.save: one layout for both formats, the PNG as savefig writes it, dense layers as images in the SVG."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from albot1.report.plots import DPI, dense, pyplot, save
from albot1.report.tight_png import PNG_COMPRESS_LEVEL


def _figure(*, rasterize: bool) -> Any:
    from matplotlib.collections import LineCollection

    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(6, 3), layout="constrained")
    t = np.linspace(0.0, 6.0, 400)
    segments = np.stack([np.c_[t[:-1], np.sin(t[:-1])], np.c_[t[1:], np.sin(t[1:])]], axis=1)
    lines = LineCollection(list(segments), linewidths=1.0)
    axes[0].add_collection(dense(lines) if rasterize else lines)
    axes[0].set_xlim(0, 6)
    axes[0].set_ylim(-1.2, 1.2)
    axes[1].plot(t, np.cos(t), label="a long legend label that the layout must make room for")
    fig.legend(loc="outside lower center")
    fig.suptitle("two panels")
    return fig


def test_the_png_is_the_one_savefig_writes_and_the_svg_embeds_the_dense_layer(tmp_path: Path) -> None:
    from PIL import Image

    for name, options in (("default.png", {}), ("old.png", {"pil_kwargs": {"compress_level": PNG_COMPRESS_LEVEL}})):
        fig = _figure(rasterize=False)
        fig.savefig(tmp_path / name, format="png", dpi=DPI, **options)  # what save wrote before it laid out once
        pyplot().close(fig)
    png = save(_figure(rasterize=True), tmp_path / "new.png")
    assert png.read_bytes() == (tmp_path / "old.png").read_bytes()
    # Pillow's default zlib level (6) until session 24: other bytes, the same pixels
    with Image.open(png) as new, Image.open(tmp_path / "default.png") as default:
        assert new.size == default.size and new.tobytes() == default.tobytes()
    assert png.stat().st_size != (tmp_path / "default.png").stat().st_size
    svg = png.with_suffix(".svg").read_text()
    assert svg.count("<image") == 1  # the 399 segments are one picture
    assert svg.count("<path") < 100 and "two panels" in svg  # axes, ticks and text stay vectors


def test_without_a_dense_layer_the_svg_draws_every_segment(tmp_path: Path) -> None:
    svg = save(_figure(rasterize=False), tmp_path / "f.png").with_suffix(".svg").read_text()
    assert "<image" not in svg and svg.count("<path") > 399
