"""albot1-places end to end: the chapter-3 hooks it uses, and thesis 4.2.1-4.2.3 on the six-room worlds.

The world runs go through the runner, and the re-visits are judged against
the worlds' rooms by the rules of the ``places`` metric
(:func:`albot1.metrics.places.judge_network`), as a run folder's evaluation does.
"""

from __future__ import annotations

import pytest

from albot1.data.open import open_sequence
from albot1.data.transforms import head
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.errors import MappingError
from albot1.methods.albot1.mapping.mapper import Albot1Mapper, UpdateEvent
from albot1.metrics.places import judge_network
from albot1.runs.execute import run_method


def test_the_chapter3_mapper_reports_its_updates_and_can_be_forced_to_update() -> None:
    mapper = Albot1Mapper(Albot1Config())
    with pytest.raises(MappingError, match="force_update before the first scan"):
        mapper.force_update()
    events: list[UpdateEvent] = []
    mapper.on_update = events.append
    for frame in head(open_sequence("synthetic-places-loop"), 30):
        mapper.process(frame)
    assert events[0].view == "initial" and events[0].scan == 0
    assert all(len(e.view_map) == len(e.outcome.view_ids) for e in events)
    before = mapper.finish().counters
    mapper.force_update()
    after = mapper.finish().counters
    assert events[-1].view == "forced" and events[-1].scan == 29 and events[-1].pose == mapper.last_pose
    assert after["updates"] == before["updates"] + 1
    assert after["updates_current_view"] == before["updates_current_view"]
    assert after["updates_previous_view"] == before["updates_previous_view"]
    assert mapper.last_view is not None and len(mapper.last_view) > 0


def run_places(dataset: str) -> dict:
    """The run's counters with the places metric's judgement of its claims merged in (as ``metrics.json`` has it)."""
    sequence = open_sequence(dataset)
    result = run_method("albot1-places", sequence)
    assert result.reference is not None
    judged = judge_network(
        result.files["places.json"], result.timestamps, result.poses, result.reference, sequence.metadata.extra
    )
    numbers = {**judged, **(judged["exits"] or {})}
    flat = {k: v for k, v in numbers.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
    return {"counters": {**result.counters, **flat}, "places": result.files["places.json"], "judged": judged}


@pytest.mark.slow
@pytest.mark.parametrize("start", [0, 1, 2])
def test_a_single_loop_learns_six_places_and_recognises_the_start_place(start: int) -> None:
    """Thesis 4.2.1 (Figures 4.1-4.3): six exits, six places, the start place recognised on return."""
    run = run_places(f"synthetic-places-loop?start={start}")
    c = run["counters"]
    assert (c["exits_crossed"], c["places_created"], c["places"]) == (6, 6, 6)
    assert (c["crossings_true"], c["crossings_false"], c["crossings_missed"]) == (6, 0, 0)
    assert (c["revisits_confirmed"], c["revisits_true"], c["revisits_false"], c["revisits_missed"]) == (1, 1, 0, 0)
    last = run["places"]["visits"][-1]
    assert last["place"] == 0 and not last["closed"]
    assert len(run["places"]["links"]) == 6  # a ring: each place linked to the next


@pytest.mark.slow
def test_the_double_loop_recognises_room_5_entered_from_a_new_direction() -> None:
    """Thesis 4.2.2: a second loop re-enters room-5 from the north, through a doorway it never used."""
    run = run_places("synthetic-places-double-loop")
    c = run["counters"]
    assert (c["exits_crossed"], c["places_created"], c["places"]) == (10, 6, 6)
    assert (c["revisits_true"], c["revisits_false"], c["revisits_missed"]) == (5, 0, 0)
    how = [(r["visit"], r["place_now"], r["how"]) for r in run["places"]["revisits"]]
    # room-1 by structure, room-2 by the exit it was left by, room-5 (new doorway) by structure,
    # room-6 and room-1 again by exits
    assert how == [(6, 0, "structure"), (7, 1, "exit"), (8, 4, "structure"), (9, 5, "exit"), (10, 0, "exit")]


@pytest.mark.slow
def test_re_traversing_the_loop_predicts_each_exit_better_aligned() -> None:
    """Thesis 4.2.3 (Figures 4.7-4.8): exits predicted aligned at the exit crossed vs where they were learned."""
    run = run_places("synthetic-places-loop?laps=2")
    c = run["counters"]
    assert c["exit_predictions_compared"] == 6 and c["revisits_false"] == 0 and c["revisits_missed"] == 0
    per_exit = run["judged"]["exits"]["exit_predictions"]
    assert len(per_exit) == 6
    assert c["exit_prediction_aligned_true_mean_m"] < 0.5 < c["exit_prediction_not_aligned_true_mean_m"]
    assert sum(e["aligned_error_m"] < e["not_aligned_error_m"] for e in per_exit) >= 5


@pytest.mark.slow
def test_every_fourth_scan_of_the_double_loop_is_judged_by_the_scans_the_run_saw() -> None:
    """The true crossings (source scans 66 ... 2079) renumbered like the run's scans: as at full rate, 10/0/0.

    The run detects them at its scans 18, 86, 164, 257, ... (one after the first scan beyond each threshold,
    17, 85, 163, 256, ...); judged by the source numbers it found none of them.
    """
    run = run_places("synthetic-places-double-loop[::4]")
    c = run["counters"]
    assert [x["scan"] for x in run["places"]["crossings"]][:4] == [18, 86, 164, 257]
    assert (c["exits_crossed"], c["crossings_true"], c["crossings_false"], c["crossings_missed"]) == (10, 10, 0, 0)
    assert run["judged"]["rooms"] == [f"room-{k}" for k in (1, 2, 3, 4, 5, 6, 1, 2, 5, 6, 1)]
    assert (c["revisits_true"], c["revisits_false"], c["revisits_missed"]) == (5, 0, 0)
