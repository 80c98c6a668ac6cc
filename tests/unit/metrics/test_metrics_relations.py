"""The relation metric (Kuemmerle et al. 2009) and RPE on constructed cases."""

from __future__ import annotations

import numpy as np
import pytest

from albot1.data.model import Relations
from albot1.geometry import se2
from albot1.metrics.blocks import block_of
from albot1.metrics.errors import MetricsError
from albot1.metrics.measures.rpe import RpeBlock, headline
from albot1.metrics.relations import relation_metric
from albot1.metrics.rpe import pair_indices, rpe, rpe_set


def straight(n: int = 21) -> tuple[np.ndarray, np.ndarray]:
    stamps = np.arange(n) * 2.0  # one scan every 2 s, 1 m apart
    return stamps, np.column_stack([np.arange(n, dtype=float), np.zeros(n), np.zeros(n)])


def relations_from(stamps: np.ndarray, poses: np.ndarray, pairs: list[tuple[int, int]]) -> Relations:
    i = np.array([p[0] for p in pairs])
    j = np.array([p[1] for p in pairs])
    return Relations(t1=stamps[i], t2=stamps[j], poses=se2.between(poses[i], poses[j]))


def test_a_perfect_estimate_has_zero_relation_error_even_in_another_frame() -> None:
    stamps, ref = straight()
    rel = relations_from(stamps, ref, [(0, 1), (3, 9), (0, 20)])
    est = se2.compose(np.array([5.0, -2.0, 1.0]), ref)
    block = relation_metric(stamps, est, rel)
    assert block["translation_m"]["max"] == pytest.approx(0.0, abs=1e-12)
    assert block["rotation_deg"]["max"] == pytest.approx(0.0, abs=1e-9)
    assert block["translation_m"]["n"] == 3


def test_a_known_error_gives_known_statistics_with_sample_std() -> None:
    stamps, ref = straight()
    est = ref.copy()
    est[10:, 0] += 0.5  # a 0.5 m jump forward between scans 9 and 10
    est[15:, 2] += np.radians(3.0)  # and a 3 deg turn between 14 and 15
    rel = relations_from(stamps, ref, [(0, 5), (8, 12), (13, 17), (16, 20)])
    block = relation_metric(stamps, est, rel)
    # (13, 17): est rel = (4, 0, 3 deg) vs (4, 0, 0): rotation 3 deg only.
    # (16, 20): both ends turned 3 deg, positions not: the 4 m step is seen 3 deg off,
    # a chord error of 2 * 4 * sin(1.5 deg).
    trans = np.array([0.0, 0.5, 0.0, 8.0 * np.sin(np.radians(1.5))])
    rot = np.array([0.0, 0.0, 3.0, 0.0])
    assert block["translation_m"]["mean"] == pytest.approx(trans.mean())
    assert block["translation_m"]["std"] == pytest.approx(trans.std(ddof=1))
    assert block["translation_m"]["max"] == pytest.approx(0.5)
    assert block["translation_m"]["min"] == pytest.approx(0.0, abs=1e-12)
    assert block["rotation_deg"]["mean"] == pytest.approx(rot.mean())
    assert block["rotation_deg"]["std"] == pytest.approx(rot.std(ddof=1))
    assert block["translation_squared_m2"]["mean"] == pytest.approx(np.mean(trans**2))
    assert block["rotation_squared_deg2"]["max"] == pytest.approx(9.0)


def test_loop_relations_are_those_spanning_more_than_30_s() -> None:
    stamps, ref = straight()
    est = ref.copy()
    est[:, 1] = 0.01 * np.arange(21)  # sideways drift
    rel = relations_from(stamps, ref, [(0, 1), (0, 15), (0, 20), (5, 19)])  # spans 2, 30, 40, 28 s
    block = relation_metric(stamps, est, rel)
    assert block["loops"]["translation_m"]["n"] == 1
    assert block["loops"]["translation_m"]["max"] == pytest.approx(0.2)  # (0, 20): 0.2 m sideways


def test_a_relation_time_without_a_scan_names_the_relation_line() -> None:
    stamps, ref = straight()
    rel = relations_from(stamps, ref, [(0, 1), (2, 3), (4, 5)])
    bad = Relations(t1=rel.t1.copy(), t2=rel.t2.copy(), poses=rel.poses)
    bad.t2[2] += 0.5
    with pytest.raises(MetricsError, match=r"rel\.txt:3: no pose within 0\.0001 s of time 10\.5"):
        relation_metric(stamps, ref, bad, source="rel.txt")


def test_relations_outside_a_prefix_run_are_excluded_and_counted_when_asked() -> None:
    stamps, ref = straight()
    rel = relations_from(stamps, ref, [(0, 1), (2, 3), (15, 18)])
    block = relation_metric(stamps[:10], ref[:10], rel, outside="exclude")
    assert (block["relations_used"], block["relations_outside_run"]) == (2, 1)
    with pytest.raises(MetricsError, match=":3: no pose within"):
        relation_metric(stamps[:10], ref[:10], rel)


def test_relations_are_looked_up_by_stamp_in_a_log_whose_stamps_go_back() -> None:
    # The Intel log: a scan stamped earlier than its predecessor. Relations name scans by stamp,
    # so (t1, t2) with t2 < t1 is the pose of the later-logged scan seen from the earlier-logged one.
    stamps = np.array([0.0, 2.0, 1.5, 3.0])
    ref = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [2.0, 0.5, 0.2], [3.0, 0.5, 0.3]])
    rel = Relations(t1=np.array([2.0, 0.0]), t2=np.array([1.5, 3.0]), poses=se2.between(ref[[1, 0]], ref[[2, 3]]))
    block = relation_metric(stamps, ref, rel)
    assert block["translation_m"]["max"] == pytest.approx(0.0, abs=1e-12)
    assert block["relations_used"] == 2
    swapped = relation_metric(stamps, ref, Relations(rel.t2, rel.t1, rel.poses))
    assert swapped["translation_m"]["max"] > 2.0  # reading it the other way round is wrong


def test_five_decimal_relation_stamps_match_six_decimal_scan_stamps() -> None:
    # mit-csail: the log prints 1134864645.903214, the relations file 1134864645.90321.
    stamps = np.array([1134864645.903214, 1134864646.324196, 1134864646.532199])
    ref = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.2], [0.5, 0.1, 0.3]])
    rel = Relations(
        t1=np.array([1134864645.90321, 1134864646.32420]),
        t2=np.array([1134864646.32420, 1134864646.53220]),
        poses=se2.between(ref[[0, 1]], ref[[1, 2]]),
    )
    block = relation_metric(stamps, ref, rel)
    assert block["relations_used"] == 2
    assert block["translation_m"]["max"] == pytest.approx(0.0, abs=1e-12)


def test_rpe_pairs_by_frames_and_by_reference_travel() -> None:
    _, ref = straight(11)
    assert pair_indices(ref, 3, "frames").tolist() == [[0, 3], [3, 6], [6, 9]]
    assert pair_indices(ref, 2.5, "m").tolist() == [[0, 3], [3, 6], [6, 9]]


def test_rpe_of_a_constant_per_step_heading_bias() -> None:
    _, ref = straight(11)
    est = se2.integrate_steps(ref[0], se2.relative_steps(ref) + np.array([0.0, 0.0, np.radians(1.0)]))
    one = rpe(est, ref, 1, "frames")
    assert one["rotation_deg"]["mean"] == pytest.approx(1.0)
    # Over one step the translation of the step is unchanged (the turn happens after it).
    assert one["translation_m"]["max"] == pytest.approx(0.0, abs=1e-12)
    two = rpe(est, ref, 2, "frames")
    # inv(Q) P for P = step(1 m) turned 1 deg then 1 m: error |(cos1 - 1, sin1)| m.
    assert two["translation_m"]["mean"] == pytest.approx(np.hypot(np.cos(np.radians(1)) - 1, np.sin(np.radians(1))))
    block = rpe_set(est, ref)
    assert [d["delta_unit"] for d in block["deltas"]] == ["frames", "m", "m"]
    assert block["translation_m"] == block["deltas"][0]["translation_m"]


@pytest.mark.parametrize("outside", ["error", "exclude"])
def test_a_relation_end_on_a_stamp_several_scans_share_is_refused_naming_its_line(outside: str) -> None:
    """Stamps 0, 0, 0, 1, 1, 1: the lookup took the first scan of each stamp and scored 0.0 m (old code)."""
    ref = np.column_stack([np.arange(6.0), np.zeros(6), np.zeros(6)])
    stamps = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    rel = Relations(t1=np.array([0.0]), t2=np.array([1.0]), poses=np.array([[3.0, 0.0, 0.0]]))
    message = (
        "r.relations:1: time 0.000000 is the stamp of 3 scans, so which one the relation names cannot be told; "
        "expected each relation end to name one scan, its own (1 relation(s) affected)"
    )
    with pytest.raises(MetricsError) as caught:
        relation_metric(stamps, ref, rel, outside=outside, source="r.relations")  # type: ignore[arg-type]
    assert str(caught.value) == message


def test_a_relation_whose_two_ends_find_one_scan_is_refused() -> None:
    """t1 != t2 (the reader's check) but both within the 0.1 ms tolerance of scan 2: old code scored it 0.3 m."""
    ref = np.column_stack([np.arange(6.0), np.zeros(6), np.zeros(6)])
    rel = Relations(t1=np.array([2.0]), t2=np.array([2.00005]), poses=np.array([[0.3, 0.0, 0.0]]))
    with pytest.raises(MetricsError) as caught:
        relation_metric(np.arange(6.0), ref, rel)
    assert str(caught.value) == (
        "relations:1: both ends name scan 2 (time 2.000000): a relation from a scan to itself; expected each "
        "relation end to name one scan, its own (1 relation(s) affected)"
    )


def test_an_rpe_step_without_a_pair_is_null_and_says_why() -> None:
    """A step longer than the log, a robot that stands still: null statistics and the reason (old: nulls only)."""
    _, ref = straight(3)
    long = rpe(ref, ref, 5, "frames")
    assert (long["pairs"], long["translation_m"]["n"], long["pairs_reason"]) == (
        0,
        0,
        "3 pose(s): none 5 frames after another",
    )
    still = np.tile([1.0, 2.0, 0.3], (20, 1))
    parked = rpe(still + 0.001, still, 1.0, "m")
    assert parked["pairs"] == 0 and np.isnan(parked["translation_m"]["rmse"])
    assert parked["pairs_reason"] == "the reference travels 0 m in all, less than one step of 1 m"
    assert "pairs_reason" not in rpe(ref, ref, 1, "frames")  # a step with pairs has none
    block = block_of(RpeBlock, rpe_set(still, still))
    assert block.pairs == 19 and block.pairs_reason is None  # 1 frame: pairs; 1 m and 10 m: none
    assert [d.pairs_reason for d in block.deltas][1:] == [
        "the reference travels 0 m in all, less than one step of 1 m",
        "the reference travels 0 m in all, less than one step of 10 m",
    ]
    assert "pairs_reason" not in block.model_dump()  # written only when set
    single = block_of(RpeBlock, rpe_set(still[:1], still[:1]))
    assert headline(single) == "delta 1 frames: n/a (1 pose(s): none 1 frames after another)"


@pytest.mark.parametrize(("counted", "n", "reading"), [(False, 1, "counted once"), (True, 2, "counted as listed")])
def test_the_block_records_repeated_lines_and_how_they_were_read(counted: bool, n: int, reading: str) -> None:
    from albot1.metrics.blocks import block_of
    from albot1.metrics.measures.relations import RelationsBlock, headline

    times = np.array([0.0, 1.0])
    poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    rows = n
    relations = Relations(
        t1=np.zeros(rows),
        t2=np.ones(rows),
        poses=np.tile([1.1, 0.0, 0.0], (rows, 1)),
        repeats=1,
        repeats_counted=counted,
    )
    block = relation_metric(times, poses, relations)
    assert (block["relations_repeated_lines"], block["relations_repeats_counted"]) == (1, counted)
    assert block["translation_m"]["n"] == n
    assert f"(1 repeated line(s) of the relations file {reading}" in headline(block_of(RelationsBlock, block))
