"""Property tests of the trajectory readers (TUM, KITTI, corrected CARMEN) and the relations reader.

On any text only the project's documented errors (DataError and its
subclasses) come out, with no numpy warning; what a reader accepts is finite;
a pose written with ``repr`` digits reads back exactly (the heading through
its quaternion or rotation matrix within 1e-12 rad).
"""

from __future__ import annotations

import math
import tempfile
import warnings
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.model import MAX_COORDINATE_M
from albot1.data.relations import MAX_YAW_RAD, read_relations
from albot1.data.trajectory import read_trajectory

NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**20), 10**20).map(str),
    st.sampled_from(["0", "1", "-1", "1e308", "-1e308", "1e309", "nan", "inf", "1e-320", "0.7071067811865476"]),
)
TOKENS = st.one_of(NUMBERS, st.sampled_from(["#", "x", "", "FLASER", "ODOM", "1,5", "--1", "\t", "é"]))
LINES = st.lists(st.lists(TOKENS, min_size=0, max_size=14).map(" ".join), max_size=10).map("\n".join)
ANY_TEXT = st.one_of(LINES, st.text(max_size=300))

FORMATS = ("tum", "kitti", "carmen")
ANGLES = st.floats(-math.pi, math.pi, allow_nan=False)
COORDS = st.floats(-1e6, 1e6, allow_nan=False)


def _read_quietly(path: Path, fmt: str) -> object:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy RuntimeWarning leaking is a failure
        warnings.simplefilter("ignore", ResourceWarning)  # another test's garbage, freed here by chance
        return read_trajectory(path, fmt)


@settings(max_examples=200, deadline=None)
@given(text=ANY_TEXT, fmt=st.sampled_from(FORMATS))
def test_trajectory_readers_return_finite_poses_or_a_data_error(text: str, fmt: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"t.{fmt if fmt != 'carmen' else 'clf'}"
        path.write_text(text, encoding="utf-8")
        try:
            file = _read_quietly(path, fmt)
        except DataError as exc:
            assert "\n" not in str(exc) and str(path) in str(exc)
            return
    poses = file.poses  # type: ignore[attr-defined]
    assert poses.ndim == 2 and poses.shape[1] == 3 and np.isfinite(poses).all()
    assert np.abs(poses[:, :2]).max(initial=0.0) <= MAX_COORDINATE_M
    stamps = file.timestamps  # type: ignore[attr-defined]
    if stamps is not None:
        assert len(np.unique(stamps)) == len(stamps)  # two poses never share a timestamp


@settings(max_examples=200, deadline=None)
@given(text=ANY_TEXT)
def test_the_relations_reader_returns_finite_relations_or_a_data_error(text: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "r.relations"
        path.write_text(text, encoding="utf-8")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                warnings.simplefilter("ignore", ResourceWarning)  # another test's garbage, freed here by chance
                relations = read_relations(path)
        except DataError as exc:
            assert "\n" not in str(exc) and str(path) in str(exc)
            return
    assert np.isfinite(relations.poses).all() and np.isfinite(relations.t1).all()
    assert not (relations.t1 == relations.t2).any()
    assert (np.abs(relations.poses[:, 2]) <= MAX_YAW_RAD).all()  # radians: a file in degrees is refused


POSES = st.lists(st.tuples(COORDS, COORDS, ANGLES), min_size=1, max_size=15)


def _stamps(n: int, start: float) -> list[float]:
    return [start + 0.125 * i for i in range(n)]


@settings(max_examples=80, deadline=None)
@given(poses=POSES, start=st.floats(0, 2e9, allow_nan=False))
def test_tum_written_with_repr_reads_back_exactly(poses: list[tuple[float, float, float]], start: float) -> None:
    stamps = _stamps(len(poses), start)
    lines = [
        f"{t!r} {x!r} {y!r} 0.0 0.0 0.0 {math.sin(a / 2)!r} {math.cos(a / 2)!r}"
        for t, (x, y, a) in zip(stamps, poses, strict=True)
    ]
    back = _round_trip("t.tum", "tum", "\n".join(lines))
    assert back.timestamps is not None and back.timestamps.tolist() == stamps
    _same(back.poses, poses)


@settings(max_examples=80, deadline=None)
@given(poses=POSES)
def test_kitti_written_with_repr_reads_back_exactly(poses: list[tuple[float, float, float]]) -> None:
    lines = []
    for x, y, a in poses:
        c, s = math.cos(a), math.sin(a)
        lines.append(f"{c!r} {-s!r} 0.0 {x!r} {s!r} {c!r} 0.0 {y!r} 0.0 0.0 1.0 0.0")
    back = _round_trip("t.kitti", "kitti", "\n".join(lines))
    assert back.timestamps is None
    _same(back.poses, poses)


@settings(max_examples=60, deadline=None)
@given(poses=POSES, start=st.floats(0, 2e9, allow_nan=False))
def test_corrected_carmen_written_with_repr_reads_back_exactly(
    poses: list[tuple[float, float, float]], start: float
) -> None:
    stamps = _stamps(len(poses), start)
    lines = [
        f"FLASER 3 1.0 2.0 3.0 {x!r} {y!r} {a!r} {x!r} {y!r} {a!r} {t!r} host {t!r}"
        for t, (x, y, a) in zip(stamps, poses, strict=True)
    ]
    back = _round_trip("t.clf", "carmen", "\n".join(lines) + "\n")
    assert back.timestamps is not None and back.timestamps.tolist() == stamps
    _same(back.poses, poses, exact_heading=True)


@settings(max_examples=80, deadline=None)
@given(rows=st.lists(st.tuples(COORDS, COORDS, ANGLES), min_size=1, max_size=15))
def test_relations_written_with_repr_read_back_exactly(rows: list[tuple[float, float, float]]) -> None:
    lines = [f"{float(i)!r} {i + 0.5!r} {x!r} {y!r} 0 0 0 {a!r}" for i, (x, y, a) in enumerate(rows)]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "r.relations"
        path.write_text("\n".join(lines))
        relations = read_relations(path)
    assert relations.poses.tolist() == [list(r) for r in rows]
    assert relations.repeats == 0


def _round_trip(name: str, fmt: str, text: str):  # type: ignore[no-untyped-def]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / name
        path.write_text(text)
        return _read_quietly(path, fmt)


def _same(got: np.ndarray, poses: list[tuple[float, float, float]], *, exact_heading: bool = False) -> None:
    expected = np.asarray(poses, dtype=float)
    assert got[:, :2].tolist() == expected[:, :2].tolist()
    if exact_heading:
        assert got[:, 2].tolist() == expected[:, 2].tolist()
        return
    wrapped = np.angle(np.exp(1j * (got[:, 2] - expected[:, 2])))
    assert np.abs(wrapped).max() <= 1e-12
