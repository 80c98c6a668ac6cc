"""Issue 15, CARMEN: data that used to be accepted or lost silently is now refused with file:line,
what was found and what was expected; whitespace-separated fields are read whatever the whitespace."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.loader import CarmenLoader


def flaser(t: float, ranges: list[float], x: float = 0.0) -> str:
    return f"FLASER {len(ranges)} {' '.join(map(str, ranges))} {x} 0 0 {x} 0 0 {t} host {t}"


def robotlaser(
    t: float,
    ranges: list[float],
    start: float = -math.pi / 2,
    fov: float | None = None,
    res: float = math.radians(1.0),
    max_range: float = 80.0,
) -> str:
    fov = (len(ranges) - 1) * res if fov is None else fov
    body = " ".join(map(str, ranges))
    return (
        f"ROBOTLASER1 0 {start!r} {fov!r} {res!r} {max_range!r} 0.01 0 {len(ranges)} {body} 0 "
        f"0 0 0 0 0 0 0 0 0 0 0 {t} host {t}"
    )


def write(tmp_path: Path, lines: list[str], name: str = "log.clf") -> Path:
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def frames(path: Path, **options: object) -> list:
    return list(CarmenLoader().load(path, **options).frames())


RANGES = [1.0, 2.0, 3.0]


def test_mixed_front_laser_kinds_are_refused_with_counts(tmp_path: Path) -> None:
    lines = [flaser(0.0, RANGES)] + [robotlaser(1.0 + k, RANGES) for k in range(3)] + [flaser(5.0, RANGES)]
    path = write(tmp_path, lines)
    message = (
        r"log\.clf:2: the log mixes front-laser message kinds: 2 FLASER lines \(first at line 1\) and "
        r"3 ROBOTLASER1 lines \(first at line 2\); .*laser=FLASER or laser=ROBOTLASER1"
    )
    with pytest.raises(ParseError, match=message):
        frames(path)
    # naming the kind reads exactly that kind: nothing is merged, nothing is dropped unasked
    assert [f.scan.timestamp for f in frames(path, laser="FLASER")] == [0.0, 5.0]
    assert [f.scan.timestamp for f in frames(path, laser="ROBOTLASER1")] == [1.0, 2.0, 3.0]


def test_a_mix_beyond_the_first_chunk_is_refused_while_streaming(tmp_path: Path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    import functools

    from albot1.data.loaders.carmen import frames as frames_module
    from albot1.data.loaders.carmen import probe as probe_module
    from albot1.data.loaders.carmen.source import iter_line_chunks

    lines = [flaser(float(k), RANGES) for k in range(200)] + [robotlaser(300.0, RANGES)]
    path = write(tmp_path, lines)
    small_chunks = functools.partial(iter_line_chunks, chunk_bytes=500)
    monkeypatch.setattr(frames_module, "iter_line_chunks", small_chunks)
    monkeypatch.setattr(probe_module, "iter_line_chunks", small_chunks)
    monkeypatch.setattr(probe_module, "PROBE_BYTES", 500)
    monkeypatch.setattr(probe_module, "PROBE_LIMIT", 500)
    with pytest.raises(ParseError, match=r"log\.clf:201: the log mixes .* 200 FLASER lines .* 1 ROBOTLASER1 lines"):
        frames(path)


def test_raw_and_robot_laser_of_one_scanner_need_a_choice(tmp_path: Path) -> None:
    raw = "RAWLASER1 0 -1.5707963 0.0349 0.01745329 80 0.01 0 3 1 2 3 0 {t} host {t}"
    lines = [raw.format(t=1.0), robotlaser(1.0, RANGES), raw.format(t=2.0), robotlaser(2.0, RANGES)]
    path = write(tmp_path, lines)
    with pytest.raises(ParseError, match="2 ROBOTLASER1 lines .* and 2 RAWLASER1 lines"):
        frames(path)
    assert len(frames(path, laser="ROBOTLASER1")) == 2


def test_a_rear_laser_only_log_says_how_to_read_it(tmp_path: Path) -> None:
    path = write(tmp_path, [flaser(1.0, RANGES).replace("FLASER", "RLASER")])
    with pytest.raises(ParseError, match=r"no front-laser scans .* the log has 1 RLASER lines: .*laser=RLASER"):
        frames(path)
    assert len(frames(path, laser="RLASER")) == 1


@pytest.mark.parametrize(
    ("line", "message"),
    [
        (flaser(1.0, [0.0, 0.0, 0.0]), r"FLASER all 3 ranges are 0, expected at least one reading"),
        ("FLASER 0 0 0 0 0 0 0 1.0 host 1.0", r"FLASER beam count is 0, expected 1 to 100000"),
        (robotlaser(1.0, [0.0, 0.0, 0.0]), r"ROBOTLASER1 all 3 ranges are 0"),
        (
            robotlaser(1.0, RANGES, res=0.0, fov=0.0),
            r"ROBOTLASER1 angular_resolution is 0\.0 rad, expected a positive angle",
        ),
        (
            robotlaser(1.0, RANGES, res=-0.01),
            r"ROBOTLASER1 angular_resolution is -0\.01 rad, expected a positive angle",
        ),
        (
            robotlaser(1.0, RANGES, max_range=-5.0),
            r"ROBOTLASER1 maximum_range is -5\.0 m, expected a finite distance >= 0",
        ),
        (
            robotlaser(1.0, RANGES, start=7.0),
            r"ROBOTLASER1 start_angle is 7\.0 rad, expected a finite angle within a full turn",
        ),
        (
            robotlaser(1.0, RANGES, fov=31.4),
            r"ROBOTLASER1 field_of_view is 31\.4 rad, expected 0 \(not stated\) to 2 pi",
        ),
        (robotlaser(1.0, [1.0] * 180, res=math.radians(10), fov=0.0), r"ROBOTLASER1 180 beams 10 deg apart span 1790"),
        (robotlaser(1.0, RANGES, fov=1.0), r"ROBOTLASER1 field_of_view 1\.0 rad disagrees with 3 beams"),
        ("PARAM laser_front_laser_resolution abc host 0", r"PARAM laser_front_laser_resolution is 'abc', expected"),
        ("PARAM robot_front_laser_max -5 host 0", r"PARAM robot_front_laser_max is '-5', expected a maximum range"),
        ("PARAM laser_frontlaser_fov nan host 0", r"PARAM laser_frontlaser_fov is 'nan', expected a field of view"),
        ("PARAM robot_frontlaser_offset inf host 0", r"PARAM robot_frontlaser_offset is 'inf', expected an offset"),
    ],
)
def test_impossible_values_are_refused_at_their_line(tmp_path: Path, line: str, message: str) -> None:
    path = write(tmp_path, [line, flaser(2.0, RANGES) if line.startswith("PARAM") else robotlaser(9.0, RANGES)])
    with pytest.raises(ParseError, match=r"log\.clf:1: " + message):
        frames(path, laser="FLASER" if line.startswith(("FLASER", "PARAM")) else "ROBOTLASER1")


def test_param_spacing_beyond_a_full_turn_names_the_scan(tmp_path: Path) -> None:
    path = write(tmp_path, ["PARAM laser_front_laser_resolution 10 host 0", flaser(1.0, [1.0] * 180)])
    with pytest.raises(ParseError, match=r"log\.clf:2: FLASER: 180 beams 10 deg apart span 1790 deg, .*PARAM"):
        frames(path)


def test_unused_params_stay_free_text_and_used_ones_apply(tmp_path: Path) -> None:
    lines = ["PARAM robot_name some robot host 0", "PARAM laser_front_laser_resolution 2 host 0", flaser(1.0, RANGES)]
    (frame,) = frames(write(tmp_path, lines))
    assert frame.scan.angles[1] - frame.scan.angles[0] == pytest.approx(math.radians(2))


def test_some_zero_beams_are_no_returns_not_an_error(tmp_path: Path) -> None:
    (frame,) = frames(write(tmp_path, [flaser(1.0, [0.0, 2.0, 0.0])]))
    assert np.isnan(frame.scan.ranges[[0, 2]]).all() and frame.scan.ranges[1] == 2.0


def test_robotlaser_fov_of_n_times_or_n_minus_one_times_the_resolution(tmp_path: Path) -> None:
    res = math.radians(1.0)
    lines = [robotlaser(1.0, [1.0] * 180, fov=180 * res), robotlaser(2.0, [1.0] * 181, fov=180 * res)]
    assert len(frames(write(tmp_path, lines))) == 2  # both conventions of the Freiburg logs


@pytest.mark.parametrize("separator", ["  ", "\t", " \t ", "   "])
def test_any_whitespace_separates_fields(tmp_path: Path, separator: str) -> None:
    lines = [
        "PARAM laser_front_laser_resolution 1.0 host 0",
        flaser(1.0, RANGES, x=0.5),
        robotlaser(2.0, RANGES),
        "ODOM 0.5 0 0 0 0 0 1.5 host 1.5",
    ]
    plain = frames(write(tmp_path, lines[:2] + lines[3:], "plain.clf"), odometry="odom")
    spaced = [separator.join(line.split(" ")) for line in lines[:2] + lines[3:]]
    spaced[0] = separator + spaced[0] + separator  # leading and trailing whitespace too
    other = frames(write(tmp_path, spaced, "spaced.clf"), odometry="odom")
    assert len(other) == len(plain) == 1
    np.testing.assert_array_equal(plain[0].scan.ranges, other[0].scan.ranges)
    np.testing.assert_array_equal(plain[0].scan.angles, other[0].scan.angles)
    np.testing.assert_array_equal(plain[0].odometry, other[0].odometry)
    robot = [separator.join(lines[2].split(" "))]
    assert len(frames(write(tmp_path, robot, "robot.clf"))) == 1
