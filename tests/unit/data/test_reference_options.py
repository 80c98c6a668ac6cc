"""Dataset reference options every dataset takes: ``odometry=reference`` and ``views=D_M:A_DEG``."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.convert import convert
from albot1.data.degrade import degrade
from albot1.data.errors import DataError, ReferenceOptionError
from albot1.data.model import Frame, Scan, Sequence
from albot1.data.open import open_sequence, parse_views
from albot1.data.transforms import reference_odometry, view_spacing
from albot1.geometry import se2


def sequence(odometry: list[tuple[float, float, float]], *, reference: bool = True) -> Sequence:
    """An in-memory sequence with the given odometry (and, optionally, reference = odometry shifted by 1 m)."""
    angles = np.radians(np.arange(-90.0, 91.0, 45.0))
    frames = []
    for i, pose in enumerate(odometry):
        scan = Scan(ranges=np.full(len(angles), 2.0), angles=angles, timestamp=float(i), max_range=30.0)
        odo = np.asarray(pose, dtype=float)
        frames.append(Frame(i, scan, odo, odo + np.array([1.0, 0.0, 0.0]) if reference else None))
    return Sequence.from_frames("toy", frames)


def kept_stamps(seq: Sequence) -> list[float]:
    return [float(t) for t in seq.timestamps]


def test_views_keep_exactly_what_the_rule_says() -> None:
    """0.3 m steps with D = 1 m: kept at 0, 1.2, 2.4 m (0.9 m is short of 1 m); 4 deg turns with A = 10: 12, 24 deg."""
    straight = [(0.3 * k, 0.0, 0.0) for k in range(10)]  # x = 0 ... 2.7
    turning = [(2.7, 0.0, math.radians(4.0 * k)) for k in range(1, 7)]  # turn on the spot to 24 deg
    seq = view_spacing(sequence(straight + turning), 1.0, 10.0)
    # scans: 0 (x 0), 4 (x 1.2), 8 (x 2.4), 12 (0.3 m and 12 deg since scan 8), 15 (24 deg: 12 deg since 12)
    assert kept_stamps(seq) == [0.0, 4.0, 8.0, 12.0, 15.0]
    assert [f.index for f in seq.frames()] == [0, 1, 2, 3, 4]  # renumbered
    frames = list(seq.frames())
    np.testing.assert_array_equal(frames[1].odometry, [1.2, 0.0, 0.0])
    np.testing.assert_array_equal(frames[1].reference, [2.2, 0.0, 0.0])  # reference and scan travel along


def test_views_measure_the_straight_line_and_the_wrapped_heading() -> None:
    # A 0.8 m square side then back: the path is long but the displacement never reaches 1 m.
    there_and_back = [(0.0, 0.0, 0.0), (0.4, 0.0, 0.0), (0.8, 0.0, 0.0), (0.4, 0.0, 0.0), (0.0, 0.0, 0.0)]
    assert kept_stamps(view_spacing(sequence(there_and_back), 1.0, 90.0)) == [0.0]
    # 175 deg -> -178 deg is a 7 deg turn, not 353 deg.
    across_pi = [(0.0, 0.0, math.radians(175.0)), (0.0, 0.0, math.radians(-178.0)), (0.0, 0.0, math.radians(-174.0))]
    assert kept_stamps(view_spacing(sequence(across_pi), 1.0, 10.0)) == [0.0, 2.0]


def test_ten_decimetre_steps_make_a_metre() -> None:
    """0.1 m steps summed in floating point fall short of 1 m by 1e-16; the rule's slack keeps that view."""
    x = np.cumsum([0.0] + [0.1] * 20)
    assert x[10] < 1.0
    seq = view_spacing(sequence([(float(v), 0.0, 0.0) for v in x]), 1.0, 10.0)
    assert kept_stamps(seq) == [0.0, 10.0, 20.0]


def test_reference_odometry_replaces_the_odometry() -> None:
    seq = reference_odometry(sequence([(0.0, 0.0, 0.0), (0.5, 0.1, 0.2)]))
    np.testing.assert_array_equal(seq.odometry, seq.reference)
    np.testing.assert_array_equal(seq.odometry[1], [1.5, 0.1, 0.2])
    assert seq.metadata.odometry_source.startswith("reference poses as odometry")


def test_reference_odometry_names_the_scan_without_a_reference() -> None:
    with pytest.raises(ReferenceOptionError, match="toy: odometry=reference .* scan 0 has none"):
        list(reference_odometry(sequence([(0.0, 0.0, 0.0)], reference=False)).frames())


def test_world_with_reference_odometry_and_views() -> None:
    seq = open_sequence("synthetic-office-loop?odometry=reference&views=1:10")
    np.testing.assert_array_equal(seq.odometry, seq.reference)
    steps = se2.relative_steps(seq.reference)
    moved, turned = np.hypot(steps[:, 0], steps[:, 1]), np.degrees(np.abs(steps[:, 2]))
    # Every kept step reached 1 m or 10 deg (the 0.1 m / 1 deg world steps in whole increments)...
    assert np.all((moved >= 1.0 - 1e-9) | (turned >= 10.0 - 1e-9))
    # ...and no kept step went beyond the first scan that reached one of them.
    assert np.all((moved <= 1.0 + 1e-9) | (turned <= 10.0 + 1e-9))
    assert seq.metadata.extra["view_spacing"] == {"distance_m": 1.0, "angle_deg": 10.0}
    assert 150 <= len(seq) <= 200


def test_degradation_acts_on_the_kept_views_steps() -> None:
    """The thesis degradation adds 0.1 m to each *kept* step: a 1 m view step becomes 1.1 m, not 1 m + 10 x 0.1."""
    seq = open_sequence("synthetic-office-loop?odometry=reference&views=1:10[:4]")
    ref_steps = se2.relative_steps(seq.reference)
    assert np.allclose(np.hypot(ref_steps[:, 0], ref_steps[:, 1]), 1.0) and np.allclose(ref_steps[:, 2], 0.0)
    degraded = degrade(seq, "thesis")
    steps = se2.relative_steps(degraded.odometry)
    np.testing.assert_allclose(np.hypot(steps[:, 0], steps[:, 1]), 1.1, atol=1e-12)
    np.testing.assert_allclose(steps[:, 2], math.radians(1.0), atol=1e-12)


def test_a_slice_applies_to_the_kept_views() -> None:
    assert open_sequence("synthetic-office-loop?views=1:10[:7]").count_scans() == 7


def test_views_must_be_two_positive_numbers() -> None:
    assert parse_views("0.1:1", "x") == (0.1, 1.0)
    for bad in ("1", "1:0", "a:10", "1:10:2", "-1:10", "inf:10"):
        with pytest.raises(ReferenceOptionError, match=r"'x': views=.*; expected views=D_M:A_DEG"):
            parse_views(bad, "x")
    with pytest.raises(ReferenceOptionError, match="'synthetic-office-loop': views=1; expected"):
        open_sequence("synthetic-office-loop?views=1")


def test_odometry_reference_on_a_log_without_reference_is_one_clear_error(tmp_path: Path) -> None:
    line = "FLASER 3 1.0 1.0 1.0 0 0 0 0 0 0 {t} host {t}"
    log = tmp_path / "plain.clf"
    log.write_text("\n".join(line.format(t=float(t)) for t in range(3)) + "\n")
    with pytest.raises(ReferenceOptionError, match="plain.clf'?: odometry=reference, but the dataset has no reference"):
        open_sequence(f"{log}?odometry=reference")
    assert open_sequence(f"{log}?views=1:10").count_scans() == 1  # it never moves: only the first scan is a view


@pytest.mark.parametrize(
    ("fmt", "what"), [("albot-log", "an albot log"), ("ros2-mcap", "a bag"), (None, "a synthetic world")]
)
@pytest.mark.parametrize("word", ["none", "truepos"])
def test_a_carmen_reference_keyword_on_another_source_says_what_reference_takes_there(
    tmp_path: Path, fmt: str | None, what: str, word: str
) -> None:
    """``reference=none`` on an albot log, a bag or a world used to be refused as an unknown option by a
    message that listed ``reference`` among the options every source takes."""
    ref = "synthetic-corridor"
    if fmt is not None:
        out = tmp_path / ("w.albotlog" if fmt == "albot-log" else "w")
        convert(open_sequence("synthetic-corridor[:3]"), out, fmt)
        ref = str(out)
    with pytest.raises(DataError) as caught:
        open_sequence(f"{ref}?reference={word}")
    assert str(caught.value).endswith(
        f"reference={word} is a CARMEN log's keyword (none, laser-pose, truepos, auto: which of its lines hold the "
        f"reference poses); for {what} reference= names a trajectory file (TUM, KITTI or a corrected CARMEN log)"
    )
