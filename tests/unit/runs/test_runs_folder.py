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


@pytest.mark.parametrize(("counted", "note"), [(True, True), (False, True), (True, False)])
def test_a_run_folders_relations_read_back_as_they_were_scored(tmp_path: Path, counted: bool, note: bool) -> None:
    """A repeated relation line counts in a run folder as it did when scored; copies from before the reading
    note (``note=False``) counted every line."""
    twice = Relations(np.array([100.0, 100.0]), np.array([101.0, 101.0]), np.array([[0.6, 0.2, 0.1]] * 2), 1, counted)
    once = Relations(np.array([100.0]), np.array([101.0]), np.array([[0.6, 0.2, 0.1]]), 1, counted)
    sequence = _sequence()
    sequence.relations = twice if counted else once
    run_dir = write_run(run_method("odometry", sequence, seed=1), tmp_path)
    copy = run_dir / "relations.txt"
    if not note:
        copy.write_text("\n".join(copy.read_text().splitlines()[1:]) + "\n")
    stored = read_run(run_dir)
    assert stored.relations is not None and len(stored.relations) == (2 if counted else 1)
    assert stored.relations.repeats == 1


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
    assert run_dir.name == run_key("toy", "odometry", result.config, "none", 1, result.versions)
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


def test_run_files_have_normal_permissions_not_mkstemps_private_ones(tmp_path: Path) -> None:
    import os
    import stat

    mask = os.umask(0o022)
    try:
        run_dir = write_run(run_method("odometry", _sequence()), tmp_path)
    finally:
        os.umask(mask)
    modes = {p.name: stat.S_IMODE(p.stat().st_mode) for p in run_dir.iterdir() if p.is_file()}
    assert modes["trajectory.tum"] == 0o644 and modes["result.json"] == 0o644 and modes[DONE] == 0o644
    assert all(mode & 0o044 == 0o044 for mode in modes.values()), modes  # every file readable by group and others


def test_rewriting_a_run_never_keeps_the_older_runs_metrics_or_files(tmp_path: Path) -> None:
    from albot1.runs.evaluate import evaluate_run

    result = run_method("odometry", _sequence())
    run_dir = write_run(result, tmp_path)
    evaluate_run(run_dir)
    (run_dir / "preview.png").write_bytes(b"old")
    (run_dir / "places.png").write_bytes(b"old")
    assert (run_dir / "metrics.json").is_file()
    write_run(result, tmp_path)  # the same inputs again: same folder
    assert not (run_dir / "metrics.json").exists() and not (run_dir / "preview.png").exists()
    assert not (run_dir / "places.png").exists()
    assert is_complete(run_dir)


def test_latest_link_and_listing_of_a_runs_root(tmp_path: Path) -> None:
    from albot1.runs.evaluate import evaluate_run
    from albot1.runs.folder import LATEST, list_runs, mark_latest

    first = write_run(run_method("odometry", _sequence()), tmp_path)
    second = write_run(run_method("odometry", _sequence(), degradation="gauss:0.1:1"), tmp_path)
    evaluate_run(second)
    link = mark_latest(tmp_path, second)
    assert link == tmp_path / LATEST and link.resolve() == second.resolve()
    assert mark_latest(tmp_path, first).resolve() == first.resolve()  # replaced, not an error
    broken = tmp_path / "0123456789abcdef"
    broken.mkdir()
    (broken / "result.json").write_text("{}")
    (tmp_path / "notes").mkdir()  # not a run: not listed
    listing = {item.path.name: item for item in list_runs(tmp_path)}
    assert set(listing) == {first.name, second.name, broken.name}
    assert listing[first.name].status == "done" and listing[second.name].status == "evaluated"
    assert listing[broken.name].status == "unreadable" and "not a valid ResultRecord" in str(
        listing[broken.name].problem
    )
    (tmp_path / LATEST).unlink()
    (tmp_path / LATEST).mkdir()
    with pytest.raises(RunError, match="exists and is not a symbolic link"):
        mark_latest(tmp_path, first)


def test_per_scan_times_are_written_atomically_and_no_temporary_file_stays(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    result = run_method("odometry", _sequence())

    def killed_mid_write(file: object, array: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(np, "save", killed_mid_write)
    with pytest.raises(OSError, match="No space left"):
        write_run(result, tmp_path)
    (run_dir,) = tmp_path.iterdir()
    assert not (run_dir / "per_scan_ns.npy").exists() and not is_complete(run_dir)
    assert not [p.name for p in run_dir.iterdir() if p.name.startswith(".")]
    monkeypatch.undo()
    (run_dir / ".trajectory.tum.k1ll3d.tmp.tum").write_bytes(b"")  # what a SIGKILLed writer leaves
    write_run(result, tmp_path)
    assert is_complete(run_dir) and not [p.name for p in run_dir.iterdir() if p.name.startswith(".")]
    assert read_run(run_dir).per_scan_ns.shape == (8,)


@pytest.mark.parametrize(
    ("damage", "words"),
    [
        (lambda d: (d / "per_scan_ns.npy").unlink(), r"per_scan_ns\.npy: missing from a run folder marked complete"),
        (
            lambda d: (d / "per_scan_ns.npy").write_text("garbage"),
            r"per_scan_ns\.npy: not a numpy array file this project wrote",
        ),
        (
            lambda d: np.save(d / "per_scan_ns.npy", np.zeros(3)),
            r"per_scan_ns\.npy: holds float64 of shape \(3,\); expected a \.npy array of 8 per-scan times",
        ),
        (lambda d: (d / "odometry.tum").unlink(), r"odometry\.tum: missing from a run folder marked complete"),
        (lambda d: (d / "reference.tum").unlink(), r"reference\.tum: missing"),
        (lambda d: (d / "relations.txt").unlink(), r"relations\.txt: missing"),
    ],
)
def test_a_damaged_run_folder_is_one_error_naming_the_file(tmp_path: Path, damage: object, words: str) -> None:
    run_dir = write_run(run_method("odometry", _sequence()), tmp_path)
    damage(run_dir)  # type: ignore[operator]
    with pytest.raises(RunError, match=words):
        read_run(run_dir)


def test_a_damaged_map_is_one_error_naming_the_file(tmp_path: Path) -> None:
    run_dir = write_run(run_method("odometry", _sequence()), tmp_path)
    stored = read_run(run_dir)
    (run_dir / "map.npz").write_text("not a zip")
    with pytest.raises(RunError, match=r"map\.npz: not a map this project wrote .*expected a \.npz archive"):
        stored.load_map()
    (run_dir / "map.npz").unlink()
    with pytest.raises(RunError, match=r"map\.npz: missing"):
        stored.load_map()
