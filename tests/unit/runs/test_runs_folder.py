"""Run folders: round trip, atomic completion marker, TUM precision."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from albot1.contract import MapData, RunResult
from albot1.data.model import Frame, Relations, Scan, Sequence
from albot1.data.trajectory import read_tum, write_tum
from albot1.runs.errors import RunError
from albot1.runs.execute import run_method
from albot1.runs.folder import DONE, is_complete, read_run, run_key, write_run

ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 7)


def _sequence() -> Sequence:
    frames = [
        Frame(
            i,
            Scan(np.array([1, 2, np.nan, 3, 2, 1, 1], dtype=float), ANGLES, 100.0 + 0.5 * i, 30.0),
            np.array([0.3 * i, 0.1 * i, 0.05 * i]),
            np.array([0.3 * i, 0.1 * i, 0.05 * i]),
        )
        for i in range(8)
    ]
    relations = Relations(np.array([100.0]), np.array([101.0]), np.array([[0.6, 0.2, 0.1]]))
    return Sequence.from_frames("toy", frames, relations=relations)


def test_tum_round_trip_keeps_micrometres(tmp_path: Path) -> None:
    stamps = np.array([1.123456789, 2.5])
    poses = np.array([[1.0000004, -2.0, 3.1], [0.1234567, 5.0, -3.1]])
    write_tum(tmp_path / "t.tum", stamps, poses)
    s, p = read_tum(tmp_path / "t.tum")
    np.testing.assert_allclose(s, stamps, atol=1e-9)
    np.testing.assert_allclose(p, poses, atol=1e-8)


def test_write_and_read_back(tmp_path: Path) -> None:
    result = run_method("odometry", _sequence(), seed=1)
    run_dir = write_run(result, tmp_path)
    assert is_complete(run_dir)
    stored = read_run(run_dir)
    np.testing.assert_allclose(stored.poses, result.poses, atol=1e-8)
    assert stored.reference is not None and stored.relations is not None and len(stored.relations) == 1
    info = json.loads((run_dir / "result.json").read_text())
    assert info["scans"] == 8 and info["counters"]["views"] == 8
    assert set(info["timing"]) >= {"per_scan_ms_median", "per_scan_ms_p95", "total_s", "peak_mb"}
    assert run_dir.name == run_key("toy", "odometry", result.config, "none", 1, result.versions["code"])
    assert stored.load_map().points is not None


def test_segments_map_round_trip(tmp_path: Path) -> None:
    result = run_method("odometry", _sequence())
    result.map = MapData(
        segments=np.array([[0, 0, 1, 0], [1, 0, 1, 2.5]], dtype=float), segment_properties=[{"id": 1}, {"id": 2}]
    )
    stored = read_run(write_run(result, tmp_path))
    loaded = stored.load_map()
    np.testing.assert_allclose(loaded.segments, result.map.segments)
    assert loaded.segment_properties == [{"id": 1}, {"id": 2}]


def test_incomplete_folder_is_refused(tmp_path: Path) -> None:
    run_dir = write_run(run_method("odometry", _sequence()), tmp_path)
    (run_dir / DONE).unlink()
    with pytest.raises(RunError, match="incomplete"):
        read_run(run_dir)
    with pytest.raises(RunError, match="not a run folder"):
        read_run(tmp_path / "nothing")


def test_preview_is_drawn_by_the_callers_renderer_before_done(tmp_path: Path) -> None:
    seen: list[tuple[str, bool]] = []

    def renderer(result: RunResult, path: Path) -> None:
        seen.append((result.method, (path.parent / DONE).exists()))
        path.write_bytes(b"picture")

    run_dir = write_run(run_method("odometry", _sequence()), tmp_path, preview=renderer)
    assert seen == [("odometry", False)]
    assert (run_dir / "preview.png").read_bytes() == b"picture" and is_complete(run_dir)
    assert not (write_run(run_method("odometry", _sequence(), seed=3), tmp_path) / "preview.png").exists()
