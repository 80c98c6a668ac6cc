"""The stored results the thesis page reads: the thesis suite's store and its companions (``results/default``).

The results store keeps one folder per suite and a cell's key depends on
its suite's plan, so the thesis suite does not repeat the default suite's
public-log runs: the page reads those from the sibling store
``results/default`` (:data:`COMPANION_SUITES`), and every number it shows
names the store it came from. A store that is absent, or a cell that is
not in it, failed or was skipped, gives a :class:`Lookup` with the reason
instead of a record, and every number read from it is then missing with
that reason (the verdict says "not comparable"), never invented.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from albot1.bench.grid import GridPlan
from albot1.errors import Albot1Error
from albot1.metrics.measures.places import METRIC as PLACES
from albot1.metrics.measures.places import ExitsJudgement, PlacesBlock
from albot1.metrics.measures.updates import METRIC as UPDATES
from albot1.report.collect import METRIC_COLUMNS, CellRecord, Column, collect
from albot1.report.provenance import bench_command
from albot1.report.thesis.verdicts import Number
from albot1.report.tuning import record_held_in

#: The stores read beside ``results/thesis``, as sibling folders of it (``results/<name>``), in search order.
COMPANION_SUITES = ("default",)
#: Where a method's own counters sit in ``metrics.json`` (places, re-visits, exit predictions, ...).
COUNTERS = "updates.counters."


def counter_path(name: str) -> str:
    """The ``metrics.json`` path of a method's counter ``name``, or of the judgement of its claims.

    The counters of a network of places judged against the reference poses
    (``revisit_precision``, ``crossings_true``, ...) are the ``places``
    metric's block, not the method's own counters.
    """
    if name in PlacesBlock.model_fields:
        return f"{PLACES.name}.{name}"
    if name in ExitsJudgement.model_fields:
        return f"{PLACES.name}.exits.{name}"
    return f"{COUNTERS}{name}"


@dataclass
class Store:
    """One results folder: its plan and a record per planned cell."""

    name: str
    path: Path
    plan: GridPlan
    records: list[CellRecord]

    @property
    def code_version(self) -> str:
        return str(self.plan.machine.get("code_version"))


@dataclass(frozen=True)
class Lookup:
    """A completed cell found in a store, or why none was found."""

    record: CellRecord | None
    store: Store | None
    missing: str | None = None

    @property
    def found(self) -> bool:
        return self.record is not None


@dataclass
class Evidence:
    """Every store the page reads, searched in order (the thesis suite's own first)."""

    stores: list[Store]
    notes: list[str] = field(default_factory=list)

    def datasets(self) -> list[str]:
        """Dataset labels with at least one planned cell in any store, in plan order."""
        out: list[str] = []
        for s in self.stores:
            for rec in s.records:
                if rec.cell.dataset_label not in out:
                    out.append(rec.cell.dataset_label)
        return out

    def methods(self, dataset: str) -> list[str]:
        """Method labels planned on ``dataset`` in any store, in plan order."""
        out: list[str] = []
        for s in self.stores:
            for rec in s.records:
                if rec.cell.dataset_label == dataset and rec.cell.method_label not in out:
                    out.append(rec.cell.method_label)
        return out

    def find(self, dataset: str, method: str, degradation: str = "none") -> Lookup:
        """The completed cell of ``method`` on ``dataset`` at the compared seed, first store first; else why not.

        Every method on one (store, dataset, degradation) is read at the same seed (:func:`compared_seed`), so
        two methods' numbers set side by side come from the same randomness: a method whose run on that seed
        failed is missing with that reason, even when another of its seeds completed (the reason says so),
        never replaced by that other seed.
        """
        reasons: list[str] = []
        for s in self.stores:
            matching = [r for r in s.records if _is(r, dataset, method, degradation)]
            seed = compared_seed(s.records, dataset, degradation)
            on_seed = [r for r in matching if r.cell.seed == seed]
            at = f"seed {seed}, " if len(seeds_of(s.records, dataset, degradation)) > 1 else ""
            done = [r for r in on_seed if r.status == "done"]
            if done:
                return Lookup(done[0], s)
            others = sorted({r.cell.seed for r in matching if r.status == "done" and r.cell.seed != seed})
            also = (
                f"; seed {', '.join(map(str, others))} completed but is not compared: every method on {dataset} "
                f"is read at seed {seed}"
                if others
                else ""
            )
            failed = [r for r in on_seed if r.status == "failed" and r.failure is not None]
            if failed:
                f = failed[0].failure
                assert f is not None
                reason = " ".join(f.reason.split())[:160]
                reasons.append(f"failed in {s.path} ({at}{f.kind}: {reason}){also}")
            elif on_seed:
                reasons.append(f"not run yet in {s.path} (the runner stopped first){also}")
            elif matching:
                read_at = f": every method on {dataset} is read at seed {seed}"
                reasons.append(f"no run on seed {seed} in {s.path}{also or read_at}")
            else:
                skipped = _skip_reason(s.plan, dataset, method)
                if skipped:
                    reasons.append(f"{skipped} in {s.path}")
        if not reasons:
            searched = ", ".join(str(s.path) for s in self.stores) or "no results store"
            reasons.append(f"no {method} run on {dataset} [{degradation}] in {searched}")
        return Lookup(None, None, "; ".join(dict.fromkeys(reasons)))

    def number(self, lookup: Lookup, path: str, label: str, unit: str = "") -> Number:
        """The number at ``path`` of the found cell's ``metrics.json``, or missing with the reason.

        A number carries its cell's held-in mark (:func:`albot1.report.tuning.record_held_in`), which every
        verdict made from it and every table cell showing it keeps.
        """
        if lookup.record is None:
            return Number(label, None, unit, lookup.missing)
        column = metric_column(path)
        if column is None:
            return Number(label, None, unit, f"metrics.json has no field {path} in this version")
        value = column.value(lookup.record)
        if value is None:
            counter = path.removeprefix(COUNTERS)
            if counter != path and lookup.record.metrics is not None and lookup.record.metrics.get(UPDATES) is not None:
                reason = _absent_counter_reason(lookup.record, counter)
            else:
                reason = column.reason(lookup.record) or "no value"
            return Number(label, None, unit, reason)
        return Number(label, value, unit, held_in=record_held_in(lookup.record))


def _absent_counter_reason(record: CellRecord, counter: str) -> str:
    """Why a run's counters lack ``counter``: the places metric's words for an exit-prediction counter, else plain.

    A network of places counts its exit predictions (``exit_predictions_compared``,
    ``exit_prediction_aligned_mean_m``, ...) only when it compared one; then the places metric says why none was
    (no place recognised, the run ended first, ...), and "does not count it" would be untrue.
    """
    places = record.metrics.get(PLACES) if record.metrics is not None else None
    exits = places.exits if places is not None else None
    if counter.startswith("exit_prediction") and exits is not None and exits.exit_predictions_reason:
        return exits.exit_predictions_reason
    return f"the run reports no counter {counter!r} (its method or version does not count it)"


def metric_column(path: str) -> Column | None:
    """The report's column for ``path`` (with its applicability rule, e.g. the loop gap's), else a plain one.

    None when ``metrics.json`` has no such numeric field in this version of the code.
    """
    for column in METRIC_COLUMNS.values():
        if column.path == path:
            return column
    try:
        return Column("metrics", path, path)
    except KeyError:
        return None


def compared_seed(records: list[CellRecord], dataset: str, degradation: str) -> int | None:
    """The seed every method on ``dataset`` [``degradation``] of one store is read at: the lowest planned there.

    Chosen from the plan, not from what completed, so one method's failure never moves another method to a
    different seed; with one seed per cell (the suites' default) it is that seed.
    """
    return min(seeds_of(records, dataset, degradation), default=None)


def seeds_of(records: list[CellRecord], dataset: str, degradation: str) -> set[int]:
    """The seeds one store planned on ``dataset`` [``degradation``], any method."""
    return {r.cell.seed for r in records if r.cell.dataset_label == dataset and r.cell.degradation == degradation}


def _is(record: CellRecord, dataset: str, method: str, degradation: str) -> bool:
    c = record.cell
    return c.dataset_label == dataset and c.method_label == method and c.degradation == degradation


def _skip_reason(plan: GridPlan, dataset: str, method: str) -> str | None:
    base = method.split(":", 1)[0]
    for s in plan.skipped_methods:
        if s.name in (method, base):
            return f"{s.name} skipped ({s.reason}{f'; {s.hint}' if s.hint else ''})"
    for s in plan.skipped_datasets:
        if s.name == dataset or dataset.startswith(f"{s.name}[") or dataset.startswith(f"{s.name}?"):
            return f"{s.name} skipped ({s.reason}{f'; {s.hint}' if s.hint else ''})"
    return None


def open_stores(results_dir: Path, companions: tuple[str, ...] = COMPANION_SUITES) -> Evidence:
    """The store at ``results_dir`` and its companions beside it; an absent or unreadable companion is a note."""
    plan, records = collect(results_dir)
    stores = [Store(plan.suite, Path(results_dir), plan, records)]
    notes: list[str] = []
    for name in companions:
        path = Path(results_dir).parent / name
        if path.resolve() == Path(results_dir).resolve():
            continue
        if not (path / "grid.json").is_file():
            notes.append(
                f"`{path}` holds no results (run `{bench_command(name, path.parent)}`, or `make bench`): the "
                "public-log rows of Experiments 1, 2 and 6 are not comparable"
            )
            continue
        try:
            other_plan, other_records = collect(path)
        except Albot1Error as exc:
            notes.append(f"`{path}` cannot be read ({exc}); its rows are not comparable")
            continue
        stores.append(Store(other_plan.suite, path, other_plan, other_records))
    versions = {s.code_version for s in stores}
    if len(versions) > 1:
        notes.append(
            "the stores were made by different code versions ("
            + ", ".join(f"`{s.path}`: `{s.code_version}`" for s in stores)
            + "); each number is from the code that made its store"
        )
    return Evidence(stores, notes)
