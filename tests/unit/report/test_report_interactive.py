"""The interactive view of index.html (albot1.report.interactive, interactive_page), on a small synthetic store.

The results folder is built by hand (dead reckoning on a 60-pose loop, one
run with a line map, one dataset without reference poses) so no bench run is
needed. The browser test drives Debian's ``chromium`` headless over the
DevTools protocol on a pipe (no library, no port), with every network
request refused, and is skipped with the reason when chromium is absent.
"""

from __future__ import annotations

import base64
import json
import math
import os
import re
import shutil
import subprocess
from dataclasses import replace
from pathlib import Path
from typing import Any

import headless_chromium
import numpy as np
import pytest
from loop_sequence import loop

from albot1.bench.grid import Cell, GridPlan
from albot1.bench.store import ResultsStore
from albot1.contract import MapData
from albot1.data.trajectory import read_tum
from albot1.geometry import se2
from albot1.metrics.alignment import align
from albot1.metrics.ate import position_errors
from albot1.report.collect import collect
from albot1.report.html import INDEX_HTML
from albot1.report.index import build_report
from albot1.report.interactive import MAX_POSES, dataset_figure, figure_json, shown_indices, stored_errors
from albot1.report.interactive_page import VIEWS_DIR, write_views
from albot1.report.map_plots import occupancy
from albot1.report.plots import Extent, method_colors
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

SEGMENTS = np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 1.0, 2.0], [-3.0, 4.0, 5.0, 6.5]])


def _cell(dataset: str, key: str, label: str, degradation: str, seed: int) -> Cell:
    return Cell("tiny", dataset, dataset, "odometry", label, "default", degradation, seed, key, "v", 60.0, 100.0)


@pytest.fixture(scope="module")
def results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Dataset ``loop``: ``noisy`` (a point map), ``lines`` (a line map); dataset ``bare``: no reference poses."""
    root = tmp_path_factory.mktemp("results") / "tiny"
    store = ResultsStore(root)
    store.runs.mkdir(parents=True)
    cells = []
    noisy = run_method("odometry", loop("loop", True), degradation="gauss:0.05:1", seed=0)
    lines = replace(
        run_method("odometry", loop("loop", True), degradation="gauss:0.05:1", seed=1), map=MapData(segments=SEGMENTS)
    )
    bare = run_method("odometry", loop("bare", False), degradation="gauss:0.05:1", seed=0)
    for result, dataset, label in ((noisy, "loop", "noisy"), (lines, "loop", "lines"), (bare, "bare", "noisy")):
        run_dir = write_run(result, store.runs)
        evaluate_run(run_dir)
        cells.append(_cell(dataset, run_dir.name, label, result.degradation, result.seed))
    plan = GridPlan("tiny", None, "A tiny grid.", cells, [], [], {}, [0, 1], ["gauss:0.05:1"], {})
    store.write_plan(plan)
    return root


@pytest.fixture(scope="module")
def report(results: Path) -> Path:
    return build_report(results, results.parent / "report").parent


def _records(results: Path, dataset: str) -> list[Any]:
    return [r for r in collect(results)[1] if r.cell.dataset_label == dataset]


def _files(run_dir: Path) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
    """The run folder's trajectory, reference and ate block, read back independently of the report."""
    poses = read_tum(run_dir / "trajectory.tum")[1]
    reference = read_tum(run_dir / "reference.tum")[1]
    return poses, reference, json.loads((run_dir / "metrics.json").read_text())["ate"]


def _array(value: Any) -> np.ndarray:
    """A plotly JSON array (a list, or a typed ``{"dtype", "bdata", "shape"}`` one) as numpy."""
    if isinstance(value, dict):
        flat = np.frombuffer(base64.b64decode(value["bdata"]), dtype=np.dtype(value["dtype"]))
        shape = value.get("shape")
        return flat.reshape([int(s) for s in str(shape).split(",")]) if shape else flat
    return np.asarray([math.nan if v is None else v for v in value], dtype=float)


def test_shown_indices_keep_every_pose_up_to_the_limit_then_a_stride_the_last_and_the_worst() -> None:
    assert shown_indices(5, None).tolist() == [0, 1, 2, 3, 4]
    assert len(shown_indices(MAX_POSES, None)) == MAX_POSES
    errors = np.zeros(25)
    errors[13] = 1.0
    assert shown_indices(25, errors, limit=7).tolist() == [0, 5, 10, 13, 15, 20, 24]
    assert shown_indices(25, None, limit=7).tolist() == [0, 5, 10, 15, 20, 24]


def test_the_stored_errors_are_the_ate_metrics_per_pose_errors_of_the_run_folder(results: Path) -> None:
    for rec in _records(results, "loop"):
        poses, reference, ate = _files(rec.run_dir)
        errors, note = stored_errors(rec)
        assert note is None and errors is not None
        expected = position_errors(poses, reference, ate["alignment"])
        assert np.array_equal(errors, expected)
        assert float(np.sqrt(np.mean(errors * errors))) == ate["rmse_m"]  # the table's ATE, to the last bit
        assert float(errors.max()) == ate["max_m"] and float(errors.max()) > 0.01


def test_the_figure_carries_each_poses_index_time_and_stored_error_exactly(results: Path) -> None:
    records = _records(results, "loop")
    colors = method_colors(r.cell.method_label for r in records)
    figure = dataset_figure(records, "loop", colors)
    assert figure is not None and figure["notes"] == []  # every method has a map and errors: nothing to note
    traces = {t["name"]: t for t in figure["data"]}
    assert list(traces) == [
        "reference",
        "noisy map (occupied 0.05 m cells)",
        "lines map (3 lines)",
        "noisy [gauss:0.05:1, seed 0]",
        "lines [gauss:0.05:1, seed 1]",
    ]
    top = 0.0
    for label, rec in ((r.cell.method_label, r) for r in records):
        poses, reference, ate = _files(rec.run_dir)
        trace = traces[f"{label} [gauss:0.05:1, seed {rec.cell.seed}]"]
        expected = position_errors(poses, reference, "rigid")
        aligned, _ = align(poses, reference, "rigid")
        assert np.array_equal(trace["customdata"][:, 0], np.arange(60.0))
        assert np.array_equal(trace["customdata"][:, 1], 10.0 + np.arange(60.0))
        assert np.array_equal(trace["customdata"][:, 2], expected)
        assert np.array_equal(trace["marker"]["color"], expected) and trace["marker"]["coloraxis"] == "coloraxis"
        assert np.array_equal(trace["x"], aligned[:, 0]) and np.array_equal(trace["y"], aligned[:, 1])
        assert trace["line"]["color"] == colors[label]
        top = max(top, float(expected.max()))
    assert figure["layout"]["coloraxis"]["cmax"] == top and figure["layout"]["coloraxis"]["cmin"] == 0.0
    # the line map is moved by the same rigid motion as its trajectory; gaps (NaN) between segments
    lines_rec = next(r for r in records if r.cell.method_label == "lines")
    poses, reference, _ = _files(lines_rec.run_dir)
    _, transform = align(poses, reference, "rigid")
    ends = se2.transform_points(transform, SEGMENTS.reshape(-1, 2)).reshape(-1, 2, 2)
    line_map = traces["lines map (3 lines)"]
    assert np.array_equal(line_map["x"][0::3], ends[:, 0, 0]) and np.array_equal(line_map["y"][1::3], ends[:, 1, 1])
    assert np.isnan(line_map["x"][2::3]).all() and len(line_map["x"]) == 9
    # the first method's map is shown, the other a legend click away; the reference is dashed and not hovered
    assert traces["noisy map (occupied 0.05 m cells)"]["visible"] is True and line_map["visible"] == "legendonly"
    assert traces["reference"]["line"]["dash"] == "dash" and traces["reference"]["hoverinfo"] == "skip"
    # the point map: one byte per cell of the static figure's occupancy grid, in the same aligned frame
    noisy_rec = next(r for r in records if r.cell.method_label == "noisy")
    poses, reference, _ = _files(noisy_rec.run_dir)
    _, transform = align(poses, reference, "rigid")
    points = se2.transform_points(transform, noisy_rec.stored_run().load_map().points)
    extent = Extent(figure["layout"]["xaxis"]["range"][0], figure["layout"]["xaxis"]["range"][1],
                    figure["layout"]["yaxis"]["range"][0], figure["layout"]["yaxis"]["range"][1])  # fmt: skip
    image, cell = occupancy(points, extent)
    grid = traces["noisy map (occupied 0.05 m cells)"]
    assert grid["z"].dtype == np.uint8 and np.array_equal(grid["z"], (~np.ma.getmaskarray(image)).astype(np.uint8))
    assert grid["x0"] == extent.x0 + cell / 2 and grid["dx"] == cell and int(grid["z"].sum()) > 20
    assert figure["layout"]["yaxis"]["scaleanchor"] == "x" and figure["layout"]["dragmode"] == "pan"


def test_the_figure_json_keeps_every_error_bit_for_bit(results: Path) -> None:
    records = _records(results, "loop")
    figure = dataset_figure(records, "loop", method_colors(["noisy", "lines"]))
    assert figure is not None
    decoded = json.loads(figure_json(figure))
    trajectory = next(t for t in decoded["data"] if t["name"].startswith("noisy ["))
    custom = _array(trajectory["customdata"])
    assert custom.shape == (60, 3)
    original = next(t for t in figure["data"] if t["name"].startswith("noisy ["))
    assert np.array_equal(custom, original["customdata"])


def test_a_run_edited_after_scoring_shows_no_error_rather_than_another_one(results: Path, tmp_path: Path) -> None:
    copy = tmp_path / "tiny"
    shutil.copytree(results, copy, symlinks=True)
    rec = next(r for r in _records(copy, "loop") if r.cell.method_label == "noisy")
    stamps, poses = read_tum(rec.run_dir / "trajectory.tum")
    lines = (rec.run_dir / "trajectory.tum").read_text().splitlines()
    fields = lines[-1].split()
    fields[1] = repr(float(fields[1]) + 0.5)  # the last pose moved by 0.5 m
    (rec.run_dir / "trajectory.tum").write_text("\n".join([*lines[:-1], " ".join(fields)]) + "\n")
    errors, note = stored_errors(rec)
    assert errors is None and note is not None
    assert note.startswith("no per-pose error: the run folder's trajectory gives ATE RMSE ") and "metrics.json" in note
    figure = dataset_figure(_records(copy, "loop"), "loop", method_colors(["noisy", "lines"]))
    assert figure is not None and any(n.startswith("noisy: no per-pose error") for n in figure["notes"])
    trace = next(t for t in figure["data"] if t["name"].startswith("noisy ["))
    assert trace["customdata"].shape == (60, 2) and "no error" in trace["hovertemplate"]
    assert len(stamps) == len(poses) == 60


def test_without_reference_poses_each_run_is_drawn_in_its_own_frame_and_says_why_no_error(results: Path) -> None:
    records = _records(results, "bare")
    figure = dataset_figure(records, "bare", method_colors(["noisy"]))
    assert figure is not None
    assert figure["notes"] == ["noisy: no reference poses: drawn in its own frame, no error"]
    trace = next(t for t in figure["data"] if t["name"].startswith("noisy ["))
    poses = read_tum(records[0].run_dir / "trajectory.tum")[1]
    assert np.array_equal(trace["x"], poses[:, 0]) and "reference" not in [t["name"] for t in figure["data"]]
    assert "each in its own frame" in figure["layout"]["title"]["text"]


def test_views_are_written_once_and_rewritten_when_a_run_changes(results: Path, tmp_path: Path) -> None:
    records = collect(results)[1]
    colors = method_colors(r.cell.method_label for r in records)
    bundle, views = write_views(records, tmp_path, colors)
    assert bundle is not None and bundle.parent == tmp_path / VIEWS_DIR and bundle.stat().st_size > 1_000_000
    assert sorted(views) == ["bare", "loop"]
    stamp = {d: v.script.stat().st_mtime_ns for d, v in views.items()}
    _, again = write_views(records, tmp_path, colors)
    assert {d: v.script.stat().st_mtime_ns for d, v in again.items()} == stamp
    assert again["bare"].notes == views["bare"].notes
    changed = {**colors, "noisy": "#000000"}  # another colour: both datasets' figures are drawn again
    _, redrawn = write_views(records, tmp_path, changed)
    assert all(redrawn[d].script.stat().st_mtime_ns != stamp[d] for d in stamp)


def test_index_html_has_a_view_per_dataset_and_loads_plotly_from_the_report_folder(report: Path) -> None:
    page = (report / INDEX_HTML).read_text(encoding="utf-8")
    assert page.count('<div class="view"') == 2 and "Interactive view" in page
    sources = re.findall(r'<script src="([^"]+)"', page)
    assert sources[0].startswith(f"{VIEWS_DIR}/plotly-") and sources[0].endswith(".min.js")
    assert sorted(sources[1:]) == [f"{VIEWS_DIR}/bare.js", f"{VIEWS_DIR}/loop.js"]
    for source in sources:
        assert (report / source).is_file()
    assert "no reference poses: drawn in its own frame" in page
    scripts = " ".join((report / s).read_text(encoding="utf-8")[:200] for s in sources[1:])
    assert "window.ALBOT1_VIEWS" in scripts


# --- the browser test -------------------------------------------------------------------------------------------


class DevTools:
    """The DevTools protocol over ``--remote-debugging-pipe`` (fd 3 in, fd 4 out; NUL-separated JSON)."""

    def __init__(self, browser: str, profile: Path) -> None:
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()
        # every network request fails: the page must need none
        flags = [*headless_chromium.flags(profile), "--remote-debugging-pipe", "about:blank"]

        def plumb() -> None:  # in the child: the pipe ends at fds 3 and 4 (copied first: they may be 3 or 4 now)
            read_end, write_end = os.dup(to_browser_r), os.dup(from_browser_w)
            os.dup2(read_end, 3)
            os.dup2(write_end, 4)

        self.process = subprocess.Popen(
            [browser, *flags],
            pass_fds=(3, 4),  # kept open past the child's closing of inherited fds (which follows plumb)
            preexec_fn=plumb,  # noqa: PLW1509 (the protocol's fixed fd numbers)
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._buffer = b""
        self._next = 0
        self.session: str | None = None

    def call(self, method: str, params: dict[str, Any] | None = None, *, session: bool = True) -> dict[str, Any]:
        self._next += 1
        message: dict[str, Any] = {"id": self._next, "method": method, "params": params or {}}
        if session and self.session is not None:
            message["sessionId"] = self.session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        while True:
            while b"\0" not in self._buffer:
                chunk = os.read(self._from_browser, 1 << 16)
                if not chunk:
                    raise RuntimeError(f"chromium closed the pipe waiting for {method}")
                self._buffer += chunk
            raw, self._buffer = self._buffer.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("id") == self._next:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                result: dict[str, Any] = reply["result"]
                return result

    def open(self, url: str) -> None:
        target = self.call("Target.createTarget", {"url": "about:blank"}, session=False)["targetId"]
        attached = self.call("Target.attachToTarget", {"targetId": target, "flatten": True}, session=False)
        self.session = attached["sessionId"]
        self.call("Page.enable")
        self.call("Page.navigate", {"url": url})
        self.evaluate("new Promise(function (ok) { if (document.readyState === 'complete') { ok(1); } "
                      "else { window.addEventListener('load', function () { ok(1); }); } })")  # fmt: skip

    def evaluate(self, expression: str) -> Any:
        reply = self.call("Runtime.evaluate", {"expression": expression, "awaitPromise": True, "returnByValue": True})
        if "exceptionDetails" in reply:
            raise RuntimeError(f"{expression[:80]}...: {reply['exceptionDetails']}")
        return reply["result"].get("value")

    def close(self) -> None:
        try:
            self.call("Browser.close", session=False)
        except (RuntimeError, OSError):
            pass
        try:
            self.process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        os.close(self._to_browser)
        os.close(self._from_browser)


#: Draws the ``loop`` view, then returns the pixel position (page coordinates) and data of every pose of ``noisy``.
POSES_JS = """
albot1ShowView("loop").then(function (gd) {
  var i = gd.data.findIndex(function (t) { return t.name.indexOf("noisy [") === 0; });
  var full = gd._fullData[i], xa = gd._fullLayout.xaxis, ya = gd._fullLayout.yaxis;
  var box = gd.getBoundingClientRect();
  var n = full.x.length, out = [];
  for (var k = 0; k < n; k++) {
    out.push({px: box.left + xa._offset + xa.l2p(full.x[k]), py: box.top + ya._offset + ya.l2p(full.y[k]),
              index: full.customdata[k][0], error: full.customdata[k][2]});
  }
  return {lines: gd.querySelectorAll("g.trace.scatter").length, images: gd.querySelectorAll("g.hm image").length,
          points: gd.querySelectorAll("g.trace.scatter path.point").length, poses: out};
})
"""


@pytest.mark.slow
@pytest.mark.skipif(headless_chromium.browser() is None, reason=headless_chromium.NO_BROWSER)
def test_chromium_offline_renders_the_view_and_hovering_a_pose_shows_its_stored_error(
    report: Path, results: Path, tmp_path: Path
) -> None:
    browser = headless_chromium.browser()
    assert browser is not None
    rec = next(r for r in _records(results, "loop") if r.cell.method_label == "noisy")
    poses, reference, ate = _files(rec.run_dir)
    stored = position_errors(poses, reference, ate["alignment"])
    tools = DevTools(browser, tmp_path / "profile")
    try:
        tools.open((report / INDEX_HTML).resolve().as_uri())
        assert tools.evaluate("typeof window.Plotly") == "object"  # loaded from the report folder, offline
        drawn = tools.evaluate(POSES_JS)
        # drawn: the reference and two trajectories (the line map is legend-only), their 120 pose markers, and
        # the point map's occupied cells as an image
        assert drawn["lines"] == 3 and drawn["points"] == 120 and drawn["images"] == 1
        assert [p["index"] for p in drawn["poses"]] == list(range(60))
        assert [p["error"] for p in drawn["poses"]] == stored.tolist()
        # the pose farthest from every other method's poses: the mouse over it can only mean this pose
        others = np.array([[p["px"], p["py"]] for p in drawn["poses"]])
        chosen = int(np.argmax(stored))
        target = drawn["poses"][chosen]
        tools.evaluate(f"window.scrollTo(0, {target['py']} - 400)")
        scroll = tools.evaluate("window.scrollY")
        x, y = target["px"], target["py"] - scroll
        for dx in (3.0, 0.0):  # a move onto the point from beside it, as a mouse does
            tools.call("Input.dispatchMouseEvent", {"type": "mouseMoved", "x": x + dx, "y": y})
        label = tools.evaluate(
            "new Promise(function (ok) { setTimeout(function () { var t = document.querySelector("
            "'div.view[data-view=\"loop\"] .hoverlayer .hovertext'); ok(t ? t.textContent : null); }, 300); })"
        )
        assert others.shape == (60, 2)
    finally:
        tools.close()
    assert label is not None, "no hover label appeared"
    found = re.search(r"pose (\d+), t = [0-9.]+ sAPE ([0-9.eE+-]+) m", label)
    assert found is not None, label
    assert int(found.group(1)) == chosen
    assert float(found.group(2)) == stored[chosen]  # the stored error, unrounded
