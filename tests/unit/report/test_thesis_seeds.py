"""The thesis page compares methods on the same seed, and says which one, whatever failed.

It used to read each method's lowest completed seed: with method A's seed 0 failed, A's seed 1 was set beside
B's seed 0, a comparison across different randomness shown as like for like.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

from albot1.bench.grid import Cell
from albot1.bench.store import Failure
from albot1.report.collect import CellRecord
from albot1.report.thesis.evidence import Evidence, Store
from albot1.report.thesis.experiments.common import store_of

STORE = Path("results") / "thesis"


def _record(method: str, seed: int, *, failed: bool = False, degradation: str = "none") -> CellRecord:
    cell = Cell("thesis", "sq", "sq", method, method, "default", degradation, seed, f"{method}-{seed}", "v", 10, 100)
    if failed:
        failure = Failure("the mapper diverged", "exception", 2, 0.1, None)
        return CellRecord(cell, "failed", Path("/nonexistent"), None, None, failure)
    return CellRecord(cell, "done", Path("/nonexistent"), None, None, None)


def _evidence(records: list[CellRecord]) -> Evidence:
    return Evidence([Store("thesis", STORE, cast(Any, SimpleNamespace(machine={})), records)])


def test_a_method_whose_compared_seed_failed_is_missing_not_read_at_another_seed() -> None:
    # Listed in an order where the old rule and the store's order both disagree with the compared seed.
    records = [_record("b", 1), _record("a", 1), _record("a", 0, failed=True), _record("b", 0)]
    ev = _evidence(records)
    b = ev.find("sq", "b")
    assert b.record is not None and b.record.cell.seed == 0
    a = ev.find("sq", "a")
    assert a.record is None
    assert a.missing == (
        f"failed in {STORE} (seed 0, exception: the mapper diverged); seed 1 completed but is not compared: "
        "every method on sq is read at seed 0"
    )
    # The verdict's row names the seed its numbers come from.
    assert store_of(ev, "sq", ["a", "b"]) == f"`{STORE}` (seed 0 of seeds 0, 1)"


def test_one_seed_reads_as_before_and_a_method_without_the_compared_seed_says_so() -> None:
    ev = _evidence([_record("a", 0, failed=True), _record("b", 0)])
    assert ev.find("sq", "a").missing == f"failed in {STORE} (exception: the mapper diverged)"
    assert store_of(ev, "sq", ["a", "b"]) == f"`{STORE}`"
    ev = _evidence([_record("a", 1), _record("b", 0), _record("b", 1)])
    assert ev.find("sq", "a").missing == (
        f"no run on seed 0 in {STORE}; seed 1 completed but is not compared: every method on sq is read at seed 0"
    )


def test_each_degradation_has_its_own_compared_seed() -> None:
    records = [_record("a", 3, degradation="gauss"), _record("b", 3, degradation="gauss"), _record("a", 0)]
    ev = _evidence(records)
    found = ev.find("sq", "b", "gauss")
    assert found.record is not None and found.record.cell.seed == 3
