"""Adversarial checks of the degradations: the frame of a wrong laser offset, no-op SPECs, and clear SPEC errors."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from albot1.bench.suite import _check_degradations
from albot1.cli.app import main
from albot1.data.degrade import Degradation, DegradationSpecError, degrade, parse_spec
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata
from albot1.data.transforms import sensor_frame
from albot1.geometry import se2
from albot1.report.collect import severity_order

ANGLES = np.radians(np.arange(-90.0, 91.0))


def _mounted(odometry: np.ndarray, mounting: tuple[float, float, float]) -> Sequence:
    """Robot odometry (= reference) with the scanner at ``mounting`` on the robot."""
    frames = [
        Frame(i, Scan(np.full(ANGLES.shape, 1.0 + i), ANGLES, 0.5 * i, 30.0), np.array(p), np.array(p))
        for i, p in enumerate(odometry)
    ]
    return Sequence.from_frames("mounted", frames, SequenceMetadata(source="unit", sensor_offset=mounting))


def test_a_wrong_laser_offset_is_seen_from_the_scanner_when_the_scanner_sits_off_the_robots_centre() -> None:
    # The scanner sits 0.3 m ahead of the robot's centre, facing backwards. The robot drives 1 m, spins 90 deg on
    # the spot and drives 1 m. The scanner's own steps: 1 m backwards, then (0.3, -0.3, 90 deg) (the lever arm),
    # then 1 m backwards. offset:0.2:0:0 puts the odometry's frame 0.2 m ahead *of the scanner*: the method must
    # see inv(D) * M * D = (0.1, -0.1, 90 deg) for the spin, and the straight steps unchanged. The offset applied
    # in the robot's frame instead (0.2 m ahead of the robot = 0.5 m behind the scanner) gave (0.5, -0.5, 90 deg).
    robot = se2.integrate_steps([0.0, 0.0, 0.0], np.array([(1.0, 0.0, 0.0), (0.0, 0.0, math.pi / 2), (1.0, 0.0, 0.0)]))
    seq = _mounted(robot, (0.3, 0.0, math.pi))
    truth = se2.relative_steps(sensor_frame(seq).odometry)
    np.testing.assert_allclose(truth[1], [0.3, -0.3, math.pi / 2], atol=1e-12)
    seen = se2.relative_steps(sensor_frame(degrade(seq, "offset:0.2:0:0")).odometry)
    np.testing.assert_allclose(seen, [[-1.0, 0.0, 0.0], [0.1, -0.1, math.pi / 2], [-1.0, 0.0, 0.0]], atol=1e-12)
    # Reference poses are untouched by the degradation.
    np.testing.assert_array_equal(degrade(seq, "offset:0.2:0:0").reference, seq.reference)


def test_a_wrong_laser_offset_without_a_mounting_is_unchanged() -> None:
    robot = se2.integrate_steps([0.0, 0.0, 0.0], np.array([(0.0, 0.0, math.pi / 2)]))
    step = se2.relative_steps(degrade(_mounted(robot, (0.0, 0.0, 0.0)), "offset:0.2:0:0").odometry)[0]
    np.testing.assert_allclose(step, [-0.2, 0.2, math.pi / 2], atol=1e-12)


@pytest.mark.parametrize(
    "spec", ["gauss:0:0", "bias:0:0", "BIAS:-0:0", "offset:0:0:0", "dropout:0", "gauss:1e-400:0", "dropout:0.0"]
)
def test_a_spec_that_changes_nothing_is_refused_rather_than_scored_as_degraded(spec: str) -> None:
    with pytest.raises(DegradationSpecError) as info:
        parse_spec(spec)
    assert str(info.value) == (
        f"degradation {spec!r} changes nothing (every value is 0): its runs would repeat the undegraded run "
        "under a degraded label; write none"
    )


@pytest.mark.parametrize(
    ("spec", "says"),
    [
        ("gauss:0.1", "gauss takes 2 value(s) (gauss:SIGMA_XY_M:SIGMA_THETA_DEG), got 1"),
        ("offset:0.1:0", "offset takes 3 value(s) (offset:DX_M:DY_M:DTHETA_DEG), got 2"),
        ("dropout:0.1:1", "dropout takes 1 value(s) (dropout:P), got 2"),
        ("bias:\u22120.02:0.5", "value '\u22120.02' is not a plain finite number (bias:DX_M:DTHETA_DEG)"),
        ("gauss:1_0:1", "value '1_0' is not a plain finite number (gauss:SIGMA_XY_M:SIGMA_THETA_DEG)"),
        ("gauss:nan:1", "value 'nan' is not a plain finite number"),
        ("gauss:0.1:-1", "sigmas must be >= 0 (gauss:SIGMA_XY_M:SIGMA_THETA_DEG)"),
        ("noise:0.1:1", "not understood (unknown kind 'noise')"),
        # a combination used to read as a miscounted SPEC ("gauss takes 2 value(s), got 4")
        (
            "gauss:0.02:0.5,bias:-0.03:-1",
            "names 2 kinds (gauss, bias): a run takes one degradation, combinations are not supported",
        ),
        (
            "gauss:0.02:0.5 dropout:0.5",
            "names 2 kinds (gauss, dropout): a run takes one degradation, combinations are not supported",
        ),
        ("thesis+bias:0.1:1", "names 2 kinds (thesis, bias): a run takes one degradation"),
        # a kind without values given one used to read "unknown kind 'thesis'"
        ("thesis:1", "thesis takes no values"),
        ("none:0", "none takes no values"),
    ],
)
def test_a_bad_spec_names_what_its_kind_expected(spec: str, says: str) -> None:
    with pytest.raises(DegradationSpecError) as info:
        parse_spec(spec)
    assert str(info.value).startswith(f"degradation {spec!r}")
    assert says in str(info.value)
    assert "\n" not in str(info.value)


def test_minus_zero_is_zero_in_the_label() -> None:
    assert parse_spec("bias:-0:0.5").spec == "bias:0:0.5"
    assert parse_spec(" gauss: 0.1 : 1 ").spec == "gauss:0.1:1"


@pytest.mark.parametrize(
    "spec", ["gauss:0.1234567:1", "bias:1234567:0.5", "offset:0.2:0.05:2.25", "dropout:0.3333333", "gauss:0.05:2"]
)
def test_the_label_names_the_level_that_was_run(spec: str) -> None:
    assert parse_spec(spec).spec == spec
    label = degrade(_mounted(np.zeros((2, 3)), (0.0, 0.0, 0.0)), spec, seed=4)
    named = label.metadata.extra.get("scan_dropout") or label.metadata.odometry_source
    assert named.endswith(f"{spec} seed 4" if parse_spec(spec).seeded else f"degraded {spec}")


@pytest.mark.parametrize("spec", ["thesis", "bias:0.02:0.5", "offset:0.2:0.05:2"])
def test_a_deterministic_degradation_claims_no_seed(spec: str) -> None:
    seq = degrade(_mounted(np.zeros((2, 3)), (0.0, 0.0, 0.0)), spec, seed=7)
    assert seq.metadata.odometry_source == f"odometry degraded {parse_spec(spec).spec}"


FINITE = st.floats(-100, 100, allow_nan=False).filter(lambda v: v != 0)


@given(st.sampled_from(["gauss", "bias", "offset", "dropout"]), st.lists(FINITE.map(repr), max_size=5))
def test_a_wrong_number_of_values_names_the_kinds_form(kind: str, values: list[str]) -> None:
    arity = {"gauss": 2, "bias": 2, "offset": 3, "dropout": 1}[kind]
    if len(values) == arity:
        return
    with pytest.raises(DegradationSpecError, match=f"{kind} takes {arity} value\\(s\\) .*got {len(values)}"):
        parse_spec(":".join([kind, *values]))


@given(st.floats(0.001, 10, allow_nan=False), st.sampled_from(["_", "\u2212", "\u00a0", "\u0660", "j"]))
def test_a_number_python_would_stretch_to_read_is_refused(value: float, odd: str) -> None:
    text = repr(value)
    spelled = text[:1] + odd + text[1:] if odd != "\u0660" else text.replace(text[0], "\u0660", 1)
    with pytest.raises(DegradationSpecError, match="is not a plain finite number"):
        parse_spec(f"gauss:{spelled}:1")


def test_albot1_run_refuses_a_bad_degradation_before_opening_the_log(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: object
) -> None:
    monkeypatch.setattr(sys, "argv", ["albot1", "run", "odometry", "no-such-log", "--degrade", "gauss:0.1"])
    with pytest.raises(SystemExit) as info:
        main()
    err = capsys.readouterr().err
    assert info.value.code != 0
    assert err.strip().splitlines() == [
        "albot1: error: degradation 'gauss:0.1': gauss takes 2 value(s) (gauss:SIGMA_XY_M:SIGMA_THETA_DEG), got 1; "
        "expected none, thesis, gauss:SIGMA_XY_M:SIGMA_THETA_DEG, bias:DX_M:DTHETA_DEG, "
        "offset:DX_M:DY_M:DTHETA_DEG or dropout:P"
    ]


def test_a_stored_run_of_a_no_op_spec_stays_readable() -> None:
    assert parse_spec("gauss:0:0", stored=True) == Degradation("gauss")
    assert severity_order(["dropout:0", "gauss:0.1:1", "none"]) == ["none", "gauss:0.1:1", "dropout:0"]


def test_a_spec_written_two_ways_is_one_run_key(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    folders = []
    for spelling in (" GAUSS:0.10:1.0 ", "gauss:0.1:1"):
        args = ["albot1", "run", "odometry", "synthetic-corridor[:4]", "--degrade", spelling]
        monkeypatch.setattr(sys, "argv", [*args, "--out", str(tmp_path), "--json"])
        with pytest.raises(SystemExit) as info:
            main()
        assert info.value.code == 0
        summary = json.loads(capsys.readouterr().out)
        assert summary["degradation"] == "gauss:0.1:1"
        folders.append(summary["run_dir"])
    assert folders[0] == folders[1]


def test_a_suite_records_its_degradations_in_their_one_spelling() -> None:
    assert _check_degradations(("GAUSS:0.10:1.0", "bias:-0:0.5", "thesis")) == ("gauss:0.1:1", "bias:0:0.5", "thesis")


@pytest.mark.parametrize(("spec", "turn"), [("bias:0:720", "720"), ("offset:0:0:360", "360"), ("bias:0:-360", "-360")])
def test_a_whole_number_of_turns_without_translation_is_refused_as_changing_nothing(spec: str, turn: str) -> None:
    """`bias:0:720` used to run and be tabled as a degraded level while its odometry was the undegraded one."""
    with pytest.raises(DegradationSpecError) as info:
        parse_spec(spec)
    assert str(info.value) == (
        f"degradation {spec!r} changes nothing (no translation, and {turn} deg is a whole number of turns): its runs "
        "would repeat the undegraded run under a degraded label; write none"
    )
    assert parse_spec(spec, stored=True).kind == spec.split(":")[0]  # a run already made stays readable


@pytest.mark.parametrize("spec", ["bias:0.01:720", "offset:0:0.1:360", "bias:0:1", "gauss:0:360"])
def test_a_whole_turn_with_anything_else_still_degrades(spec: str) -> None:
    assert parse_spec(spec).kind == spec.split(":")[0]


@pytest.mark.parametrize(
    ("spec", "says"),
    [
        ("dropout:0.9999999999999", "0.9999999999999 being 1 to the 12 significant digits"),
        ("bias:0:359.9999999999", "0:359.9999999999 being 0:360 to the 12 significant digits"),
        ("offset:0:0:-720.0000000000001", "0:0:-720.0000000000001 being 0:0:-720 to the 12 significant digits"),
    ],
)
def test_a_spec_whose_label_rounds_to_a_refused_level_is_refused_as_written(spec: str, says: str) -> None:
    """`albot1 run` and suites run the label (12 significant digits): its level is the one checked.

    ``dropout:0.9999999999999`` was accepted, labelled ``dropout:1`` and then refused when the run
    started, quoting ``'dropout:1'``, a SPEC nobody wrote.
    """
    with pytest.raises(DegradationSpecError) as info:
        parse_spec(spec)
    assert str(info.value).startswith(f"degradation {spec!r}") and says in str(info.value)


@given(
    st.sampled_from(["gauss", "bias", "offset", "dropout"]),
    st.lists(st.floats(-1e6, 1e6, allow_nan=False).map(repr), min_size=3, max_size=3),
)
def test_every_accepted_spec_runs_the_level_its_label_names(kind: str, values: list[str]) -> None:
    """The label parses back to the same level, so the run (which parses the label) is the level checked here."""
    arity = {"gauss": 2, "bias": 2, "offset": 3, "dropout": 1}[kind]
    spec = ":".join([kind, *values[:arity]])
    try:
        parsed = parse_spec(spec)
    except DegradationSpecError:
        return
    assert parse_spec(parsed.spec) == parsed
