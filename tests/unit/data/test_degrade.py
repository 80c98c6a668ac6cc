"""Odometry degradation (albot1.data.degrade): exact per-step effects, seeding, and what is left untouched."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest

from albot1.data.degrade import Degradation, DegradationSpecError, check_seed, degrade, parse_spec
from albot1.data.errors import DataError
from albot1.data.model import Frame, Relations, Scan, Sequence, SequenceMetadata
from albot1.geometry import se2

ANGLES = np.radians(np.arange(-90.0, 91.0))


def _sequence(odometry: np.ndarray, name: str = "route") -> Sequence:
    """A sequence with the given odometry, a distinct scan per frame and reference = odometry."""
    frames = []
    for i, pose in enumerate(odometry):
        ranges = np.full(ANGLES.shape, 1.0 + i)
        ranges[::7] = np.nan
        frames.append(
            Frame(
                i, Scan(ranges, ANGLES, 0.5 * i, 30.0), np.array(pose, dtype=float), np.array(pose, dtype=float) + 100.0
            )
        )
    relations = Relations(np.array([0.0]), np.array([1.0]), np.array([[1.0, 0.0, 0.0]]))
    return Sequence.from_frames(name, frames, SequenceMetadata(source="unit", odometry_source="wheels"), relations)


def _straight(steps: int, length: float = 1.0) -> np.ndarray:
    return np.column_stack([np.arange(steps + 1) * length, np.zeros(steps + 1), np.zeros(steps + 1)])


def _route() -> np.ndarray:
    """1 m moves and 45 deg turns on the spot, like the thesis's start-stop routes."""
    steps = (
        [(1.0, 0.0, 0.0)] * 4
        + [(0.0, 0.0, math.pi / 4)] * 2
        + [(1.0, 0.0, 0.0)] * 3
        + [(0.0, 0.0, -math.pi / 4)]
        + [(0.7, 0.0, 0.0)]
    )
    return se2.integrate_steps([2.0, -1.0, 0.3], np.array(steps))


def test_thesis_adds_exactly_a_tenth_of_a_metre_and_a_degree_to_every_straight_step() -> None:
    seq = degrade(_sequence(_straight(10)), "thesis")
    odo = seq.odometry
    steps = se2.relative_steps(odo)
    np.testing.assert_allclose(steps[:, 0], 1.1, atol=1e-12)
    np.testing.assert_allclose(steps[:, 1], 0.0, atol=1e-12)
    np.testing.assert_allclose(steps[:, 2], math.radians(1.0), atol=1e-12)
    # Accumulated: the heading grows by exactly 1 deg per step, the path by exactly 1.1 m per step.
    np.testing.assert_allclose(odo[:, 2], np.radians(np.arange(11)), atol=1e-12)
    np.testing.assert_allclose(se2.path_length(odo), 11.0, atol=1e-12)
    np.testing.assert_array_equal(odo[0], [0.0, 0.0, 0.0])
    # Each step is 1.1 m along the heading reached after the previous steps.
    expected = [np.zeros(2)]
    for k in range(10):
        heading = math.radians(k)
        expected.append(expected[-1] + 1.1 * np.array([math.cos(heading), math.sin(heading)]))
    np.testing.assert_allclose(odo[:, :2], np.array(expected), atol=1e-12)


def test_thesis_lengthens_each_step_along_its_own_direction_and_adds_a_degree_to_turns() -> None:
    truth = _route()
    got = se2.relative_steps(degrade(_sequence(truth), "thesis").odometry)
    want = se2.relative_steps(truth)
    for g, w in zip(got, want, strict=True):
        dist = math.hypot(w[0], w[1])
        if dist > 1e-9:
            np.testing.assert_allclose(g[:2], w[:2] * (dist + 0.1) / dist, atol=1e-12)
        else:  # a turn on the spot gains the 0.1 m forward
            np.testing.assert_allclose(g[:2], [0.1, 0.0], atol=1e-12)
        assert g[2] == pytest.approx(float(se2.wrap(w[2] + math.radians(1.0))), abs=1e-12)


def test_bias_accumulates_exactly() -> None:
    seq = degrade(_sequence(_straight(8, 0.5)), "bias:0.05:-2")
    odo = seq.odometry
    steps = se2.relative_steps(odo)
    np.testing.assert_allclose(steps, np.tile([0.55, 0.0, math.radians(-2.0)], (8, 1)), atol=1e-12)
    np.testing.assert_allclose(odo[:, 2], np.radians(-2.0 * np.arange(9)), atol=1e-12)
    np.testing.assert_allclose(se2.path_length(odo), 8 * 0.55, atol=1e-12)


def test_none_returns_the_sequence_itself() -> None:
    seq = _sequence(_route())
    assert degrade(seq, "none") is seq
    assert degrade(seq, "") is seq


def test_gauss_is_seeded_and_reiterating_gives_identical_odometry() -> None:
    seq = _sequence(_route())
    a = degrade(seq, "gauss:0.05:2", seed=7)
    first = np.array([f.odometry for f in a])
    second = np.array([f.odometry for f in a])
    np.testing.assert_array_equal(first, second)
    np.testing.assert_array_equal(first, degrade(seq, "gauss:0.05:2", seed=7).odometry)
    assert not np.allclose(first, degrade(seq, "gauss:0.05:2", seed=8).odometry)
    np.testing.assert_array_equal(first[0], seq.odometry[0])
    assert not np.allclose(first[1:], seq.odometry[1:])


def test_gauss_noise_is_zero_mean_with_the_given_sigmas() -> None:
    steps = 4000
    seq = _sequence(_straight(steps, 0.2))
    noisy = se2.relative_steps(degrade(seq, "gauss:0.03:1.5", seed=3).odometry)
    err = noisy - np.array([0.2, 0.0, 0.0])
    err[:, 2] = se2.wrap(err[:, 2])
    sigma = np.array([0.03, 0.03, math.radians(1.5)])
    # Means within 4 standard errors of zero; standard deviations within 5 %.
    assert np.all(np.abs(err.mean(axis=0)) < 4 * sigma / math.sqrt(steps))
    np.testing.assert_allclose(err.std(axis=0), sigma, rtol=0.05)


def test_a_parsed_gauss_with_zero_sigmas_changes_nothing() -> None:
    # As a SPEC it is refused (tests/unit/data/test_degrade_checks.py); built directly it is the identity.
    seq = _sequence(_route())
    np.testing.assert_allclose(degrade(seq, Degradation("gauss"), seed=1).odometry, seq.odometry, atol=1e-12)
    assert not Degradation("gauss").seeded


@pytest.mark.parametrize("spec", ["thesis", "gauss:0.1:3", "bias:0.2:5"])
def test_scans_reference_timestamps_relations_and_name_are_untouched(spec: str) -> None:
    seq = _sequence(_route())
    out = degrade(seq, spec, seed=11)
    assert out.name == seq.name
    assert out.relations is seq.relations
    assert len(out) == len(seq)
    for before, after in zip(seq, out, strict=True):
        assert after.index == before.index
        assert after.scan is before.scan
        np.testing.assert_array_equal(after.reference, before.reference)
    np.testing.assert_array_equal(out.timestamps, seq.timestamps)
    assert out.metadata.source == "unit"
    seeded = " seed 11" if parse_spec(spec).seeded else ""  # a deterministic SPEC claims no seed
    assert out.metadata.odometry_source == f"wheels degraded {parse_spec(spec).spec}{seeded}"
    # The input sequence's own odometry is not modified by degrading it.
    np.testing.assert_array_equal(seq.odometry, _sequence(_route()).odometry)


def test_degradation_acts_on_relative_motion_so_the_start_pose_is_kept() -> None:
    truth = _route()
    for spec in ("thesis", "gauss:0.1:3", "bias:0.2:5"):
        np.testing.assert_array_equal(degrade(_sequence(truth), spec, seed=2).odometry[0], truth[0])


def test_a_parsed_degradation_object_is_accepted() -> None:
    seq = _sequence(_straight(3))
    np.testing.assert_array_equal(degrade(seq, parse_spec("bias:0.1:1")).odometry, degrade(seq, "bias:0.1:1").odometry)


@pytest.mark.parametrize(
    ("text", "kind", "a", "b_deg"),
    [
        ("none", "none", 0.0, 0.0),
        ("  Thesis ", "thesis", 0.1, 1.0),
        ("gauss:0.05:2", "gauss", 0.05, 2.0),
        ("bias:-0.1:-1.5", "bias", -0.1, -1.5),
        ("BIAS:0:0.5", "bias", 0.0, 0.5),
    ],
)
def test_parse_spec(text: str, kind: str, a: float, b_deg: float) -> None:
    deg = parse_spec(text)
    assert (deg.kind, deg.a) == (kind, pytest.approx(a))
    assert math.degrees(deg.b) == pytest.approx(b_deg)


@pytest.mark.parametrize("spec", ["none", "thesis", "gauss:0.05:2", "bias:-0.1:-1.5"])
def test_spec_round_trips(spec: str) -> None:
    assert parse_spec(spec).spec == spec
    assert parse_spec(parse_spec(spec).spec) == parse_spec(spec)


@pytest.mark.parametrize(
    "spec",
    [
        "thesis:1",
        "gauss",
        "gauss:0.1",
        "gauss:0.1:2:3",
        "bias:1",
        "noise:0.1:1",
        "gauss:a:b",
        "bias:0.1:x",
        "gauss:nan:1",
        "bias:inf:0",
        "gauss:-0.1:1",
        "gauss:0.1:-1",
        ":",
        "gauss::",
        "offset:0.1:0",
        "offset:0.1:0:2:1",
        "offset:0.1:nan:2",
        "dropout",
        "dropout:0.1:1",
        "dropout:1",
        "dropout:-0.1",
        "dropout:x",
    ],
)
def test_bad_specs_raise_with_the_expected_format(spec: str) -> None:
    with pytest.raises(DegradationSpecError) as info:
        parse_spec(spec)
    message = str(info.value)
    assert repr(spec) in message
    assert (
        "expected none, thesis, gauss:SIGMA_XY_M:SIGMA_THETA_DEG, bias:DX_M:DTHETA_DEG, offset:DX_M:DY_M:DTHETA_DEG "
        "or dropout:P" in message
    )
    assert isinstance(info.value, DataError)


def test_bad_spec_is_rejected_by_degrade_before_iterating() -> None:
    with pytest.raises(DegradationSpecError):
        degrade(_sequence(_straight(2)), "gauss:1")


def test_degradation_dataclass_perturb_of_none_is_identity() -> None:
    step = np.array([0.3, -0.1, 0.2])
    np.testing.assert_array_equal(Degradation("none").perturb(step, np.random.default_rng(0)), step)


@pytest.mark.parametrize("seed", [-1, -(2**40), 2**63, True, 1.5, "3"])
def test_a_seed_outside_0_to_2_63_is_refused_before_any_scan_is_read(seed: object) -> None:
    def frames() -> Iterator[Frame]:
        raise AssertionError("the sequence was read")
        yield  # pragma: no cover

    sequence = Sequence("never-read", frames, _sequence(_straight(2)).metadata)
    for spec in ("none", "gauss:0.1:1"):
        with pytest.raises(DegradationSpecError, match=r"seed .*: expected an integer from 0 to 9223372036854775807"):
            degrade(sequence, spec, seed=seed)  # type: ignore[arg-type]


def test_seeds_at_the_bounds_and_numpy_integers_are_accepted() -> None:
    assert check_seed(0) == 0 and check_seed(2**63 - 1) == 2**63 - 1
    assert check_seed(np.int64(7)) == 7 and type(check_seed(np.uint32(7))) is int


def test_a_wrong_laser_offset_turns_a_spin_on_the_spot_into_an_arc_and_keeps_straight_steps() -> None:
    # The odometry frame sits 0.2 m ahead of the scanner: a 90 deg turn on the spot of the scanner reads, in the
    # odometry frame, as a move of 0.2 * sqrt(2) m (from (0.2, 0) to (0, 0.2) seen from the start).
    spin = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, math.pi / 2]])
    seq = degrade(_sequence(spin), "offset:0.2:0:0")
    step = se2.relative_steps(seq.odometry)[0]
    np.testing.assert_allclose(step, [-0.2, 0.2, math.pi / 2], atol=1e-12)
    straight = degrade(_sequence(_straight(3)), "offset:0.2:0:0").odometry
    np.testing.assert_allclose(straight, _straight(3), atol=1e-12)  # no turn: a forward mounting changes nothing
    # A mounting turned by 90 deg: each 1 m forward step of the scanner is a 1 m step to the right of that frame.
    turned = se2.relative_steps(degrade(_sequence(_straight(2)), "offset:0:0:90").odometry)
    np.testing.assert_allclose(turned, [[0.0, -1.0, 0.0]] * 2, atol=1e-12)
    assert parse_spec("offset:0.2:-0.1:3").spec == "offset:0.2:-0.1:3"
    assert not parse_spec("offset:0.2:0:0").seeded


def test_scan_dropout_keeps_the_first_scan_renumbers_and_repeats_with_its_seed() -> None:
    seq = _sequence(_straight(40))
    kept = list(degrade(seq, "dropout:0.5", seed=3).frames())
    again = list(degrade(seq, "dropout:0.5", seed=3).frames())
    other = list(degrade(seq, "dropout:0.5", seed=4).frames())
    assert [f.index for f in kept] == list(range(len(kept)))
    assert kept[0].scan.timestamp == 0.0  # the first scan always stays
    assert [f.scan.timestamp for f in kept] == [f.scan.timestamp for f in again]
    assert [f.scan.timestamp for f in kept] != [f.scan.timestamp for f in other]
    assert 5 < len(kept) < 36  # about half of 40 after the first (binomial(40, 0.5): far inside 5 sigma)
    by_time = {f.scan.timestamp: f for f in seq.frames()}
    for frame in kept:  # each kept scan keeps its own odometry, reference pose and ranges
        source = by_time[frame.scan.timestamp]
        np.testing.assert_array_equal(frame.odometry, source.odometry)
        np.testing.assert_array_equal(frame.reference, source.reference)
        np.testing.assert_array_equal(frame.scan.ranges, source.scan.ranges)
    assert degrade(seq, "dropout:0.5", seed=3).metadata.extra["scan_dropout"] == "dropout:0.5 seed 3"
    assert len(list(degrade(seq, Degradation("dropout"), seed=3).frames())) == 41
    assert parse_spec("dropout:0.25").seeded and not Degradation("dropout").seeded
