"""What every report plot shares: colours, the runs pictured, the common frame, figure sizing, saving.

* **One colour per method** across every plot of a report
  (:func:`method_colors`): assigned once from the plan's method order, so a
  method keeps its colour whatever failed where.
* **The run pictured** for a dataset and method (:func:`representative`):
  its run on the dataset's own odometry (degradation ``none``) with the
  lowest seed, falling back to the first completed cell; maps and overlays
  show that run so every method is pictured on the same input.
* **One frame**: estimates (and their maps) are drawn after the rigid
  alignment the ATE uses (:func:`albot1.metrics.alignment.align`), so the
  picture and the number agree and every method shares the reference's
  frame; without reference poses each method is drawn in its own frame
  (they all start at the odometry's first pose) and the title says so.
* **Figures follow the data's shape** (:func:`panel_layout`): a long narrow
  corridor gets wide, flat panels stacked in rows instead of a 20-pixel
  strip; legends sit outside the axes.
* **PNG and SVG** of every figure (:func:`save`, laid out once for both): PNG
  for the pages, SVG for papers (dense layers, the point maps, the line maps
  and the per-pose error tracks, are embedded as images inside the SVG).
"""

from __future__ import annotations

import hashlib
import math
import re
import textwrap
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from albot1.geometry import se2
from albot1.metrics.alignment import align, rigid_transform
from albot1.metrics.errors import MetricsError
from albot1.report.collect import CellRecord
from albot1.report.mathtext_memo import share_parsed_math
from albot1.report.tick_memo import share_tick_updates
from albot1.report.tight_png import PNG_COMPRESS_LEVEL

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Colours of other method labels, chosen by a hash of the label: tab10 then the light half of tab20.
PALETTE = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
    "#aec7e8",
    "#ffbb78",
    "#98df8a",
    "#ff9896",
    "#c5b0d5",
    "#c49c94",
)
#: The colours of the project's own method labels (distinct; the first ten are matplotlib's tab10).
FIXED_COLORS: dict[str, str] = {
    "odometry": "#7f7f7f",
    "albot1": "#1f77b4",
    "albot1:thesis": "#17becf",
    "albot1:plus": "#9467bd",
    "albot1:literal": "#aec7e8",
    "albot1:exact": "#bcbd22",
    "albot1-places": "#e377c2",
    "kiss-icp": "#ff7f0e",
    "gtsam-graph": "#2ca02c",
    "mrpt-icp": "#d62728",
    "mrpt-rbpf": "#8c564b",
}
REFERENCE_COLOR = "black"
DPI = 120
#: Figure width limit (inches) and the widest/tallest panel shape drawn (a longer extent is padded).
MAX_WIDTH_IN = 13.0
MAX_PANEL_ASPECT = 6.0
VECTOR_FORMAT = "svg"


#: Longest readable part of a :func:`slug` (plot names add a kind and a suffix; file systems allow 255 bytes).
SLUG_CHARS = 48
_HASHED = re.compile(r".*-h[0-9a-f]{10}")


def slug(text: str) -> str:
    """A short file-name-safe name of a dataset or method label, different for different labels.

    A label that is already safe (ASCII letters, digits, ``_.-``; at most
    :data:`SLUG_CHARS` characters) is its own slug, so common plot names stay
    readable (``aces-maps.png``). Any other label (a slice ``aces[:2500:2]``,
    a path, non-ASCII characters, a 290-character path) gets its readable part
    cut to :data:`SLUG_CHARS` characters plus ``-h`` and 10 hex digits of the
    label's sha256: two labels differing only in characters that the readable
    part drops (``büro`` and ``båro``) never share a file, and no name is too
    long for the file system.
    """
    safe = re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_.") or "x"
    if safe == text and len(text) <= SLUG_CHARS and _HASHED.fullmatch(text) is None:
        return text
    digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:10]
    return f"{safe[:SLUG_CHARS].rstrip('_.-')}-h{digest}"


def pyplot() -> Any:
    """matplotlib.pyplot on the headless Agg backend (imported on first use: it is slow to import).

    Every figure of the reports is made through here, so this is also where the process's math-text
    parses start being shared across figures (:func:`~albot1.report.mathtext_memo.share_parsed_math`) and
    an axes' ticks start being worked out once per layout pass and per draw
    (:func:`~albot1.report.tick_memo.share_tick_updates`).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    share_parsed_math()
    share_tick_updates()
    return plt


def method_colors(labels: Iterable[str]) -> dict[str, str]:
    """method label -> its colour, the same in every report and figure (first-seen order of ``labels`` kept).

    The colour depends on the label alone, never on which other methods a
    report holds: the project's own method labels have fixed, distinct
    colours (:data:`FIXED_COLORS`); any other label (a plugin, a preset
    variant, another system's output) gets one of :data:`PALETTE` chosen by
    the sha256 of its text, so two such labels may share a colour (the
    legend still tells them apart).
    """
    return {label: method_color(label) for label in dict.fromkeys(labels)}


def method_color(label: str) -> str:
    """The colour of one method label (see :func:`method_colors`)."""
    if label in FIXED_COLORS:
        return FIXED_COLORS[label]
    digest = int.from_bytes(hashlib.sha256(label.encode("utf-8")).digest()[:8], "big")
    return PALETTE[digest % len(PALETTE)]


def representative(records: Iterable[CellRecord]) -> dict[str, CellRecord]:
    """method label -> its representative completed run (see module doc)."""
    best: dict[str, CellRecord] = {}
    for rec in records:
        if rec.status != "done":
            continue
        c = rec.cell
        current = best.get(c.method_label)
        rank = (c.degradation != "none", c.seed)
        if current is None or rank < (current.cell.degradation != "none", current.cell.seed):
            best[c.method_label] = rec
    return best


def has_reference(reference: NDArray[np.float64] | None, poses: NDArray[np.float64]) -> bool:
    """Whether ``reference`` can frame ``poses`` (one reference pose per estimated pose, at least two)."""
    return reference is not None and len(reference) == len(poses) and len(poses) >= 2


def aligned_poses(poses: NDArray[np.float64], reference: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """``poses`` rigidly aligned to ``reference`` (as the ATE aligns them), or as they are without one."""
    if reference is None or not has_reference(reference, poses):
        return poses
    try:
        aligned, _ = align(poses, reference, "rigid")
    except MetricsError:  # a degenerate trajectory: a picture is still useful unaligned; the metrics say why
        return poses
    return np.asarray(aligned)


def transform_points(
    points: NDArray[np.float64], poses: NDArray[np.float64], reference: NDArray[np.float64] | None
) -> NDArray[np.float64]:
    """Apply to map points the rigid motion that aligns ``poses`` onto ``reference``."""
    if reference is None or not has_reference(reference, poses) or not len(points):
        return points
    try:
        transform = rigid_transform(poses, reference)
    except MetricsError:  # see aligned_poses
        return points
    return np.asarray(se2.transform_points(transform, points))


@dataclass(frozen=True)
class Extent:
    """An axis-aligned box in metres, padded to a drawable shape."""

    x0: float
    x1: float
    y0: float
    y1: float

    @property
    def width(self) -> float:
        return self.x1 - self.x0

    @property
    def height(self) -> float:
        return self.y1 - self.y0

    @property
    def aspect(self) -> float:
        return self.width / self.height

    @classmethod
    def around(cls, arrays: Sequence[NDArray[np.float64]], pad_fraction: float = 0.04) -> Extent:
        """The box around every ``(N, >=2)`` array's x, y, padded, and widened to at most :data:`MAX_PANEL_ASPECT`."""
        xy = [np.asarray(a, dtype=float)[:, :2] for a in arrays if len(a)]
        pts = np.concatenate(xy) if xy else np.zeros((1, 2))
        pts = pts[np.isfinite(pts).all(axis=1)]
        if not len(pts):
            pts = np.zeros((1, 2))
        (x0, y0), (x1, y1) = pts.min(axis=0), pts.max(axis=0)
        pad = max(x1 - x0, y1 - y0, 1.0) * pad_fraction
        x0, x1, y0, y1 = x0 - pad, x1 + pad, y0 - pad, y1 + pad
        w, h = x1 - x0, y1 - y0
        if w / h > MAX_PANEL_ASPECT:
            grow = (w / MAX_PANEL_ASPECT - h) / 2
            y0, y1 = y0 - grow, y1 + grow
        elif h / w > MAX_PANEL_ASPECT:
            grow = (h / MAX_PANEL_ASPECT - w) / 2
            x0, x1 = x0 - grow, x1 + grow
        return cls(float(x0), float(x1), float(y0), float(y1))

    def apply(self, ax: Any) -> None:
        ax.set_xlim(self.x0, self.x1)
        ax.set_ylim(self.y0, self.y1)
        ax.set_aspect("equal")


def robust_points(points: NDArray[np.float64], keep: float = 0.995) -> NDArray[np.float64]:
    """The points inside the central ``keep`` quantile box (a map's few far-away returns would shrink the picture)."""
    if len(points) < 50:
        return points
    low = np.quantile(points[:, :2], (1 - keep) / 2, axis=0)
    high = np.quantile(points[:, :2], 1 - (1 - keep) / 2, axis=0)
    inside = ((points[:, :2] >= low) & (points[:, :2] <= high)).all(axis=1)
    return points[inside]


def panel_layout(
    extent: Extent, panels: int, *, panel_max_in: float = 5.2, extra_height_in: float = 1.1
) -> tuple[int, int, tuple[float, float]]:
    """(rows, columns, figure size in inches) for ``panels`` panels showing ``extent`` at equal scale.

    The column count makes the whole figure closest to a 4:3 landscape
    page without leaving many panels empty; each panel is as large as the
    width limit allows, its height set by the data's aspect ratio (so a
    corridor gets wide, flat panels). ``extra_height_in`` leaves room for
    titles and the legend below.
    """
    aspect = extent.aspect
    best: tuple[float, int] | None = None
    for cols in range(1, panels + 1):
        rows = math.ceil(panels / cols)
        empty = rows * cols - panels
        score = abs(math.log((cols * aspect) / rows / (4 / 3))) + 0.5 * empty / panels
        if best is None or score < best[0] - 1e-9:
            best = (score, cols)
    assert best is not None
    cols = best[1]
    rows = math.ceil(panels / cols)
    width = min(MAX_WIDTH_IN / cols, panel_max_in * max(1.0, aspect))
    height = width / aspect
    if height > panel_max_in * 1.3:
        height = panel_max_in * 1.3
        width = height * aspect
    return rows, cols, (max(4.0, cols * width + 0.9), rows * (height + 0.45) + extra_height_in)


def label_grid(axes: Any, used: int) -> None:
    """Hide the unused panels of a grid; label x (m) under the lowest panel of each column, y (m) on the left."""
    rows, cols = axes.shape
    for k, ax in enumerate(axes.flat):
        if k >= used:
            ax.set_visible(False)
    for c in range(cols):
        lowest = max((r for r in range(rows) if r * cols + c < used), default=None)
        if lowest is not None:
            axes[lowest, c].set_xlabel("x (m)", fontsize=8)
            axes[lowest, c].xaxis.set_tick_params(labelbottom=True)
    for r in range(rows):
        axes[r, 0].set_ylabel("y (m)", fontsize=8)


def log_floor(series: Iterable[Iterable[float]], *, decades: float = 2.0) -> float | None:
    """A log axis's lower limit when the data span more than ``decades`` decades, else None (linear).

    Values near zero (a perfect-odometry error of 1e-10 m) would stretch a
    log axis over ten decades of nothing: the floor is 1e-4 of the largest
    value, and values under it are drawn at the floor (and marked so by the
    caller). Data whose positive values span less than ``decades`` decades
    are drawn on a linear axis.
    """
    values = np.asarray([v for s in series for v in s], dtype=float)
    values = values[np.isfinite(values)]
    if not len(values) or values.max() <= 0:
        return None
    high = float(values.max())
    floor = high * 1e-4
    above = values[values >= floor]
    low = float(above.min()) if len(above) else high
    if high / max(low, floor) < 10**decades:
        return None
    return max(floor, low / 2)


def value_axis(ax: Any, floor: float | None, clipped: list[str], unit: str) -> None:
    """A log axis from ``floor`` (noting the series drawn at the floor), or a linear one from zero.

    The note is wrapped and left out of the layout: a long one (every method of a log clipped) once made
    constrained layout shrink the axes to nothing; more than three series are counted, not listed.
    """
    if floor is None:
        ax.set_ylim(bottom=0)
        return
    ax.set_yscale("log")
    ax.set_ylim(bottom=floor * 0.8)
    if clipped:
        which = ", ".join(clipped) if len(clipped) <= 3 else f"{len(clipped)} series"
        note = textwrap.fill(f"values below {floor:.2g} {unit} drawn at {floor:.2g} ({which})", width=48)
        ax.text(0.01, 0.01, note, transform=ax.transAxes, fontsize=7, color="0.3", va="bottom", in_layout=False)


def save(fig: Figure, png: Path) -> Path:
    """Write ``png`` and its vector twin (same stem, ``.svg``); close the figure; return the PNG's path.

    The figure is laid out once, by the PNG's own draw, and the SVG reuses that layout. ``savefig`` would
    lay it out twice per format (a dry draw, then the real one, each running the constrained layout):
    four passes where two do (docs/benchmarking.md, "The report half, laid out once"). The PNG's pixels
    are those ``savefig(dpi=DPI)`` gives; the SVG's boxes are placed from text measured at the PNG's
    resolution instead of at 72 dpi (boxes up to about 1 pt apart). Its dense layers (:func:`dense`) are
    embedded as images at :data:`DPI`, as the point maps already were.
    """
    import matplotlib
    from matplotlib.backends.backend_svg import FigureCanvasSVG

    plt = pyplot()
    write_png(fig, png)
    fig.set_layout_engine("none")  # keep the positions just computed (the engine would measure again)
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "albot1"}):  # text stays editable text
        FigureCanvasSVG(fig).print_svg(  # type: ignore[no-untyped-call]
            png.with_suffix(f".{VECTOR_FORMAT}"), metadata={"Date": None}
        )
    plt.close(fig)
    return png


def write_png(fig: Figure, png: Path) -> None:
    """Write ``fig`` as ``png`` at :data:`DPI` in one draw (the pixels of ``savefig(png, dpi=DPI)``).

    The layout engine runs inside that draw; ``savefig`` draws the figure once more before it, to lay it out.
    Compressed at zlib level :data:`~albot1.report.tight_png.PNG_COMPRESS_LEVEL` as the run previews are,
    not Pillow's default 6: the same pixels in less encoding time (docs/benchmarking.md, "Session 24").
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig.set_dpi(DPI)
    pil_kwargs = {"compress_level": PNG_COMPRESS_LEVEL}
    FigureCanvasAgg(fig).print_png(png, pil_kwargs=pil_kwargs)  # type: ignore[no-untyped-call]


def dense(artist: Any) -> Any:
    """Mark ``artist`` (a collection of thousands of segments) to be drawn as an image in the SVG twin.

    Written as vectors, each segment is an SVG element of its own: most of the file and of its writing
    time. The PNG is unchanged (it is an image anyway). Returns ``artist``.
    """
    artist.set_rasterized(True)
    return artist


def vector_of(png: Path) -> Path:
    """The vector twin of a PNG written by :func:`save`."""
    return png.with_suffix(f".{VECTOR_FORMAT}")
