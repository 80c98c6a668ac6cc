"""A mapper's extra files in the run folder, and the places metric judging albot1-places's claims in them."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from albot1.data.open import open_sequence
from albot1.metrics.measures.places import METRIC as PLACES
from albot1.records import ResultRecord, read_record
from albot1.report.preview import render_preview
from albot1.runs.errors import RunError
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import REWRITTEN_FILES, STANDARD_FILES, is_complete, write_run


def test_extra_files_are_written_as_text_bytes_or_json(tmp_path: Path) -> None:
    result = run_method("odometry", open_sequence("synthetic-office-startstop[:5]"))
    result.files = {"notes.txt": "hello\n", "blob.bin": b"\x00\x01", "table.json": {"a": np.float64(1.5), "b": [1, 2]}}
    run_dir = write_run(result, tmp_path)
    assert (run_dir / "notes.txt").read_text() == "hello\n"
    assert (run_dir / "blob.bin").read_bytes() == b"\x00\x01"
    assert json.loads((run_dir / "table.json").read_text()) == {"a": 1.5, "b": [1, 2]}
    assert is_complete(run_dir)


@pytest.mark.parametrize("name", ["result.json", "DONE", "../escape.json", "sub/dir.json", ".hidden", ""])
def test_an_extra_file_may_not_take_a_run_folder_name_or_leave_it(tmp_path: Path, name: str) -> None:
    result = run_method("odometry", open_sequence("synthetic-office-startstop[:5]"))
    result.files = {name: "x"}
    with pytest.raises(RunError, match="extra file name"):
        write_run(result, tmp_path)
    assert "result.json" in STANDARD_FILES
    assert set(REWRITTEN_FILES) <= STANDARD_FILES  # what a rewrite removes is never a mapper's own file


def test_albot1_places_run_folder_has_its_network_judged_against_the_reference(tmp_path: Path) -> None:
    result = run_method("albot1-places", open_sequence("synthetic-places-loop[:200]"))
    run_dir = write_run(result, tmp_path, preview=render_preview)
    for name in ("places.json", "places.graphml", "places.png", "preview.png"):
        assert (run_dir / name).is_file(), name
    counters = read_record(ResultRecord, run_dir / "result.json").counters
    # one doorway crossed (door-1-2 at scan 66): two places' visits, no re-visit to claim or miss
    assert counters["exits_crossed"] == 1 and counters["places_created"] == 1 and counters["visits"] == 2
    # the runner does not judge: the method's claims leave the run as the mapper wrote them ...
    assert "crossings_true" not in counters and "revisits_true" not in counters
    places = json.loads((run_dir / "places.json").read_text())
    assert "ground_truth" not in places and places["crossings"][0]["scan"] == pytest.approx(66, abs=5)
    ET.fromstring((run_dir / "places.graphml").read_text())
    assert "places" in json.loads((run_dir / "extras.json").read_text())
    # ... and the evaluation judges them against the reference poses: the places metric
    block = evaluate_run(run_dir).get(PLACES)
    assert block is not None and block.rule == "rooms" and block.rooms == ["room-1", "room-2"]
    assert block.exits is not None
    assert (block.exits.crossings_true, block.exits.crossings_false, block.exits.crossings_missed) == (1, 0, 0)
    assert (block.revisits_true, block.revisits_false, block.revisits_missed, block.claims) == (0, 0, 0, 0)
    assert block.revisit_precision is None and block.revisit_recall is None  # nothing to claim: undefined


def test_without_reference_poses_there_is_no_judgement(tmp_path: Path) -> None:
    seq = open_sequence("synthetic-places-loop[:100]")
    from albot1.data.model import Sequence

    frames = [type(f)(f.index, f.scan, f.odometry, None) for f in seq]
    result = run_method("albot1-places", Sequence.from_frames("no-reference", frames))
    assert result.reference is None
    assert "revisits_true" not in result.counters and "ground_truth" not in result.files["places.json"]
    metrics = evaluate_run(write_run(result, tmp_path))
    assert metrics.get(PLACES) is None and metrics.reason("places") == "the dataset has no reference poses"


def test_a_method_without_a_network_of_places_has_no_places_metric(tmp_path: Path) -> None:
    run_dir = write_run(run_method("odometry", open_sequence("synthetic-places-loop[:20]")), tmp_path)
    metrics = evaluate_run(run_dir)
    assert metrics.places is None  # type: ignore[attr-defined]  # the runtime record has every metric's field
    assert metrics.reason("places") == "the method keeps no network of places (no places.json)"
