"""CarmenLoader on small synthetic logs: geometry, no-return rule, pose sources, streaming."""

from __future__ import annotations

import bz2
import gzip
import math
import re
from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import DataError, ParseError
from albot1.data.loaders.carmen.loader import CarmenLoader
from albot1.data.loaders.registry import loader_for


def flaser(
    ranges: list[float] | np.ndarray,
    stamp: float,
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
    odom: tuple[float, float, float] | None = None,
) -> str:
    odom = pose if odom is None else odom
    r = " ".join(f"{v:.3f}" for v in ranges)
    return (
        f"FLASER {len(ranges)} {r} {pose[0]} {pose[1]} {pose[2]} {odom[0]} {odom[1]} {odom[2]} "
        f"{stamp:.6f} host {stamp:.6f}"
    )


def odom_line(pose: tuple[float, float, float], stamp: float) -> str:
    return f"ODOM {pose[0]} {pose[1]} {pose[2]} 0 0 0 {stamp:.6f} host {stamp:.6f}"


def write(tmp_path: Path, lines: list[str], name: str = "log.clf") -> Path:
    path = tmp_path / name
    text = "\n".join(lines) + "\n"
    if name.endswith(".gz"):
        path.write_bytes(gzip.compress(text.encode()))
    elif name.endswith(".bz2"):
        path.write_bytes(bz2.compress(text.encode()))
    else:
        path.write_text(text)
    return path


def load(path: Path, **options: object) -> list:
    return list(CarmenLoader().load(path, **options).frames())


@pytest.mark.parametrize(
    ("beams", "step_deg", "last_deg"), [(180, 1.0, 89.0), (181, 1.0, 90.0), (360, 0.5, 89.5), (361, 0.5, 90.0)]
)
def test_flaser_default_geometry_by_beam_count(tmp_path: Path, beams: int, step_deg: float, last_deg: float) -> None:
    frames = load(write(tmp_path, [flaser([1.0] * beams, 1.0)]))
    angles = frames[0].scan.angles
    assert angles[0] == pytest.approx(-math.pi / 2)
    assert angles[1] - angles[0] == pytest.approx(math.radians(step_deg))
    assert angles[-1] == pytest.approx(math.radians(last_deg))


def test_param_lines_set_resolution_fov_max_range_and_offset(tmp_path: Path) -> None:
    lines = [
        "PARAM laser_front_laser_resolution 0.5 0 host 0",
        "PARAM laser_front_laser_fov 90 0 host 0",
        "PARAM robot_front_laser_max 20.0 0 host 0",
        "PARAM robot_frontlaser_offset 0.25 0 host 0",
        flaser([1.0, 19.996, 19.99, 0.0, 5.0], 1.0),
    ]
    seq = CarmenLoader().load(write(tmp_path, lines))
    scan = next(iter(seq)).scan
    assert scan.angles[0] == pytest.approx(math.radians(-45))
    assert scan.angles[1] - scan.angles[0] == pytest.approx(math.radians(0.5))
    assert scan.max_range == 20.0
    # no-return rule: r >= max_range - 0.005 or r == 0
    np.testing.assert_array_equal(np.isnan(scan.ranges), [False, True, False, True, False])
    assert seq.metadata.sensor_offset == (0.25, 0.0, 0.0)


def test_max_range_option_overrides_the_log(tmp_path: Path) -> None:
    scan = load(write(tmp_path, [flaser([1.0, 81.91, 81.83, 50.0], 1.0)]), max_range=80.0)[0].scan
    np.testing.assert_array_equal(np.isnan(scan.ranges), [False, True, True, False])


def test_laser_pose_odometry_is_the_odom_fields_and_reference_the_xy_theta_fields(tmp_path: Path) -> None:
    path = write(tmp_path, [flaser([1.0] * 180, 1.0, pose=(5.0, 6.0, 0.5), odom=(1.0, 2.0, 0.1))])
    frame = load(path, reference="laser-pose")[0]
    np.testing.assert_array_equal(frame.odometry, [1.0, 2.0, 0.1])
    np.testing.assert_array_equal(frame.reference, [5.0, 6.0, 0.5])
    assert load(path)[0].reference is None


def test_odom_interpolation_at_scan_time(tmp_path: Path) -> None:
    lines = [
        odom_line((0.0, 0.0, 0.0), 0.0),
        flaser([1.0] * 180, 1.0),
        odom_line((2.0, 0.0, 1.0), 2.0),
        flaser([1.0] * 180, 1.5),
        odom_line((2.0, 0.0, 1.0), 5.0),
    ]
    frames = load(write(tmp_path, lines), odometry="odom")
    np.testing.assert_allclose(frames[0].odometry, [1.0, 0.0, 0.5])
    np.testing.assert_allclose(frames[1].odometry, [1.5, 0.0, 0.75])


def test_odom_interpolation_holds_end_poses_and_sorts_jitter(tmp_path: Path) -> None:
    lines = [
        flaser([1.0] * 180, 0.5),
        odom_line((1.0, 0.0, 0.0), 1.0),
        odom_line((3.0, 0.0, 0.0), 3.0),
        odom_line((2.0, 0.0, 0.0), 2.0),
        flaser([1.0] * 180, 2.5),
        flaser([1.0] * 180, 3.9),
    ]
    frames = load(write(tmp_path, lines), odometry="odom")
    np.testing.assert_allclose([f.odometry[0] for f in frames], [1.0, 2.5, 3.0])


@pytest.mark.parametrize("kind", ["ODOM", "TRUEPOS"])
@pytest.mark.parametrize(
    ("layout", "line", "found"),
    [
        (
            "S10 P14.5 S14.6 P15 S15 P15.5",
            1,
            "10.000000 s lies 4.500 s before the first {kind} line (t = 14.500000 s)",
        ),
        (
            "S14.6 P14.5 S15 P15 P15.5 S30",
            6,
            "30.000000 s lies 14.500 s after the last {kind} line (t = 15.500000 s)",
        ),
    ],
)
def test_scans_far_outside_the_pose_lines_are_refused_not_given_a_held_pose(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str, layout: str, line: int, found: str
) -> None:
    """A log whose ODOM (or TRUEPOS) stream covers only part of its scans used to give the others the end
    pose, silently: a robot standing still in the odometry, or reference poses that were never measured.
    Farther than time_tolerance outside the poses' span that is refused, at the scan's line, in every chunking.
    ``layout``: the log's lines, S = a scan and P = a pose line at that time."""
    import functools

    from albot1.data.loaders.carmen import frames as frames_module
    from albot1.data.loaders.carmen.source import iter_line_chunks

    def pose(t: float) -> str:
        if kind == "ODOM":
            return odom_line((t, 0.0, 0.0), t)
        return f"TRUEPOS {t} 0 0 {t} 0 0 {t:.6f} host {t:.6f}"

    lines = [flaser([1.0] * 180, float(w[1:])) if w[0] == "S" else pose(float(w[1:])) for w in layout.split()]
    path = write(tmp_path, lines)
    options = {"odometry": "odom"} if kind == "ODOM" else {"reference": "truepos"}
    message = (
        rf"log\.clf:{line}: scan at t = {re.escape(found.format(kind=kind))}.*time_tolerance=inf holds the end poses"
    )
    with pytest.raises(ParseError, match=message):
        load(path, **options)
    monkeypatch.setattr(frames_module, "iter_line_chunks", functools.partial(iter_line_chunks, chunk_bytes=200))
    with pytest.raises(ParseError, match=message):
        load(path, **options)
    assert len(load(path, time_tolerance=math.inf, **options)) == 3


def test_odom_going_back_beyond_tolerance_names_the_line(tmp_path: Path) -> None:
    lines = [odom_line((0, 0, 0), 10.0), flaser([1.0] * 180, 10.5), odom_line((0, 0, 0), 2.0)]
    with pytest.raises(ParseError, match=r"log\.clf:3: ODOM timestamp .* goes back 8\.000 s.*odom-segments"):
        load(write(tmp_path, lines), odometry="odom")


def test_scan_timestamps_going_back_are_a_parse_error(tmp_path: Path) -> None:
    lines = [flaser([1.0] * 180, 10.0), flaser([1.0] * 180, 9.5), flaser([1.0] * 180, 5.0)]
    path = write(tmp_path, lines)
    with pytest.raises(ParseError, match=r"log\.clf:3: FLASER timestamp 5\.000000 goes back 5\.000 s from line 1"):
        load(path)
    assert len(load(path, time_tolerance=math.inf)) == 3


def gmapping_log() -> tuple[list[str], np.ndarray]:
    """A GMapping-style corrected log and the odometry it encodes (raw steps of +1 m along x)."""
    corrected = [(0.0, 0.0, 0.0), (1.1, 0.1, 0.05), (2.0, 0.3, 0.1)]
    lines = [odom_line((0.0, 0.0, 0.0), 0.0)]
    for k, pose in enumerate(corrected):
        lines.append(flaser([1.0] * 180, float(k), pose=pose))
        lines.append(odom_line(pose, 0.0))  # GMapping's re-anchoring line (stamp 0)
        lines.append("NEFF 12.5")
        x, y, th = pose
        lines.append(odom_line((x + 0.5 * math.cos(th), y + 0.5 * math.sin(th), th), k + 0.5))
        lines.append(odom_line((x + math.cos(th), y + math.sin(th), th), k + 1.0))
    return lines, np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])


def test_odom_segments_chain_the_raw_increments(tmp_path: Path) -> None:
    lines, expected = gmapping_log()
    frames = load(write(tmp_path, lines), odometry="odom-segments", reference="laser-pose")
    np.testing.assert_allclose([f.odometry for f in frames], expected, atol=1e-12)
    np.testing.assert_allclose(frames[2].reference, [2.0, 0.3, 0.1])


def test_odom_segments_reject_a_log_that_is_not_re_anchored(tmp_path: Path) -> None:
    lines, _ = gmapping_log()
    lines[2] = odom_line((9.0, 9.0, 0.0), 0.0)
    with pytest.raises(
        ParseError,
        match=r"log\.clf:3: the first ODOM after the scan at line 2 .* expected it to "
        r"repeat",
    ):
        load(write(tmp_path, lines), odometry="odom-segments")


def robotlaser(
    ranges: list[float],
    stamp: float,
    robot: tuple[float, float, float],
    start: float = -1.0,
    res: float = 0.5,
    max_range: float = 30.0,
) -> str:
    r = " ".join(f"{v:.3f}" for v in ranges)
    laser = (robot[0] + 0.2 * math.cos(robot[2]), robot[1] + 0.2 * math.sin(robot[2]), robot[2])
    return (
        f"ROBOTLASER1 0 {start} {res * (len(ranges) - 1)} {res} {max_range} 0.01 0 {len(ranges)} {r} 0 "
        f"{laser[0]} {laser[1]} {laser[2]} {robot[0]} {robot[1]} {robot[2]} 0 0 0 0 0 {stamp} host {stamp}"
    )


def test_robotlaser1_geometry_pose_and_sensor_offset(tmp_path: Path) -> None:
    seq = CarmenLoader().load(write(tmp_path, [robotlaser([1.0, 2.0, 30.0], 3.0, (1.0, 2.0, 0.3))]))
    frame = next(iter(seq))
    np.testing.assert_allclose(frame.scan.angles, [-1.0, -0.5, 0.0])
    assert np.isnan(frame.scan.ranges[2]) and frame.scan.max_range == 30.0
    np.testing.assert_allclose(frame.odometry, [1.0, 2.0, 0.3])
    np.testing.assert_allclose(seq.metadata.sensor_offset, (0.2, 0.0, 0.0), atol=1e-9)


def test_rawlaser_needs_odom_and_truepos_becomes_reference(tmp_path: Path) -> None:
    raw = "RAWLASER1 0 -1.5 3.0 1.5 20 0.01 0 3 1.0 2.0 3.0 0 {t} host {t}"
    lines = [
        "TRUEPOS 0 0 0 9 9 9 0.0 host 0.0",
        odom_line((0, 0, 0), 0.0),
        raw.format(t=1.0),
        odom_line((4, 0, 0), 4.0),
        "TRUEPOS 8 0 0 9 9 9 4.0 host 4.0",
    ]
    path = write(tmp_path, lines)
    with pytest.raises(DataError, match="RAWLASER1 lines carry no pose"):
        CarmenLoader().load(path)
    frame = load(path, odometry="odom")[0]
    np.testing.assert_allclose(frame.odometry, [1.0, 0.0, 0.0])
    np.testing.assert_allclose(frame.reference, [2.0, 0.0, 0.0])


@pytest.mark.parametrize("name", ["log.clf.gz", "log.clf.bz2", "renamed.clf"])
def test_compressed_logs_equal_plain(tmp_path: Path, name: str) -> None:
    lines = [flaser([1.0, 2.0] * 90, float(k), pose=(k, 0, 0)) for k in range(5)]
    plain = load(write(tmp_path, lines))
    path = write(tmp_path, lines, name if name != "renamed.clf" else "x.clf.bz2")
    if name == "renamed.clf":
        path = path.rename(tmp_path / name)  # bzip2 content under a plain name: found by magic bytes
    other = load(path)
    assert len(other) == 5
    for a, b in zip(plain, other):
        np.testing.assert_array_equal(a.scan.ranges, b.scan.ranges)
        np.testing.assert_array_equal(a.odometry, b.odometry)


def test_registry_sniffs_carmen_by_content(tmp_path: Path) -> None:
    path = write(tmp_path, ["# a comment", flaser([1.0] * 180, 1.0)], "data.txt")
    assert loader_for(path).format_name == "carmen"


def test_unknown_messages_are_skipped_and_listed(tmp_path: Path) -> None:
    seq = CarmenLoader().load(write(tmp_path, ["SYNC tag 0 host 0", "NEFF 3", flaser([1.0] * 180, 1.0)]))
    assert len(list(seq)) == 1
    assert seq.metadata.extra["ignored_messages"] == ["NEFF", "SYNC"]


def test_first_frame_is_yielded_before_a_late_error_is_read(tmp_path: Path) -> None:
    ranges = np.full(180, 12.345)
    good = [flaser(ranges, float(k)) for k in range(3000)]  # ~3.3 MB: more than one 2 MiB chunk
    path = write(tmp_path, good + ["FLASER 180 1 2 3"])
    frames = CarmenLoader().load(path).frames()
    first = next(frames)
    assert first.index == 0 and first.scan.timestamp == 0.0
    with pytest.raises(ParseError, match=r"log\.clf:3001: FLASER has 4 fields after the name, expected 190"):
        for _ in frames:
            pass


def test_unknown_option_is_rejected(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="unknown CARMEN loader option"):
        CarmenLoader().load(write(tmp_path, [flaser([1.0] * 180, 1.0)]), odom_topic="/odom")


def test_param_between_scans_applies_only_to_later_scans(tmp_path: Path) -> None:
    lines = [
        flaser([1.0] * 180, 1.0),
        flaser([1.0] * 181, 1.5),
        "PARAM laser_front_laser_resolution 0.5 0 host 0",
        flaser([1.0] * 180, 2.0),
        flaser([1.0] * 181, 2.5),
    ]
    steps = [round(math.degrees(f.scan.angles[1] - f.scan.angles[0]), 9) for f in load(write(tmp_path, lines))]
    assert steps == [1.0, 1.0, 0.5, 0.5]


@pytest.mark.parametrize(("odometry", "reference"), [("odom", "truepos"), ("odom-segments", "laser-pose")])
def test_small_chunks_give_the_same_frames(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, odometry: str, reference: str
) -> None:
    """The look-ahead buffers carry state across chunk boundaries: chunking never changes a pose."""
    import functools

    from albot1.data.loaders.carmen import frames as frames_module
    from albot1.data.loaders.carmen.source import iter_line_chunks

    rng = np.random.default_rng(5)
    lines: list[str] = []
    pose = np.zeros(3)
    for k in range(300):
        stamp = 0.1 * k
        lines.append(flaser(rng.uniform(0.5, 9.0, 180), stamp, pose=tuple(pose)))
        lines.append(odom_line(tuple(pose), 0.0 if odometry == "odom-segments" else stamp + 0.02))
        pose = pose + np.array([0.05, 0.01, 0.002])
        jitter = rng.uniform(-0.3, 0.0) if odometry == "odom" else 0.0
        lines.append(odom_line(tuple(pose), stamp + 0.07 + jitter))
        lines.append(f"TRUEPOS {pose[0]} {pose[1]} {pose[2]} 0 0 0 {stamp + 0.05:.6f} host {stamp + 0.05:.6f}")
    path = write(tmp_path, lines)
    whole = CarmenLoader().load(path, odometry=odometry, reference=reference)
    expected_odom, expected_ref = whole.odometry, whole.reference
    monkeypatch.setattr(frames_module, "iter_line_chunks", functools.partial(iter_line_chunks, chunk_bytes=3000))
    chunked = CarmenLoader().load(path, odometry=odometry, reference=reference)
    np.testing.assert_array_equal(chunked.odometry, expected_odom)
    np.testing.assert_array_equal(chunked.reference, expected_ref)
    assert chunked.count_scans() == 300


@pytest.mark.parametrize(("offset", "side", "angular"), [(0.3, 0.0, 0.0), (-0.25, 0.05, 0.1)])
def test_rear_laser_mount_faces_backwards_as_carmen_writes_its_laser_pose(
    tmp_path: Path, offset: float, side: float, angular: float
) -> None:
    """CARMEN's robot module writes an RLASER line's laser pose as theta = odom_theta + pi and
    x = odom_x + offset * cos(theta) (robot_laser.c): the rear laser looks backwards. Its mount used to be
    read as (offset, side, angular), facing forwards, so every rear scan was placed mirrored front to back.
    The mount must be the one the lines' own laser and odometry poses imply."""
    from albot1.geometry import se2

    params = [
        f"PARAM robot_rearlaser_offset {offset}",
        f"PARAM robot_rearlaser_side_offset {side}",
        f"PARAM robot_rearlaser_angular_offset {angular}",
    ]
    mount = np.array([-offset, -side, math.pi + angular])  # the rear PARAMs after a half turn
    lines = []
    for k, odom in enumerate([(0.0, 0.0, 0.0), (1.0, 0.5, 0.7), (2.0, -1.0, -2.9)]):
        laser = [float(v) for v in se2.compose(np.array(odom), mount)]
        r = " ".join(["2.000"] * 181)
        lines.append(
            f"RLASER 181 {r} {laser[0]!r} {laser[1]!r} {laser[2]!r} {odom[0]} {odom[1]} {odom[2]} "
            f"{k + 1.0:.6f} host {k + 1.0:.6f}"
        )
    sequence = CarmenLoader().load(write(tmp_path, params + lines), laser="RLASER", reference="laser-pose")
    offset = np.array(sequence.metadata.sensor_offset)
    np.testing.assert_allclose(offset[:2], mount[:2], atol=1e-12)
    assert abs(se2.wrap(offset[2] - mount[2])) < 1e-12
    for frame in sequence.frames():
        # the reference is the laser pose fields moved back onto the robot by that mount: the odometry fields
        implied = se2.between(frame.odometry, frame.reference)
        np.testing.assert_allclose(implied, [0.0, 0.0, 0.0], atol=1e-9)
