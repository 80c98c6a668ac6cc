"""``albot1 evaluate --plot DIR``: what ``evo_ape --plot`` and ``evo_traj --plot`` draw, for scored trajectories.

For the trajectories one ``evaluate`` call scores (a run folder, or a file
and any ``--plot-also`` files against the same reference), three figures,
each as PNG with an SVG twin (:func:`albot1.report.plots.save`):

* ``<name>-ape.png`` per trajectory: its poses rigidly aligned to the
  reference (as the ATE aligns them), coloured by the position error of
  each pose, over the dashed reference; every such figure of one call uses
  one colour scale (stated on the bar), so they compare;
* ``errors.png``: the per-pose position error against time since the first
  pose and against distance travelled along the reference, one line per
  trajectory;
* ``trajectories.png``: every trajectory over the reference in one axes
  (each in its own frame when there is no reference).

The per-pose error is :func:`albot1.metrics.ate.position_errors`, the
numbers whose RMSE is the ATE printed beside. Without reference poses only
``trajectories.png`` is drawn and the result says why the others are not.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.geometry import se2
from albot1.metrics.ate import position_errors
from albot1.report.plots import REFERENCE_COLOR, Extent, aligned_poses, has_reference, method_colors, pyplot, save, slug
from albot1.runs.scored import Scored

APE_COLORMAP = "viridis"


@dataclass(frozen=True)
class EvaluatePlots:
    """The figures written, and why the error figures are missing when they are (None: drawn)."""

    files: list[Path]
    missing: str | None


def _name(scored: Scored) -> str:
    return str(scored.header.get("method") or "trajectory")


def plot_scored(items: list[Scored], out: Path) -> EvaluatePlots:
    """Draw the figures of the module doc for ``items`` (first is the main one) into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    names = list(dict.fromkeys(_name(s) for s in items))
    colors = method_colors(names)
    framed = [s for s in items if s.reference is not None and has_reference(s.reference, s.poses)]
    files = [_trajectories(items, out / "trajectories.png", colors)]
    if not framed:
        return EvaluatePlots(files, "the dataset has no reference poses: no error figures")
    errors: dict[str, NDArray[np.float64]] = {}
    for s in framed:
        assert s.reference is not None
        errors[_name(s)] = np.asarray(position_errors(s.poses, s.reference, "rigid"), dtype=float)
    top = max(float(e.max()) for e in errors.values())
    top = top if top > 0 else 1.0
    for s in framed:
        files.append(_ape(s, errors[_name(s)], top, out / f"{slug(_name(s))}-ape.png"))
    files.append(_errors(framed, errors, colors, out / "errors.png"))
    return EvaluatePlots(files, None)


def _trajectories(items: list[Scored], path: Path, colors: dict[str, str]) -> Path:
    plt = pyplot()
    reference = next(
        (s.reference for s in items if s.reference is not None and has_reference(s.reference, s.poses)), None
    )
    lines = [(_name(s), aligned_poses(s.poses, s.reference)) for s in items]
    extent = Extent.around([xy for _, xy in lines] + ([reference] if reference is not None else []))
    fig, ax = plt.subplots(figsize=(8, 8 / max(0.5, min(2.0, extent.aspect))), layout="constrained")
    if reference is not None:
        ax.plot(reference[:, 0], reference[:, 1], color=REFERENCE_COLOR, lw=1.6, alpha=0.45, label="reference")
    for name, xy in lines:
        ax.plot(xy[:, 0], xy[:, 1], color=colors[name], lw=1.0, label=name)
    extent.apply(ax)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(alpha=0.25, lw=0.5)
    framing = "rigidly aligned to the reference" if reference is not None else "each in its own frame (no reference)"
    ax.set_title(f"{items[0].dataset}: trajectories, {framing}", fontsize=9)
    fig.legend(loc="outside lower center", ncols=min(len(lines) + 1, 4), fontsize=8, frameon=False)
    return save(fig, path)


def _ape(s: Scored, errors: NDArray[np.float64], top: float, path: Path) -> Path:
    from matplotlib.collections import LineCollection

    assert s.reference is not None
    plt = pyplot()
    xy = aligned_poses(s.poses, s.reference)
    extent = Extent.around([xy, s.reference])
    fig, ax = plt.subplots(figsize=(8, 8 / max(0.5, min(2.0, extent.aspect))), layout="constrained")
    ax.plot(s.reference[:, 0], s.reference[:, 1], color="0.55", lw=0.9, ls="--", label="reference")
    segments = np.stack([xy[:-1, :2], xy[1:, :2]], axis=1)
    lc = LineCollection(list(segments), cmap=APE_COLORMAP, linewidths=1.8)
    lc.set_array((errors[:-1] + errors[1:]) / 2)
    lc.set_clim(0.0, top)
    ax.add_collection(lc)
    bar = fig.colorbar(lc, ax=ax, shrink=0.85, pad=0.02)
    bar.set_label(f"APE (m), one scale for every figure of this call: 0 to {top:.3g} m", fontsize=8)
    extent.apply(ax)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    rmse = float(np.sqrt(np.mean(errors**2)))
    ax.set_title(
        f"{_name(s)} on {s.dataset}: position error per pose (rigid alignment), ATE RMSE {rmse:.4g} m, "
        f"max {float(errors.max()):.4g} m",
        fontsize=9,
    )
    return save(fig, path)


def _errors(framed: list[Scored], errors: dict[str, NDArray[np.float64]], colors: dict[str, str], path: Path) -> Path:
    plt = pyplot()
    fig, (by_time, by_distance) = plt.subplots(2, 1, figsize=(9, 6.5), layout="constrained")
    for s in framed:
        name = _name(s)
        assert s.reference is not None
        by_time.plot(s.timestamps - s.timestamps[0], errors[name], color=colors[name], lw=1.0, label=name)
        by_distance.plot(se2.cumulative_length(s.reference), errors[name], color=colors[name], lw=1.0)
    by_time.set_xlabel("time since the first pose (s)")
    by_distance.set_xlabel("distance travelled along the reference (m)")
    for ax in (by_time, by_distance):
        ax.set_ylabel("position error (m)")
        ax.set_ylim(bottom=0.0)
        ax.grid(alpha=0.3, lw=0.5)
    by_time.set_title(
        f"{framed[0].dataset}: absolute position error per pose (rigid alignment, as for the ATE)", fontsize=9
    )
    fig.legend(loc="outside right upper", fontsize=8, frameon=False)
    return save(fig, path)
