"""The data model: streamed sequences, cached arrays, summaries, transforms."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

from albot1.data.degrade import degrade
from albot1.data.model import Frame, Scan, Sequence
from albot1.data.open import open_sequence
from albot1.data.synthetic.worlds import load_world, world_data
from albot1.data.transforms import head, stride

ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 5)


def _frame(i: int, ranges: np.ndarray | None = None) -> Frame:
    r = np.array([1.0, np.nan, 2.0, 2.0, 1.0]) if ranges is None else ranges
    return Frame(i, Scan(r, ANGLES, 10.0 + i, 30.0), np.array([float(i), 0.0, 0.0]))


def test_points_skip_no_return_and_follow_rep103() -> None:
    pts = _frame(0).scan.points()
    assert pts.shape == (4, 2)
    np.testing.assert_allclose(pts[0], [0.0, -1.0], atol=1e-12)  # beam 0 at -90 deg points right
    np.testing.assert_allclose(pts[1], [2.0, 0.0], atol=1e-12)  # beam 2 straight ahead


def test_points_range_limits_keep_beams_exactly_at_a_limit() -> None:
    scan = _frame(0, np.array([0.5, np.nan, 2.0, 3.0, 1.0])).scan
    assert scan.points(min_range_m=1.0).shape == (3, 2)  # 0.5 m dropped, 1.0 m kept
    kept = scan.points(min_range_m=1.0, max_range_m=2.0)
    np.testing.assert_allclose(kept, [[2.0, 0.0], [0.0, 1.0]], atol=1e-12)  # 2 m ahead, 1 m left
    assert scan.points(max_range_m=0.1).shape == (0, 2)
    np.testing.assert_array_equal(scan.points(), scan.points(None, None))


def test_points_keep_missing_gives_one_point_per_beam_nan_where_no_return() -> None:
    scan = _frame(0).scan
    every = scan.points(keep_missing=True)
    assert every.shape == (5, 2)
    assert np.isnan(every[1]).all() and np.isfinite(np.delete(every, 1, axis=0)).all()
    np.testing.assert_array_equal(np.delete(every, 1, axis=0), scan.points())
    with pytest.raises(ValueError, match="no range limits"):
        scan.points(min_range_m=1.0, keep_missing=True)


def test_scan_rejects_mismatched_shapes() -> None:
    with pytest.raises(ValueError, match="equal 1-D shapes"):
        Scan(np.zeros(3), np.zeros(4), 0.0, 10.0)


def _counting_factory(decoded: list[int], n: int = 1000) -> Callable[[], Iterator[Frame]]:
    def factory() -> Iterator[Frame]:
        for i in range(n):
            decoded.append(i)
            yield _frame(i)

    return factory


def test_streamed_sequence_decodes_lazily() -> None:
    decoded: list[int] = []
    seq = Sequence("lazy", _counting_factory(decoded))
    first = next(iter(seq))
    assert first.index == 0 and decoded == [0]


def test_len_of_a_streamed_sequence_is_a_type_error_and_count_scans_is_the_explicit_pass() -> None:
    decoded: list[int] = []
    seq = Sequence("lazy", _counting_factory(decoded))
    assert seq.known_scan_count is None
    with pytest.raises(TypeError, match=r"len\(\) of sequence 'lazy' is unknown.*count_scans\(\)"):
        len(seq)
    assert decoded == [] and bool(seq) is True  # neither len() nor truth testing decoded anything
    assert seq.count_scans() == 1000 and len(decoded) == 1000  # one full pass...
    assert seq.count_scans() == len(seq) == seq.known_scan_count == 1000 and len(decoded) == 1000  # ...cached


def test_list_of_a_streamed_sequence_decodes_it_once() -> None:
    decoded: list[int] = []
    frames = list(Sequence("lazy", _counting_factory(decoded, 50)))
    # list() asks for a size hint first; the TypeError of len() means "unknown", not a second full pass.
    assert len(frames) == 50 and decoded == list(range(50))


def test_known_counts_need_no_decoding_and_survive_prefix_stride_and_degradation() -> None:
    decoded: list[int] = []
    seq = Sequence("known", _counting_factory(decoded, 10), scan_count=10)
    assert len(seq) == 10
    assert (len(head(seq, 3)), len(head(seq, 50)), len(stride(seq, 4)), len(stride(seq, 5))) == (3, 10, 3, 2)
    assert len(degrade(seq, "gauss:0.1:1", seed=3)) == 10
    assert decoded == []
    assert len(Sequence.from_frames("s", [_frame(i) for i in range(4)])) == 4
    # A transform of an unknown count stays unknown (a prefix of a log may be shorter than asked for).
    assert head(Sequence("lazy", _counting_factory(decoded, 2)), 5).known_scan_count is None
    assert head(Sequence("lazy", _counting_factory(decoded, 2)), 5).count_scans() == 2


def test_negative_scan_count_is_refused() -> None:
    with pytest.raises(ValueError, match="scan_count must be >= 0"):
        Sequence("bad", lambda: iter(()), scan_count=-1)


def test_synthetic_world_knows_its_length() -> None:
    world = load_world("synthetic-corridor")
    assert len(world) == world_data("synthetic-corridor").scans > 0


def _carmen_log(path: Path, scans: int) -> Path:
    """A small CARMEN log: FLASER lines (181 beams) with odometry, one every 0.5 s."""
    lines = []
    for k in range(scans):
        ranges = " ".join("2.000" for _ in range(181))
        stamp = 100.0 + 0.5 * k
        lines.append(f"FLASER 181 {ranges} {0.1 * k} 0 0 {0.1 * k} 0 0 {stamp:.6f} host {stamp:.6f}")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_len_of_a_lazily_loaded_carmen_log(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    decoded: list[int] = []
    stream = Sequence.frames

    seen: list[Frame] = []

    def counting(self: Sequence) -> Iterator[Frame]:
        for frame in stream(self):
            # a frame passed on unchanged by a wrapping sequence (the finite-value check) is one decoding
            if not any(known is frame for known in seen):
                seen.append(frame)
                decoded.append(frame.index)
            yield frame

    monkeypatch.setattr(Sequence, "frames", counting)
    monkeypatch.setenv("ALBOT1_DECODED_CACHE", "off")  # frames read back from the cache are new objects
    path = _carmen_log(tmp_path / "tiny.clf", 7)
    seq = open_sequence(str(path))
    with pytest.raises(TypeError, match="count_scans"):
        len(seq)
    prefix = open_sequence(f"{path}[:5]")
    with pytest.raises(TypeError, match="count_scans"):
        len(prefix)
    assert decoded == []  # len() decoded nothing
    assert seq.count_scans() == 7 and decoded == list(range(7))
    assert len(seq) == 7 and decoded == list(range(7))  # counted once, free from then on
    assert prefix.count_scans() == 5


def test_summary_and_reference_absent() -> None:
    seq = Sequence.from_frames("s", [_frame(i) for i in range(4)])
    summary = seq.summary()
    assert summary["scans"] == 4 and summary["beams"] == 5
    assert summary["duration_s"] == pytest.approx(3.0)
    assert summary["odometry_path_m"] == pytest.approx(3.0)
    assert summary["has_reference"] is False and seq.reference is None


def test_from_frames_requires_consecutive_indices() -> None:
    with pytest.raises(ValueError, match="numbered 0..N-1"):
        Sequence.from_frames("bad", [_frame(1)])


def test_head_and_stride() -> None:
    seq = Sequence.from_frames("s", [_frame(i) for i in range(10)])
    assert len(head(seq, 3)) == 3
    strided = list(stride(seq, 4))
    assert [f.index for f in strided] == [0, 1, 2]
    assert [f.scan.timestamp for f in strided] == [10.0, 14.0, 18.0]
