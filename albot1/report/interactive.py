"""The interactive view of a dataset in ``index.html``: trajectories and maps over the reference, error on hover.

Why: the static figures show one scale and one crop; a reader checking where
a method goes wrong wants to zoom into a corner of the map, pan along the
route and read the error of one pose. The view is a plotly figure (plotly's
own ``plotly.min.js``, written once into the report folder, so the page needs
no network) with, per dataset:

* the reference trajectory (black, dashed);
* each method's representative run (:func:`albot1.report.plots.representative`,
  the run the static figures show), in the method's colour, its poses marked
  and coloured by their absolute position error on one colour scale shared by
  every method of the figure;
* each method's map in the same frame (Albot1's line surfaces as lines, a
  point map as its occupied cells, as the static map figure draws it); one
  method's map is shown, the others are a click on their legend entry away.

Frames: an estimate and its map are moved by the alignment its
``metrics.json`` ``ate`` block records (rigid for every bench run), so the
picture and the table's ATE agree; without reference poses each method is
drawn in its own frame and no error is shown.

**The error on hover is the stored one.** It is the per-pose position error
whose RMSE is the run's ATE: :func:`albot1.metrics.ate.position_errors` (the
function the ``ate`` metric summarises) on the run folder's
``trajectory.tum`` and ``reference.tum`` with the alignment recorded in its
``metrics.json``. The report checks that these errors give the recorded ATE
RMSE exactly; when they do not (the run folder was edited after it was
scored) the view says so and shows no errors rather than different ones.
The value is carried at full double precision (plotly's binary arrays) and
the hover label prints it unrounded.

Long trajectories are thinned for display to at most :data:`MAX_POSES` poses
(every k-th pose, the last one and the pose of largest error); every pose
shown carries its own index and its own stored error, never an interpolated
one.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.geometry import se2
from albot1.metrics.alignment import align
from albot1.metrics.ate import position_errors
from albot1.metrics.errors import MetricsError
from albot1.metrics.measures.ate import METRIC as ATE
from albot1.metrics.stats import summarize
from albot1.report.collect import CellRecord
from albot1.report.map_plots import occupancy
from albot1.report.plots import REFERENCE_COLOR, Extent, has_reference, representative, robust_points
from albot1.report.tuning import LEGEND, marked, record_held_in

#: The most poses of one trajectory drawn (and hoverable); longer ones are thinned (module doc).
MAX_POSES = 2000
#: Relative tolerance between the ATE RMSE of the recomputed per-pose errors and ``metrics.json``'s.
RMSE_TOLERANCE = 1e-9
ERROR_COLORSCALE = "Viridis"
MAP_COLOR = "#8c8c8c"
LINE_MAP_COLOR = "#262626"


@dataclass(frozen=True)
class RunView:
    """One method's run as the view draws it: poses in the figure's frame, and its per-pose errors or why none."""

    label: str
    tag: str
    timestamps: NDArray[np.float64]
    xy: NDArray[np.float64]
    transform: NDArray[np.float64] | None  # the alignment applied (pose), None when drawn in its own frame
    errors: NDArray[np.float64] | None
    note: str | None  # why no errors are shown, or None
    #: the run's held-in mark (:func:`albot1.report.tuning.record_held_in`; None: tuning unknown)
    held_in: bool | None = None

    @property
    def name(self) -> str:
        """The method's label as its traces are named: with the held-in mark when its values were tuned here."""
        return marked(self.label, self.held_in)


def shown_indices(count: int, errors: NDArray[np.float64] | None, limit: int = MAX_POSES) -> NDArray[np.int64]:
    """The indices of the poses drawn: all up to ``limit``, else every k-th, the last and the largest error's."""
    if count <= limit:
        return np.arange(count, dtype=np.int64)
    step = math.ceil(count / (limit - 2))
    keep = [np.arange(0, count, step, dtype=np.int64), np.array([count - 1], dtype=np.int64)]
    if errors is not None and len(errors):
        keep.append(np.array([int(np.argmax(errors))], dtype=np.int64))
    return np.unique(np.concatenate(keep))


def stored_errors(rec: CellRecord) -> tuple[NDArray[np.float64] | None, str | None]:
    """The run's per-pose ATE position errors as its ``metrics.json`` was computed (module doc), or why none."""
    run = rec.stored_run()
    if run.reference is None or not has_reference(run.reference, run.poses):
        return None, "no reference poses: drawn in its own frame, no error"
    block = rec.metrics.get(ATE) if rec.metrics is not None else None
    if block is None:
        reason = rec.metrics.reason(ATE.name) if rec.metrics is not None else "no metrics.json"
        return None, f"no ATE: {reason}"
    try:
        errors = position_errors(run.poses, run.reference, block.alignment, block.alignment_transform.n_to_align)
    except MetricsError as exc:
        return None, f"no per-pose error: {exc}"
    rmse = summarize(errors, ddof=0)["rmse"]
    if not math.isclose(rmse, block.rmse_m, rel_tol=RMSE_TOLERANCE, abs_tol=1e-15):
        return None, (
            f"no per-pose error: the run folder's trajectory gives ATE RMSE {rmse:.6g} m, its metrics.json "
            f"{block.rmse_m:.6g} m (edited after scoring? run albot1 evaluate again)"
        )
    return errors, None


def run_view(label: str, rec: CellRecord) -> RunView:
    """``rec``'s run in the figure's frame: aligned as its ATE was (when it has one), with its stored errors."""
    run = rec.stored_run()
    errors, note = stored_errors(rec)
    tag = f"[{rec.cell.degradation}, seed {rec.cell.seed}]"
    held = record_held_in(rec)
    if errors is None or run.reference is None:
        return RunView(label, tag, run.timestamps, run.poses[:, :2], None, None, note, held)
    block = rec.metrics.get(ATE) if rec.metrics is not None else None
    assert block is not None  # stored_errors returned errors
    aligned, transform = align(run.poses, run.reference, block.alignment, block.alignment_transform.n_to_align)
    return RunView(label, tag, run.timestamps, np.asarray(aligned)[:, :2], np.asarray(transform), errors, None, held)


def _map_traces(
    view: RunView, rec: CellRecord, extent: Extent, visible: bool
) -> tuple[list[dict[str, Any]], str | None]:
    """The traces of one method's map (lines, occupied cells) in the figure's frame, or a note why none."""
    if rec.cell.trajectory is not None:
        return [], "no map: an external trajectory file"
    data = rec.stored_map()

    def frame(points: NDArray[np.float64]) -> NDArray[np.float64]:
        return points if view.transform is None else np.asarray(se2.transform_points(view.transform, points))

    traces: list[dict[str, Any]] = []
    common = {"legendgroup": f"map:{view.label}", "visible": True if visible else "legendonly", "hoverinfo": "skip"}
    if data.segments is not None and len(data.segments):
        ends = frame(np.asarray(data.segments, dtype=float).reshape(-1, 2)).reshape(-1, 2, 2)
        # one polyline with a gap (NaN) after each segment: one trace, however many segments
        xs = np.column_stack([ends[:, 0, 0], ends[:, 1, 0], np.full(len(ends), np.nan)]).ravel()
        ys = np.column_stack([ends[:, 0, 1], ends[:, 1, 1], np.full(len(ends), np.nan)]).ravel()
        traces.append(
            {
                "type": "scatter",
                "mode": "lines",
                "x": xs,
                "y": ys,
                "name": f"{view.name} map ({len(ends)} lines)",
                "line": {"color": LINE_MAP_COLOR, "width": 1},
                **common,
            }
        )
    if data.points is not None and len(data.points):
        points = frame(np.asarray(data.points, dtype=float).reshape(-1, 2))
        image, cell = occupancy(points, extent)
        # 1 byte per cell (0: empty, drawn transparent): a tenth of a float image in the page
        z = (~np.ma.getmaskarray(image)).astype(np.uint8)
        traces.append(
            {
                "type": "heatmap",
                "z": z,
                "zmin": 0,
                "zmax": 1,
                "x0": extent.x0 + cell / 2,
                "dx": cell,
                "y0": extent.y0 + cell / 2,
                "dy": cell,
                "colorscale": [[0, "rgba(0,0,0,0)"], [1, MAP_COLOR]],
                "showscale": False,
                "showlegend": True,
                "opacity": 0.7,
                "name": f"{view.name} map (occupied {cell:.2g} m cells)",
                **common,
            }
        )
    if not traces:
        return [], "no map: the run's map is empty"
    return traces, None


def _extent(views: list[RunView], records: dict[str, CellRecord], reference: NDArray[np.float64] | None) -> Extent:
    parts: list[NDArray[np.float64]] = [v.xy for v in views]
    if reference is not None:
        parts.append(reference[:, :2])
    for view in views:
        rec = records[view.label]
        if rec.cell.trajectory is not None:
            continue
        geometry = rec.map_geometry()
        if len(geometry) and view.transform is not None:
            geometry = np.asarray(se2.transform_points(view.transform, geometry))
        if len(geometry):
            parts.append(robust_points(geometry))
    return Extent.around(parts)


def dataset_figure(records: list[CellRecord], dataset: str, colors: dict[str, str]) -> dict[str, Any] | None:
    """The plotly figure (``data``, ``layout``, and ``notes`` for the page) of one dataset; None without runs."""
    runs = representative(records)
    if not runs:
        return None
    views = [run_view(label, rec) for label, rec in runs.items()]
    reference = None
    for rec in runs.values():
        run = rec.stored_run()
        if run.reference is not None and has_reference(run.reference, run.poses):
            reference = run.reference
            break
    extent = _extent(views, runs, reference)
    top = max((float(v.errors.max()) for v in views if v.errors is not None and len(v.errors)), default=0.0)
    top = top if top > 0 else 1.0
    data: list[dict[str, Any]] = []
    notes: list[str] = []
    if reference is not None:
        idx = shown_indices(len(reference), None)
        data.append(
            {
                "type": "scatter",
                "mode": "lines",
                "x": reference[idx, 0],
                "y": reference[idx, 1],
                "name": "reference",
                "line": {"color": REFERENCE_COLOR, "width": 1.5, "dash": "dash"},
                "hoverinfo": "skip",
            }
        )
    map_shown = False
    for view in views:
        traces, note = _map_traces(view, runs[view.label], extent, not map_shown)
        map_shown = map_shown or bool(traces)
        data += traces
        if note is not None:
            notes.append(f"{view.label}: {note}")
    for view in views:
        data.append(_trajectory_trace(view, colors.get(view.label, "#1f77b4")))
        if view.note is not None:
            notes.append(f"{view.label}: {view.note}")
        if len(view.xy) > MAX_POSES:
            notes.append(f"{view.label}: {len(shown_indices(len(view.xy), view.errors))} of {len(view.xy)} poses drawn")
    if any(v.held_in for v in views):
        notes.append(LEGEND)
    framed = any(v.transform is not None for v in views)
    frame = "aligned to the reference as for the ATE" if framed else "each in its own frame (no reference)"
    layout = {
        "title": {"text": f"{dataset}: trajectories and maps, {frame}", "font": {"size": 13}},
        "xaxis": {"title": {"text": "x (m)"}, "range": [extent.x0, extent.x1], "zeroline": False},
        "yaxis": {
            "title": {"text": "y (m)"},
            "range": [extent.y0, extent.y1],
            "scaleanchor": "x",
            "scaleratio": 1,
            "zeroline": False,
        },
        "hovermode": "closest",
        "dragmode": "pan",
        "legend": {"orientation": "h", "y": -0.12},
        "coloraxis": {
            "colorscale": ERROR_COLORSCALE,
            "cmin": 0.0,
            "cmax": top,
            "colorbar": {"title": {"text": "APE (m), one scale<br>for every method"}, "len": 0.8},
        },
        "margin": {"l": 60, "r": 20, "t": 50, "b": 40},
        "plot_bgcolor": "white",
        "height": 640,
    }
    return {"data": data, "layout": layout, "notes": notes}


def _trajectory_trace(view: RunView, color: str) -> dict[str, Any]:
    """A method's trajectory: its line in its colour, each pose shown a marker coloured by its stored error."""
    idx = shown_indices(len(view.xy), view.errors)
    if view.errors is not None:
        custom = np.column_stack([idx.astype(float), view.timestamps[idx], view.errors[idx]])
        marker: dict[str, Any] = {"size": 5, "color": view.errors[idx], "coloraxis": "coloraxis"}
        template = "pose %{customdata[0]}, t = %{customdata[1]:.3f} s<br>APE %{customdata[2]} m"
    else:
        custom = np.column_stack([idx.astype(float), view.timestamps[idx]])
        marker = {"size": 4, "color": color}
        template = "pose %{customdata[0]}, t = %{customdata[1]:.3f} s<br>no error (no reference)"
    name = html.escape(view.name)  # plotly reads the template as HTML
    return {
        "type": "scatter",
        "mode": "lines+markers",
        "x": view.xy[idx, 0],
        "y": view.xy[idx, 1],
        "customdata": custom,
        "name": f"{view.name} {view.tag}",
        "legendgroup": view.label,
        "line": {"color": color, "width": 1.5},
        "marker": marker,
        "hovertemplate": f"<b>{name}</b> {view.tag}<br>{template}<br>x %{{x:.3f}} m, y %{{y:.3f}} m<extra></extra>",
    }


def figure_json(figure: dict[str, Any]) -> str:
    """The figure as plotly JSON (validated by plotly; numeric arrays as exact binary arrays)."""
    import plotly.graph_objects as go
    import plotly.io as pio

    fig = go.Figure(data=figure["data"], layout=figure["layout"])
    return str(pio.to_json(fig, validate=True, pretty=False, engine="json"))


def write_plotly_js(folder: Path) -> Path:
    """``plotly-<version>.min.js`` in ``folder`` (once per plotly version): what the page draws with, offline."""
    import plotly
    from plotly.offline import get_plotlyjs

    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"plotly-{plotly.__version__}.min.js"
    if not path.is_file():
        from albot1.atomic import atomic_write

        atomic_write(path, lambda tmp: tmp.write_text(get_plotlyjs(), encoding="utf-8"))
    return path
