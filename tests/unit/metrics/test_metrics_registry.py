"""The metric registry: what it finds, what it refuses, and that one module is all a metric takes."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

from albot1.metrics.blocks import block_of
from albot1.metrics.measures.ate import METRIC as ATE
from albot1.metrics.measures.ate import AteBlock
from albot1.metrics.measures.map_shape import METRIC as MAP_SHAPE
from albot1.metrics.measures.relation_box import METRIC as RELATION_BOX
from albot1.metrics.measures.relation_box import RelationBoxBlock
from albot1.metrics.record import NOT_IN_FILE, MetricsRecord, build_metrics_record
from albot1.metrics.registry import MetricRegistry, MetricRegistryError, build_registry, metric_registry
from albot1.metrics.unit import NO_REFERENCE, REFERENCE, ColumnSpec, Metric, MetricInputs
from albot1.records import Record, RecordError, dump_record, parse_record
from albot1.report.collect import METRIC_COLUMNS
from albot1.runs.evaluate import score
from albot1.runs.scored import Scored

RUN = {
    "key": "k",
    "method": "m",
    "dataset": "d",
    "preset": "p",
    "degradation": "none",
    "seed": 0,
    "scans": 3,
    "has_reference": True,
}
ORDER = (
    "ate",
    "ate_windows",
    "rpe",
    "drift",
    "loop_gap",
    "orientation",
    "relations",
    "map_shape",
    "updates",
    "cost",
    "places",
    "relation_box",
)


def test_the_registry_holds_every_metric_once_in_file_order() -> None:
    registry = metric_registry()
    assert registry.names == ORDER
    assert registry is metric_registry()  # built once
    assert registry.get("ate") is ATE
    with pytest.raises(KeyError, match="no metric 'atee'; known: ate, ate_windows"):
        registry.get("atee")


def test_a_metric_in_one_module_reaches_the_record_the_report_and_the_cli() -> None:
    """``relation_box`` lives in one file; nothing else names it, yet every reader has it."""
    assert metric_registry().get("relation_box") is RELATION_BOX
    assert list(MetricsRecord.model_fields)[-2:] == ["relation_box", "relation_box_reason"]
    assert (METRIC_COLUMNS["relation_median_m"].path, METRIC_COLUMNS["relation_iqr_m"].path) == (
        "relation_box.translation_m.median",
        "relation_box.translation_m.iqr",
    )
    assert METRIC_COLUMNS["relation_iqr_m"].metric == "relation_box"
    from albot1.cli.evaluate import headlines

    record = parse_record(MetricsRecord, {"run": RUN}, "old file")
    assert headlines(record)[-1] == f"  relation_box null: {NOT_IN_FILE}"


def test_the_report_columns_are_the_metrics_own_in_registry_order() -> None:
    assert list(METRIC_COLUMNS) == [
        "ate_rmse_m",
        "ate_windows_m",
        "rpe_frame_m",
        "rpe_frame_deg",
        "drift_10m_m",
        "drift_10m_deg",
        "loop_gap_m",
        "revisit_gap_m",
        "orientation_deg",
        "relation_m",
        "relation_deg",
        "relation_loops_m",
        "map_precision",
        "map_coverage",
        "updates_per_view",
        "places",
        "revisits_claimed",
        "revisit_precision",
        "revisit_recall",
        "exit_aligned_m",
        "exit_not_aligned_m",
        "relation_median_m",
        "relation_iqr_m",
    ]
    assert (METRIC_COLUMNS["places"].source, METRIC_COLUMNS["places"].path) == ("result", "counters.places")
    assert METRIC_COLUMNS["revisit_precision"].path == "places.revisit_precision"


def test_a_file_written_before_a_metric_existed_reads_as_not_applicable_with_that_reason() -> None:
    data = {"run": RUN}
    for name in ORDER[:10]:
        data[name], data[f"{name}_reason"] = None, "absent"
    record = parse_record(MetricsRecord, data, "old metrics.json")
    assert record.reason("places") == NOT_IN_FILE and record.get(RELATION_BOX) is None
    assert dump_record(record)["relation_box_reason"] == NOT_IN_FILE
    assert list(dump_record(record)) == ["run", "missing", *(k for n in ORDER for k in (n, f"{n}_reason"))]


def test_a_metric_with_both_or_neither_block_and_reason_is_refused() -> None:
    with pytest.raises(RecordError, match="metric 'ate' has neither a block nor a reason"):
        parse_record(MetricsRecord, {"run": RUN, "ate": None}, "m")
    with pytest.raises(RecordError, match="atee: Extra inputs are not permitted"):
        parse_record(MetricsRecord, {"run": RUN, "atee": None}, "m")


def test_get_is_typed_by_the_metric_and_returns_its_block() -> None:
    poses = np.column_stack([np.arange(4.0), np.zeros(4), np.zeros(4)])
    from albot1.metrics.ate import ate

    block = block_of(AteBlock, ate(poses, poses))
    record = parse_record(MetricsRecord, {"run": RUN, "ate": dump_record(block)}, "m")
    got = record.get(ATE)
    assert isinstance(got, AteBlock) and got.rmse_m == 0.0 and got == block
    assert record.reason("ate") is None and record.get(MAP_SHAPE) is None
    assert record.reason("map_shape") == NOT_IN_FILE


def test_needs_are_checked_in_order_and_the_first_unmet_gives_the_reason() -> None:
    poses = np.zeros((3, 3))

    def inputs(reference: np.ndarray | None, with_map: bool) -> MetricInputs:
        return MetricInputs(
            dataset="d",
            timestamps=np.arange(3.0),
            poses=poses,
            reference=reference,
            relations=None,
            relations_source="r",
            relation_timestamps=np.arange(3.0),
            relation_poses=poses,
            open_dataset=lambda: pytest.fail("a need check must not open the dataset here"),
            load_map=(lambda: pytest.fail("not loaded")) if with_map else None,
        )

    assert MAP_SHAPE.missing(inputs(None, True)) == NO_REFERENCE
    assert MAP_SHAPE.missing(inputs(poses, False)) == "no map to compare"
    assert MAP_SHAPE.missing(inputs(poses, True)) is None
    assert RELATION_BOX.missing(inputs(poses, True)) == "the dataset has no ground-truth relations"


def _package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str, modules: dict[str, str]) -> str:
    root = tmp_path / name
    root.mkdir()
    (root / "__init__.py").write_text("")
    for module, text in modules.items():
        (root / f"{module}.py").write_text(textwrap.dedent(text))
    monkeypatch.syspath_prepend(str(tmp_path))
    return name


GOOD = """
    from albot1.metrics.unit import Metric
    from albot1.records import Record

    class B(Record):
        x_m: float

    def compute(inputs): return B(x_m=1.0)
    def headline(block): return f"{block.x_m} m"

    METRIC = Metric(name="{name}", position={position}, models=(B,), needs=(),
                    compute=compute, headline=headline)
"""


def test_a_module_without_its_metric_is_refused_not_skipped(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    package = _package(tmp_path, monkeypatch, "measures_missing", {"lonely": "def compute(inputs): return None\n"})
    with pytest.raises(MetricRegistryError, match=r"measures_missing\.lonely .*: expected METRIC = Metric\(\.\.\.\)"):
        build_registry(package)


def test_a_metric_named_unlike_its_module_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    package = _package(
        tmp_path, monkeypatch, "measures_misnamed", {"one": GOOD.replace("{name}", "two").replace("{position}", "1")}
    )
    with pytest.raises(MetricRegistryError, match="METRIC.name is 'two'; expected the module's name"):
        build_registry(package)


def test_two_metrics_in_one_place_are_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    modules = {n: GOOD.replace("{name}", n).replace("{position}", "5") for n in ("one", "two")}
    package = _package(tmp_path, monkeypatch, "measures_clash", modules)
    with pytest.raises(MetricRegistryError, match="metrics share a position: 5"):
        build_registry(package)


def test_a_registry_of_its_own_scores_and_records_its_metrics(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    modules = {
        "second": GOOD.replace("{name}", "second").replace("{position}", "2"),
        "first": GOOD.replace("{name}", "first").replace("{position}", "1"),
    }
    registry = build_registry(_package(tmp_path, monkeypatch, "measures_own", modules))
    assert registry.names == ("first", "second") and len(registry) == 2
    poses = np.zeros((2, 3))
    scored = Scored(RUN, "d", np.arange(2.0), poses, None, None, "r", np.arange(2.0), poses)
    record = score(scored, registry=registry)
    run = {**RUN, "data_sha256": {}}  # no data file: a run header names the data checksums it has
    assert dump_record(record) == {"run": run, "missing": record.missing, "first": {"x_m": 1.0}, "second": {"x_m": 1.0}}


class Toy(Record):
    x_m: float


def test_a_need_unmet_records_its_reason_and_compute_is_not_called() -> None:
    def compute(inputs: MetricInputs) -> Toy:
        raise AssertionError("compute without its need")

    toy = Metric("toy", 1, (Toy,), (REFERENCE,), compute, lambda b: "", (ColumnSpec("toy_m", "x_m", "toy"),))
    registry = MetricRegistry((toy,))
    poses = np.zeros((2, 3))
    record = score(Scored(RUN, "d", np.arange(2.0), poses, None, None, "r", np.arange(2.0), poses), registry=registry)
    run = {**RUN, "data_sha256": {}}
    assert dump_record(record) == {"run": run, "missing": record.missing, "toy": None, "toy_reason": NO_REFERENCE}
    assert type(record).__name__ == "MetricsRecord" and build_metrics_record(registry).REGISTRY is registry


def test_a_block_that_does_not_fit_its_model_is_the_metrics_bug_and_is_raised() -> None:
    with pytest.raises(RecordError, match="the RelationBoxBlock being computed: not a valid RelationBoxBlock"):
        block_of(RelationBoxBlock, {"units": {}})


def test_the_docs_list_the_fields_of_every_metric_of_the_registry() -> None:
    text = (Path(__file__).resolve().parents[3] / "docs" / "metrics.md").read_text(encoding="utf-8")
    table = [line.split("|")[1].strip() for line in text.splitlines() if line.startswith("| `")]
    assert [name for name in table if name.strip("`") in ORDER] == [f"`{name}`" for name in ORDER]


def _places(**rest: object) -> dict[str, object]:
    """A places block of a run that claimed no re-visit (rooms rule), with ``rest`` (its exits) added."""
    return {
        "units": {},
        "rule": "rooms",
        "rooms": ["a"],
        "buffer_m": None,
        "min_overlap": None,
        "claims": 0,
        "claims_true": [],
        "revisits_true": 0,
        "revisits_false": 0,
        "revisits_missed": 0,
        "revisits_actual": 0,
        "revisit_precision": None,
        "revisit_recall": None,
        "visits": [],
        **rest,
    }


def test_a_ratio_without_a_denominator_is_not_applicable_with_the_metrics_words() -> None:
    from albot1.bench.grid import Cell
    from albot1.metrics.measures.places import PlacesBlock
    from albot1.report.collect import CellRecord

    places = _places(exits=None, exits_reason="the dataset knows no doorways (exit checks need them)")
    block_of(PlacesBlock, places)
    metrics = parse_record(MetricsRecord, {"run": RUN, "places": places}, "m")
    cell = Cell("s", "d", "d", "m", "m", "p", "none", 0, "k", "v", 1, 1)
    record = CellRecord(cell, "done", Path("/nonexistent"), None, metrics, None)
    assert METRIC_COLUMNS["revisit_precision"].reason(record) == "no re-visit claimed (claims: 0)"
    assert METRIC_COLUMNS["revisit_recall"].reason(record) == "no true re-visit (revisits_actual: 0)"
    assert METRIC_COLUMNS["exit_aligned_m"].reason(record) == places["exits_reason"]
    assert METRIC_COLUMNS["relation_iqr_m"].reason(record) == NOT_IN_FILE


@pytest.mark.parametrize("reason", ["no exit prediction compared: no place was recognised (no re-visit claimed)", None])
def test_exit_errors_without_a_comparison_are_not_applicable_with_the_runs_reason(reason: str | None) -> None:
    """The block's exit_predictions_reason; a file written before that reason existed: the column's own note."""
    from albot1.bench.grid import Cell
    from albot1.report.collect import CellRecord

    exits = {
        "exit_predictions": [],
        "crossing_scans": 15,
        "exit_prediction_aligned_true_mean_m": None,
        "exit_prediction_not_aligned_true_mean_m": None,
        "crossings_true": 2,
        "crossings_false": 1,
        "crossings_missed": 0,
        **({"exit_predictions_reason": reason} if reason else {}),
    }
    places = _places(exits=exits)
    metrics = parse_record(MetricsRecord, {"run": RUN, "places": places}, "m")
    cell = Cell("s", "d", "d", "m", "m", "p", "none", 0, "k", "v", 1, 1)
    record = CellRecord(cell, "done", Path("/nonexistent"), None, metrics, None)
    expected = reason or "no exit prediction compared (exits.exit_predictions: [])"
    assert METRIC_COLUMNS["exit_aligned_m"].reason(record) == expected
    assert METRIC_COLUMNS["exit_not_aligned_m"].reason(record) == expected


def test_updates_and_orientation_nulls_say_why() -> None:
    """A null updates/view or bearing mean is n/a with its own reason, not "not defined for this run"."""
    from albot1.bench.grid import Cell
    from albot1.metrics.orientation import orientation_table
    from albot1.metrics.updates import update_counts
    from albot1.report.collect import CellRecord

    still = np.zeros((3, 3))  # a robot that never moved: its one stop (the last scan) is at the start
    blocks = {"updates": update_counts({"views": 0, "updates": 0}), "orientation": orientation_table(still, still)}
    assert blocks["updates"]["updates_per_view"] is None and blocks["orientation"]["bearing_undefined"] == 1
    metrics = parse_record(MetricsRecord, {"run": RUN, **blocks}, "m")
    cell = Cell("s", "d", "d", "m", "m", "p", "none", 0, "k", "v", 1, 1)
    record = CellRecord(cell, "done", Path("/nonexistent"), None, metrics, None)
    assert METRIC_COLUMNS["updates_per_view"].reason(record) == "the run saw no views (views: 0)"
    assert METRIC_COLUMNS["orientation_deg"].reason(record) == (
        "no stop point where the start's bearing is defined (none 1 m or more from the start)"
    )


def test_a_closed_route_without_reference_says_why_it_has_no_revisit_gap() -> None:
    from albot1.bench.grid import Cell
    from albot1.metrics.loop_gap import route_gap
    from albot1.report.collect import CellRecord

    loop_gap = {
        "units": {"gap": "m", "heading": "deg"},
        "alignment": "none (relative poses)",
        "route": route_gap(np.zeros((3, 3)), None),
        "pairs": None,
        "pairs_reason": NO_REFERENCE,
    }
    metrics = parse_record(MetricsRecord, {"run": RUN, "loop_gap": loop_gap}, "m")
    cell = Cell("s", "d", "d", "m", "m", "p", "none", 0, "k", "v", 1, 1)
    record = CellRecord(cell, "done", Path("/nonexistent"), None, metrics, None)
    assert METRIC_COLUMNS["loop_gap_m"].value(record) == 0.0
    assert METRIC_COLUMNS["revisit_gap_m"].value(record) is None
    assert METRIC_COLUMNS["revisit_gap_m"].reason(record) == NO_REFERENCE
