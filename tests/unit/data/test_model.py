"""The data model: streamed sequences, cached arrays, summaries, transforms."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from albot1.data.model import Frame, Scan, Sequence
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


def test_scan_rejects_mismatched_shapes() -> None:
    with pytest.raises(ValueError, match="equal 1-D shapes"):
        Scan(np.zeros(3), np.zeros(4), 0.0, 10.0)


def test_streamed_sequence_decodes_lazily() -> None:
    decoded: list[int] = []

    def factory() -> Iterator[Frame]:
        for i in range(1000):
            decoded.append(i)
            yield _frame(i)

    seq = Sequence("lazy", factory)
    first = next(iter(seq))
    assert first.index == 0 and decoded == [0]
    assert len(seq) == 1000  # one full pass, cached
    passes = len(decoded)
    assert len(seq) == 1000 and len(decoded) == passes


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
