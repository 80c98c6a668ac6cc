"""Re-visits, crossings and exit predictions of a network of places scored against reference poses."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from albot1.data.degrade import degrade
from albot1.data.open import open_sequence
from albot1.metrics.errors import MetricsError
from albot1.metrics.measures.places import METRIC as PLACES
from albot1.metrics.measures.places import compute as places_compute
from albot1.metrics.measures.places import headline as places_headline
from albot1.metrics.places import believed_in_world, crossings_in_run, judge_network, judge_revisits
from albot1.metrics.unit import MetricInputs

# Two rooms side by side, x 0..5 (room-a) and 5.2..10 (room-b), joined by a doorway at x = 5.1, y 2..3.
SPACES = [{"name": "room-a", "rect": [0.0, 0.0, 5.0, 5.0]}, {"name": "room-b", "rect": [5.2, 0.0, 10.0, 5.0]}]
DOORWAYS = [{"id": "door", "a": [5.1, 2.0], "b": [5.1, 3.0], "width_m": 1.0, "spaces": ["room-a", "room-b"]}]


def route() -> np.ndarray:
    """a (scans 0-19) -> b (20-39) -> a (40-59) -> b (60-79), along y = 2.5, heading east then west."""
    xs = np.concatenate(
        [np.linspace(1, 4.9, 20), np.linspace(5.3, 9, 20), np.linspace(4.9, 1, 20), np.linspace(5.3, 9, 20)]
    )
    heading = np.concatenate([np.zeros(20), np.zeros(20), np.full(20, math.pi), np.zeros(20)])
    return np.column_stack([xs, np.full(80, 2.5), heading])


def record(places: list[int | None], claims: list[tuple[int, int, str]]) -> dict:
    bounds = [(0, 19), (20, 39), (40, 59), (60, 79)]
    visits = [
        {"id": k, "place": p, "first_scan": b[0], "last_scan": b[1]} for k, (p, b) in enumerate(zip(places, bounds))
    ]
    revisits = [{"scan": s, "visit": v, "place": p, "place_now": p, "how": how} for v, p, how in claims for s in [0]]
    return {"visits": visits, "revisits": revisits, "crossings": []}


def test_rooms_decide_when_the_dataset_knows_them() -> None:
    # a perfect network: visits 2 and 3 recognised as places 0 and 1
    counters, truth, summary = judge_revisits(
        record([0, 1, 0, 1], [(2, 0, "structure"), (3, 1, "exit")]), route(), SPACES
    )
    assert truth == [True, True]
    assert counters == {
        "revisits_true": 2,
        "revisits_false": 0,
        "revisits_missed": 0,
        "revisits_actual": 2,
        "revisit_precision": 1.0,
        "revisit_recall": 1.0,
    }
    assert summary["rule"] == "rooms" and summary["rooms"] == ["room-a", "room-b", "room-a", "room-b"]


def test_a_wrong_claim_and_a_missed_revisit() -> None:
    # visit 2 (room-a again) wrongly claimed as place 1 (room-b); visit 3 made a new place: both re-visits missed
    counters, truth, _ = judge_revisits(record([0, 1, 1, 2], [(2, 1, "structure")]), route(), SPACES)
    assert truth == [False]
    assert (counters["revisits_true"], counters["revisits_false"], counters["revisits_missed"]) == (0, 1, 2)
    assert counters["revisit_precision"] == 0.0 and counters["revisit_recall"] == 0.0


def test_no_claims_leaves_precision_undefined_not_zero() -> None:
    counters, truth, _ = judge_revisits(record([0, 1, 2, 3], []), route(), SPACES)
    assert truth == [] and "revisit_precision" not in counters and counters["revisit_recall"] == 0.0


def test_without_rooms_the_reference_positions_must_overlap() -> None:
    counters, truth, summary = judge_revisits(record([0, 1, 0, 1], [(2, 0, "structure"), (3, 1, "exit")]), route())
    assert summary["rule"] == "overlap"
    # visit 2 retraces visit 0's path, visit 3 visit 1's; the neighbour just before never counts
    assert truth == [True, True] and counters["revisits_missed"] == 0


def test_a_visit_outside_the_reference_is_an_error() -> None:
    bad = record([0, 1, 0, 1], [])
    bad["visits"][3]["last_scan"] = 80
    with pytest.raises(MetricsError, match="visit 3: scans 60..80 outside the 80 reference poses"):
        judge_revisits(bad, route(), SPACES)


def test_points_are_put_in_the_world_as_the_robot_believed_them() -> None:
    estimate = np.array([1.0, 0.0, math.pi / 2])  # the map's pose of the robot
    reference = np.array([5.0, 5.0, 0.0])  # where it truly was
    point = np.array([1.0, 2.0])  # 2 m ahead of the estimated pose
    np.testing.assert_allclose(believed_in_world(point, estimate, reference), [7.0, 5.0], atol=1e-12)


def test_judge_network_scores_exit_predictions_and_crossings() -> None:
    ref = route()
    # the map is the world shifted by (-1, 0): estimate = reference - (1, 0)
    est = ref - np.array([1.0, 0.0, 0.0])
    crossing = {
        "scan": 60,
        "exit": 3,
        "segment": [4.1, 2.0, 4.1, 3.0],  # the door as perceived (map frame): exactly right
        "prediction": {"aligned": [4.2, 2.0, 4.2, 3.0], "not_aligned": [5.1, 2.5, 5.1, 3.5]},
    }
    rec = record([0, 1, 0, 1], [(2, 0, "structure"), (3, 1, "exit")])
    rec["crossings"] = [crossing, {"scan": 19, "exit": 0, "segment": [4.1, 2.0, 4.1, 3.0], "prediction": None}]
    true_crossings = [{"scan": 20, "t": 20.0}, {"scan": 40, "t": 40.0}, {"scan": 60, "t": 60.0}]
    dataset = {"spaces": SPACES, "doorways": DOORWAYS, "doorway_crossings": true_crossings}
    block = judge_network(rec, np.arange(80.0), est, ref, dataset)
    exits = block["exits"]
    assert exits["exit_prediction_aligned_true_mean_m"] == pytest.approx(0.1)
    assert exits["exit_prediction_not_aligned_true_mean_m"] == pytest.approx(math.hypot(1.0, 0.5))
    assert (exits["crossings_true"], exits["crossings_false"], exits["crossings_missed"]) == (2, 0, 1)
    assert exits["exit_predictions"][0]["doorway"] == "door"
    assert block["claims_true"] == [True, True] and block["rule"] == "rooms"
    assert "true" not in rec["revisits"][0] and "ground_truth" not in rec  # the method's file is left as it was


def test_judge_network_without_doorways_says_why_there_is_no_exit_check() -> None:
    block = judge_network(record([0, 1, 2, 3], []), np.arange(80.0), route(), route(), {"spaces": SPACES})
    assert block["exits"] is None and block["exits_reason"].startswith("the dataset knows no doorways")
    assert math.isnan(block["revisit_precision"]) and block["revisit_recall"] == 0.0  # no claim: undefined, not 0


def test_judge_network_refuses_mismatched_inputs() -> None:
    with pytest.raises(MetricsError, match="80 estimated poses but 79 reference poses and 80 timestamps"):
        judge_network(record([0, 1, 0, 1], []), np.arange(80.0), route(), route()[:79], {})


def _places_inputs(
    rec: dict | None, extra: dict, estimate: np.ndarray | None = None, timestamps: np.ndarray | None = None
) -> MetricInputs:
    ref = route()
    est = ref if estimate is None else estimate
    files = {"places.json": rec} if rec is not None else {}
    return MetricInputs(
        dataset="two-rooms",
        timestamps=np.arange(80.0) if timestamps is None else timestamps,
        poses=est,
        reference=ref,
        relations=None,
        relations_source="",
        relation_timestamps=np.arange(80.0),
        relation_poses=est,
        open_dataset=lambda: SimpleNamespace(metadata=SimpleNamespace(extra=extra)),  # type: ignore[arg-type,return-value]
        read_file=files.get,
    )


def test_the_places_metric_judges_the_claims_file_into_its_block_and_headline() -> None:
    rec = record([0, 1, 0, 2], [(2, 0, "structure")])  # visit 3 (room-b again) made a new place: one missed
    inputs = _places_inputs(rec, {"spaces": SPACES})
    assert PLACES.missing(inputs) is None
    block = places_compute(inputs)
    assert (block.claims, block.revisits_true, block.revisits_missed, block.revisits_actual) == (1, 1, 1, 2)
    assert (block.revisit_precision, block.revisit_recall, block.rooms) == (1.0, 0.5, ["room-a", "room-b"] * 2)
    assert block.exits is None and block.exits_reason == "the dataset knows no doorways (exit checks need them)"
    assert places_headline(block) == (
        "1 of 1 claimed re-visits true (precision 1.00), recall 0.50 of 2 true re-visits (rooms); "
        "the dataset knows no doorways (exit checks need them)"
    )


def test_the_places_metric_does_not_apply_without_a_claims_file_and_says_why() -> None:
    inputs = _places_inputs(None, {})
    assert PLACES.missing(inputs) == "the method keeps no network of places (no places.json)"


def test_a_claims_file_of_the_wrong_shape_is_one_clear_error() -> None:
    bad = {"visits": [{"id": 0}], "revisits": []}
    with pytest.raises(MetricsError, match=r"^places.json: unexpected content \(KeyError: 'first_scan'\)$"):
        places_compute(_places_inputs(bad, {}))


def _crossing(scan: int) -> dict:
    return {"scan": scan, "exit": 0, "segment": [5.1, 2.0, 5.1, 3.0], "prediction": None}


def test_true_crossings_are_renumbered_by_time_like_the_scans_the_run_saw() -> None:
    """The run saw every 2nd scan of a 160-scan source (0.1 s apart): the truth's source numbers must follow.

    The true crossings are at source scans 40, 80 and 121 and 170 (4.0, 8.0, 12.1, 17.0 s); the run's
    scans are 0.2 s apart, so they are its scans 20, 40 and 61 (the first at or after each time), and the
    last is after the run's end (15.8 s). The method detected 20, 40 and 61: all true, none missed.
    """
    rec = record([0, 1, 0, 1], [])
    rec["crossings"] = [_crossing(20), _crossing(40), _crossing(61)]
    truth = [{"scan": s, "t": round(0.1 * s, 9)} for s in (40, 80, 121, 170)]
    assert crossings_in_run(truth, 0.2 * np.arange(80)) == [20, 40, 61]
    extra = {"spaces": SPACES, "doorways": DOORWAYS, "doorway_crossings": truth}
    block = places_compute(_places_inputs(rec, extra, timestamps=0.2 * np.arange(80)))
    assert block.exits is not None
    assert (block.exits.crossings_true, block.exits.crossings_false, block.exits.crossings_missed) == (3, 0, 0)


def test_true_crossings_in_uneven_views_go_to_the_first_view_at_or_after_them() -> None:
    # views kept at 0, 1.5, 1.7, 4.0, 9.0 s (view spacing, dropout); crossings at 1.5, 1.6, 3.999 9999 995, 9.5 s
    times = np.array([0.0, 1.5, 1.7, 4.0, 9.0])
    truth = [{"scan": 15, "t": 1.5}, {"scan": 16, "t": 1.6}, {"scan": 40, "t": 3.9999999995}, {"scan": 95, "t": 9.5}]
    assert crossings_in_run(truth, times) == [1, 2, 3]


def test_crossings_need_their_times_and_increasing_scan_times() -> None:
    with pytest.raises(MetricsError, match=r"^doorway_crossings\[0\] of the dataset's metadata has no time 't' \(s\)$"):
        crossings_in_run([{"scan": 3}], np.arange(5.0))
    with pytest.raises(MetricsError, match=r"^scan 2: time 1.000000 s does not follow scan 1's 1.000000 s"):
        crossings_in_run([{"scan": 3, "t": 3.0}], np.array([0.0, 1.0, 1.0, 2.0]))


@pytest.mark.parametrize(
    ("selection", "expected"),
    [
        ("", [66, 338, 649, 1024, 1284, 1421, 1643, 1794, 1942, 2079]),
        ("[::4]", [17, 85, 163, 256, 321, 356, 411, 449, 486, 520]),  # ceil(scan / 4): the first kept beyond
        ("[:700]", [66, 338, 649]),
        ("?views=0.5:15", [8, 35, 64, 103, 128, 141, 163, 180, 195, 209]),
    ],
)
def test_a_worlds_true_crossings_follow_a_selection_of_its_scans(selection: str, expected: list[int]) -> None:
    """The double loop's ten crossings (source scans 66 ... 2079) numbered as each selection numbers its scans."""
    sequence = open_sequence(f"synthetic-places-double-loop{selection}")
    times = np.array([frame.scan.timestamp for frame in sequence])
    got = crossings_in_run(sequence.metadata.extra["doorway_crossings"], times)
    assert got == expected
    for scan, crossing in zip(got, sequence.metadata.extra["doorway_crossings"]):
        assert times[scan] >= crossing["t"] and (scan == 0 or times[scan - 1] < crossing["t"])


def test_a_worlds_true_crossings_follow_a_dropout() -> None:
    full = open_sequence("synthetic-places-loop[:700]")
    kept = degrade(full, "dropout:0.5", seed=1)
    source_of = {frame.scan.timestamp: frame.index for frame in full}
    survivors = [source_of[frame.scan.timestamp] for frame in kept]  # the source scan of each kept scan
    got = crossings_in_run(full.metadata.extra["doorway_crossings"], np.array([f.scan.timestamp for f in kept]))
    # the crossings are at source scans 66, 338 and 649; seed 1 dropped 66, 67 and 338, so the first
    # survivors on the far side are 68, 339 and 649
    assert {66, 67, 338}.isdisjoint(survivors) and {68, 339, 649} <= set(survivors)
    assert got == [survivors.index(68), survivors.index(339), survivors.index(649)]


def test_a_false_crossing_inside_a_room_is_no_revisit_of_it() -> None:
    """Visits 1 and 2 are one stay in room-b (a false crossing at scan 30 split it): only 3 and 4 are re-visits."""
    bounds = [(0, 19), (20, 29), (30, 39), (40, 59), (60, 79)]
    visits = [{"id": k, "place": k, "first_scan": a, "last_scan": b} for k, (a, b) in enumerate(bounds)]
    visits[4]["place"] = 2  # visit 4 (room-b again) recognised as visit 2's place; visit 3 made a new place
    rec = {"visits": visits, "revisits": [{"scan": 60, "visit": 4, "place_now": 2}], "crossings": []}
    counters, truth, summary = judge_revisits(rec, route(), SPACES)
    assert summary["rooms"] == ["room-a", "room-b", "room-b", "room-a", "room-b"]
    assert [v["same_place_as"] for v in summary["visits"]] == [[], [], [], [0], [1, 2]]
    assert truth == [True]
    assert counters == {
        "revisits_true": 1,
        "revisits_false": 0,
        "revisits_missed": 1,
        "revisits_actual": 2,
        "revisit_precision": 1.0,
        "revisit_recall": 0.5,
    }


def test_a_claim_of_the_stay_it_never_left_is_false() -> None:
    bounds = [(0, 19), (20, 29), (30, 39)]
    visits = [
        {"id": k, "place": p, "first_scan": a, "last_scan": b} for k, (p, (a, b)) in enumerate(zip([0, 1, 1], bounds))
    ]
    rec = {"visits": visits, "revisits": [{"scan": 30, "visit": 2, "place_now": 1}], "crossings": []}
    counters, truth, _ = judge_revisits(rec, route()[:40], SPACES)
    assert truth == [False] and (counters["revisits_actual"], counters["revisits_false"]) == (0, 1)
    assert "revisit_recall" not in counters  # no true re-visit: undefined, not 0


def _exit_record(claims: list[tuple[int, int, str]], predictions: list[dict], crossings: list[dict]) -> dict:
    rec = record([0, 1, 0, 1], claims)
    rec.update(predictions=predictions, crossings=crossings, config={"exit_link_distance_m": 1.0})
    return rec


def _left(visit: int, scan: int, segment: list[float], prediction: dict | None = None) -> dict:
    return {"scan": scan, "exit": 0, "from_visit": visit, "segment": segment, "prediction": prediction}


DOOR = [5.1, 2.0, 5.1, 3.0]
THREE = [_left(0, 20, DOOR), _left(1, 40, DOOR), _left(2, 60, DOOR)]  # visits 0-2 left at each true crossing
TRUTH = {
    "spaces": SPACES,
    "doorways": DOORWAYS,
    "doorway_crossings": [{"scan": s, "t": float(s)} for s in (20, 40, 60)],
}


@pytest.mark.parametrize(
    ("claims", "predictions", "crossings", "reason"),
    [
        ([], [], THREE, "no place was recognised (no re-visit claimed), so none was made"),
        (
            [(2, 0, "structure")],
            [],
            THREE,
            "none was made, as the places of the 1 re-visit(s) claimed knew no exit but the one they were entered by",
        ),
        (
            [(2, 0, "structure"), (3, 1, "exit")],
            [{"visit": 2, "aligned": [8.0, 2.0, 8.0, 3.0]}, {"visit": 2, "aligned": [5.1, 6.0, 5.1, 7.0]}],
            THREE,
            "exits were predicted in 1 visit(s), but visit 2 was left at scan 60 by an exit 2.90 m from the "
            "nearest prediction (beyond 2 m the mapper takes it for a new way out)",
        ),
        (
            [(2, 0, "structure"), (3, 1, "exit")],
            [{"visit": 3, "aligned": DOOR}],
            THREE,
            "exits were predicted in 1 visit(s), but the run ended in visit 3 before an exit was crossed",
        ),
    ],
)
def test_no_exit_prediction_compared_says_why_in_the_runs_own_terms(
    claims: list[tuple[int, int, str]], predictions: list[dict], crossings: list[dict], reason: str
) -> None:
    block = places_compute(_places_inputs(_exit_record(claims, predictions, crossings), TRUTH))
    assert block.exits is not None and block.exits.exit_prediction_aligned_true_mean_m is None
    assert block.exits.exit_predictions_reason == f"no exit prediction compared: {reason}"
    assert places_headline(block).endswith(
        f"; 3 of 3 true crossings found, 0 false; {block.exits.exit_predictions_reason}"
    )
    assert (
        PLACES.columns[4].applies is not None
        and PLACES.columns[4].applies(block, None) == block.exits.exit_predictions_reason
    )


def test_the_headline_shows_false_crossings_and_the_medians_beside_the_means() -> None:
    def compared(scan: int, aligned_x: float) -> dict:
        # the estimate is the reference, so the believed positions are the map's: errors |aligned_x - 5.1|, 1.0
        prediction = {"aligned": [aligned_x, 2.0, aligned_x, 3.0], "not_aligned": [6.1, 2.0, 6.1, 3.0]}
        return _left(0, scan, DOOR, prediction)

    crossings = [compared(20, 5.2), compared(40, 5.4), compared(60, 6.1), _left(1, 10, DOOR)]  # scan 10: false
    block = places_compute(_places_inputs(_exit_record([(2, 0, "structure")], [], crossings), TRUTH))
    exits = block.exits
    assert exits is not None and (exits.crossings_true, exits.crossings_false, exits.crossings_missed) == (3, 1, 0)
    assert exits.exit_prediction_aligned_true_mean_m == pytest.approx(1.4 / 3)
    assert exits.exit_prediction_aligned_true_median_m == pytest.approx(0.3)
    assert exits.exit_prediction_not_aligned_true_median_m == pytest.approx(1.0)
    assert exits.exit_predictions_reason is None
    assert places_headline(block) == (
        "1 of 1 claimed re-visits true (precision 1.00), recall 1.00 of 2 true re-visits (rooms); "
        "3 of 3 true crossings found, 1 false; 3 exit predictions compared, mean (median) 0.467 (0.300) m aligned, "
        "1.000 (1.000) m not"
    )


def _merged_record(places: list[int | None], bounds: list[tuple[int, int]]) -> dict:
    visits = [
        {"id": k, "place": p, "first_scan": b[0], "last_scan": b[1]} for k, (p, b) in enumerate(zip(places, bounds))
    ]
    return {"visits": visits, "revisits": [], "crossings": []}


def test_true_revisits_are_the_routes_stays_not_the_methods_visits() -> None:
    # the method missed every doorway: one visit over all 80 scans, yet the route re-entered a and b (D10)
    counters, truth, _ = judge_revisits(_merged_record([0], [(0, 79)]), route(), SPACES)
    assert truth == []
    assert (counters["revisits_actual"], counters["revisits_missed"], counters["revisit_recall"]) == (2, 2, 0.0)


def test_a_claim_counts_for_the_true_stay_holding_most_of_its_visit() -> None:
    # two doorways found of three: visits a | b+a (mostly b: 20-55) | b; the last visit re-visits b, claimed right
    rec = _merged_record([0, 1, 1], [(0, 19), (20, 55), (56, 79)])
    rec["revisits"] = [{"scan": 60, "visit": 2, "place": 1, "place_now": 1, "how": "structure"}]
    counters, truth, _ = judge_revisits(rec, route(), SPACES)
    assert truth == [True]
    assert (counters["revisits_actual"], counters["revisits_true"], counters["revisits_missed"]) == (2, 1, 1)
    assert counters["revisit_recall"] == 0.5
