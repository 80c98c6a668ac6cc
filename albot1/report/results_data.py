"""The record behind ``docs/results.md`` and the README's results block: numbers and what produced them.

Built from the stores ``make bench`` fills (the default suite: standard
benchmark and key ATE cells; the thesis suite: verdicts and the standard-log
columns of the methods only it runs), written as
``docs/results/results.json`` and read back by :mod:`albot1.report.results_page`,
which renders the page and the README block from it alone. Measured and
published rows are kept apart by ``kind``; nothing here reads the clock.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

from albot1.report.collect import collect
from albot1.report.errors import ReportError
from albot1.report.standard import Row, measured_rows, published_rows
from albot1.report.tuning import record_held_in

#: Layout of ``results.json``; a record of another version is not read.
FORMAT = 1
VARIANT_WORDS = ("holds", "does not hold", "not comparable")
#: The (dataset, degradation) cells of the default suite whose ATE per seed the README quotes: the issue targets'
#: "odometry about 4 m" setting on a real log, and the thesis's own degradation on its start-stop route.
KEY_ATE: tuple[tuple[str, str], ...] = (
    ("synthetic-office-startstop", "none"),
    ("synthetic-office-startstop", "gauss:0.1:1"),
    ("synthetic-office-startstop", "thesis"),
    ("intel-corrected?odometry=laser-pose", "none"),
    ("intel-corrected?odometry=laser-pose", "gauss:0.1:1"),
    ("intel-corrected?odometry=laser-pose", "thesis"),
)


@dataclass(frozen=True)
class StoreStamp:
    """One results folder the page reads: where, which suite, which code produced it, how many cells."""

    path: str
    suite: str
    code_version: str
    git: str | None
    cells: int
    done: int
    failed: int


@dataclass(frozen=True)
class StandardRow:
    """One row of the standard table: a measured run or a published system (never mixed) on one log."""

    log: str
    kind: str  # measured | published
    method: str
    status: str
    translation_mean_m: float | None
    translation_std_m: float | None
    rotation_mean_deg: float | None
    relations: int | None
    speed: float | None
    held_in: bool | None
    source: str
    note: str
    #: The results folder of a measured row taken from another store than the default suite's ("": the default's).
    store: str = ""
    #: Written since the page shows every published figure with its spread and every measured row with its
    #: medians (a record written before reads them as None): the rotational std, and the medians of a measured row
    #: (the relation errors are heavy-tailed: the median says how typical relations fare)
    rotation_std_deg: float | None = None
    translation_median_m: float | None = None
    rotation_median_deg: float | None = None
    #: A published row: the decimals its source printed its figures with (``standard.Row``); None: measured
    translation_decimals: int | None = None
    rotation_decimals: int | None = None


@dataclass(frozen=True)
class AteCell:
    """ATE RMSE of one method on one key (dataset, degradation) for one seed, or why there is none."""

    dataset: str
    degradation: str
    method: str
    seed: int
    rmse_m: float | None
    note: str
    #: the cell's held-in mark (albot1.report.tuning.record_held_in; None: unknown, or a record before it)
    held_in: bool | None = None


@dataclass(frozen=True)
class VerdictRow:
    """One thesis claim and its verdict tally per Albot1 variant (``""``: one verdict for every variant)."""

    experiment: str
    claim: str
    thesis: str
    tallies: dict[str, dict[str, int]]
    #: label -> how many of its verdicts rest on a held-in number (albot1.report.thesis.verdicts.held); none: 0
    held_in: dict[str, int] = field(default_factory=dict)


@dataclass
class ResultsData:
    """Everything the page and the README block show; written as JSON beside the page."""

    command: str
    stores: list[StoreStamp]
    libraries: dict[str, str | None]
    machine: str
    standard: list[StandardRow]
    ate: list[AteCell] = field(default_factory=list)
    verdict_columns: dict[str, str] = field(default_factory=dict)
    verdicts: list[VerdictRow] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    figures: dict[str, str] = field(default_factory=dict)  # file name -> caption

    def to_json(self) -> str:
        body = {"format": FORMAT, **asdict(self)}
        return json.dumps(body, indent=1, allow_nan=False)  # key order is column order + "\n"

    @classmethod
    def from_json(cls, text: str, where: str) -> ResultsData:
        try:
            body = json.loads(text)
            if body.get("format") != FORMAT:
                raise ValueError(f"format {body.get('format')!r}, expected {FORMAT}")
            return cls(
                command=body["command"],
                stores=[StoreStamp(**s) for s in body["stores"]],
                libraries=body["libraries"],
                machine=body["machine"],
                standard=[StandardRow(**r) for r in body["standard"]],
                ate=[AteCell(**a) for a in body["ate"]],
                verdict_columns=body["verdict_columns"],
                verdicts=[VerdictRow(**v) for v in body["verdicts"]],
                notes=body["notes"],
                figures=body["figures"],
            )
        except (ValueError, KeyError, TypeError, AttributeError) as exc:
            raise ReportError(f"{where}: not a results record of format {FORMAT} ({exc})") from exc


def _finite(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _standard_row(row: Row) -> StandardRow:
    return StandardRow(
        log=row.log,
        kind=row.kind,
        method=row.method,
        status=row.status,
        translation_mean_m=_finite(row.translation_mean_m),
        translation_std_m=_finite(row.translation_std_m),
        rotation_mean_deg=_finite(row.rotation_mean_deg),
        relations=row.relations,
        speed=_finite(row.speed) if row.kind == "measured" else None,
        held_in=row.held_in,
        source=row.source,
        note=row.note,
        rotation_std_deg=_finite(row.rotation_std_deg),
        translation_median_m=_finite(row.translation_median_m),
        rotation_median_deg=_finite(row.rotation_median_deg),
        translation_decimals=row.translation_decimals,
        rotation_decimals=row.rotation_decimals,
    )


def _stamp(path: Path, shown: str) -> tuple[StoreStamp, Any, list[Any]]:
    plan, records = collect(path)
    machine = plan.machine
    stamp = StoreStamp(
        path=shown,
        suite=plan.suite,
        code_version=str(machine.get("code_version")),
        git=machine.get("git"),
        cells=len(records),
        done=sum(r.status == "done" for r in records),
        failed=sum(r.status == "failed" for r in records),
    )
    return stamp, plan, records


def _tally(verdicts: list[Any]) -> dict[str, int]:
    counts = dict.fromkeys(VARIANT_WORDS, 0)
    for verdict in verdicts:
        counts[verdict.word] += 1
    return {word: n for word, n in counts.items() if n}


def ate_cells(records: list[Any]) -> list[AteCell]:
    """ATE RMSE per seed of every method on each :data:`KEY_ATE` pair the store holds (failed: why)."""
    from albot1.metrics.measures.ate import METRIC as ATE

    cells: list[AteCell] = []
    for dataset, degradation in KEY_ATE:
        for rec in records:
            cell = rec.cell
            if (cell.dataset_label, cell.degradation, cell.limit, cell.stride) != (dataset, degradation, None, None):
                continue
            block = rec.metrics.get(ATE) if rec.status == "done" and rec.metrics is not None else None
            if block is not None:
                note = ""
            elif rec.status != "done":
                note = rec.failure.reason if rec.failure is not None else rec.status
            else:
                note = (rec.metrics.reason(ATE.name) if rec.metrics is not None else None) or "no ATE"
            rmse = _finite(block.rmse_m) if block is not None else None
            held = record_held_in(rec)
            cells.append(
                AteCell(dataset, degradation, cell.method_label, cell.seed, rmse, " ".join(note.split()), held)
            )
    return sorted(cells, key=lambda c: (KEY_ATE.index((c.dataset, c.degradation)), c.seed))


def _verdicts(thesis_dir: Path) -> tuple[dict[str, str], list[VerdictRow], list[str]]:
    """The thesis page's verdicts at a glance: one row per claim, verdicts counted per variant."""
    from albot1.report.thesis.evidence import open_stores
    from albot1.report.thesis.experiments import all_sections

    ev = open_stores(thesis_dir)
    rows: list[VerdictRow] = []
    columns: dict[str, str] = {}
    for section in all_sections(ev):
        for text, group in section.claim_groups():
            if all("" in row.verdicts for row in group):
                shown = {"": [row.verdicts[""] for row in group]}
            else:
                shown = {
                    label: [row.verdicts[key] for row in group if key in row.verdicts]
                    for key, label in section.columns.items()
                }
                columns.update({label: label for label in section.columns.values()})
            tallies = {label: _tally(verdicts) for label, verdicts in shown.items()}
            held = {label: n for label, verdicts in shown.items() if (n := sum(v.held_in for v in verdicts))}
            rows.append(VerdictRow(section.title.split(":")[0], text, group[0].thesis, tallies, held))
    return columns, rows, list(ev.notes)


#: Why a standard-log row read from the thesis suite's store shows no speed.
THESIS_SPEED_NOTE = "no speed shown: make bench runs this grid beside the default suite's report"


def thesis_rows(default: list[StandardRow], thesis: list[Any], store: str) -> list[StandardRow]:
    """The thesis store's whole-log rows on the standard logs, of the methods the default store has none of.

    Why: the thesis suite runs the Albot1 variants the default suite leaves out (``albot1:literal``,
    ``albot1:plus``) on every default-suite dataset, the five standard logs whole among them, so the standard
    table can show Albot1+ beside the others without running it twice. The rows name their store (``store``);
    their speed is left out, since ``make bench`` runs the thesis grid while the default report is drawn, so its
    timings are those of a loaded machine (the default suite's cells run alone).
    """
    shown = {row.method for row in default}
    rows: list[StandardRow] = []
    for row in map(_standard_row, measured_rows(thesis)):
        if row.method in shown:
            continue
        said = row.note.replace("this suite's", f"{store}'s")  # "this suite" would read as the default suite
        speed = THESIS_SPEED_NOTE if row.speed is not None else ""
        note = "; ".join(part for part in (said, f"from {store}", speed) if part)
        source = (
            f"{store}, {row.source.removeprefix('this suite, ')}"
            if row.source.startswith("this suite, ")
            else row.source
        )
        rows.append(replace(row, speed=None, source=source, note=note, store=store))
    return rows


def check_thesis_store(thesis_dir: Path) -> None:
    """ReportError (one line) when ``thesis_dir`` holds the results of a suite other than the thesis suite.

    Why: the verdicts are the thesis page's experiments, which read their datasets and methods by the thesis
    suite's tags and labels; on another store (``--thesis results/default``) they would be "not comparable"
    or drawn from the wrong runs, and its methods would join the standard table as "the thesis suite's".
    A store names its suite in its ``grid.json`` (the plan ``albot1 bench`` wrote).
    """
    from albot1.bench.store import ResultsStore
    from albot1.report.thesis.experiments.datasets import THESIS_SUITE

    suite = ResultsStore(thesis_dir).read_plan().suite
    if suite != THESIS_SUITE:
        raise ReportError(
            f"{thesis_dir.as_posix()}: --thesis expects the results of the {THESIS_SUITE!r} suite (`albot1 bench "
            f"{THESIS_SUITE}`), found those of suite {suite!r}; give its results folder, e.g. results/{THESIS_SUITE}"
        )


def build_data(
    default_dir: Path, thesis_dir: Path | None, command: str, *, shown: dict[Path, str] | None = None
) -> ResultsData:
    """The record of ``default_dir`` (standard benchmark) and ``thesis_dir`` (verdicts; None: not shown).

    The standard table also takes from ``thesis_dir`` the methods ``default_dir`` lacks (:func:`thesis_rows`).
    A ``thesis_dir`` that is no results folder yet is a note (``make bench`` may not have run the thesis
    suite); one that holds another suite's results is a ReportError (:func:`check_thesis_store`).
    """
    if thesis_dir is not None and (thesis_dir / "grid.json").is_file():
        check_thesis_store(thesis_dir)
    names = shown or {}
    stamp, plan, records = _stamp(default_dir, names.get(default_dir, default_dir.as_posix()))
    stores = [stamp]
    measured = [_standard_row(r) for r in measured_rows(records)]
    published = [_standard_row(r) for r in published_rows()]
    machine = plan.machine
    model = machine.get("cpu_model") or machine.get("processor") or "unknown CPU"
    data = ResultsData(
        command=command,
        stores=stores,
        libraries=dict(sorted((machine.get("libraries") or {}).items())),
        machine=f"{model}, {machine.get('cpu_count')} logical CPUs, Python {machine.get('python')}",
        standard=measured + published,
        ate=ate_cells(records),
    )
    taken: list[StandardRow] = []
    if thesis_dir is None:
        data.notes.append("No thesis suite given: no verdicts, and no column of the methods only it runs.")
    elif not (thesis_dir / "grid.json").is_file():
        data.notes.append(
            f"{thesis_dir.as_posix()} is not a results folder (no grid.json): no verdicts, and no column of the "
            "methods only the thesis suite runs (albot1:plus, albot1:literal)."
        )
    else:
        tstamp, _, trecords = _stamp(thesis_dir, names.get(thesis_dir, thesis_dir.as_posix()))
        data.stores.append(tstamp)
        taken = thesis_rows(measured, trecords, tstamp.path)
        data.standard = [*measured, *taken, *published]
        data.verdict_columns, data.verdicts, notes = _verdicts(thesis_dir)
        data.notes += notes
    if not measured and not taken:
        data.notes.append(f"{stamp.path} holds no whole-log run on the five standard logs: no measured row.")
    return data


def load_data(record: Path) -> ResultsData | None:
    """The record at ``record``, or None when it has not been written yet."""
    if not record.is_file():
        return None
    return ResultsData.from_json(record.read_text(encoding="utf-8"), str(record))
