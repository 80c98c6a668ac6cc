"""Which data every number of a report comes from: the data checksums per dataset.

A completed run records the sha256 of every file its dataset was read from
(``result.json`` ``dataset_info.data_sha256``; :mod:`albot1.data.identity`).
A report states them per dataset on each page, and never lets runs of one
dataset label on different data share a table row or a plot: when the
records of one label come from more than one data identity, each record's
label gains the short checksum of its data (``aces @b663e2976ed0``), before
any table or plot groups them (:func:`separate_data`).
"""

from __future__ import annotations

import hashlib
import shlex
from dataclasses import replace
from pathlib import Path

from albot1.bench.errors import SuiteError
from albot1.bench.grid import GridPlan
from albot1.bench.suite import find_suite
from albot1.data.identity import short
from albot1.report.collect import CellRecord
from albot1.report.folders import default_out
from albot1.settings import RESULTS_ROOT


def data_checksums(record: CellRecord) -> dict[str, str]:
    """File name -> sha256 of the data the record's run read (empty: not run, or no data file)."""
    return dict(record.result.dataset_info.data_sha256) if record.result is not None else {}


def data_identity(record: CellRecord) -> str:
    """The short checksum naming the record's data: its file's, or one over all its files ("" for none)."""
    checksums = data_checksums(record)
    if not checksums:
        return ""
    if len(checksums) == 1:
        return short(next(iter(checksums.values())))
    joined = "\n".join(f"{name}\0{sha}" for name, sha in sorted(checksums.items()))
    return short(hashlib.sha256(joined.encode()).hexdigest())


def separate_data(records: list[CellRecord]) -> list[CellRecord]:
    """``records`` with a dataset label made unique per data identity (see the module docstring).

    Records without a checksum (failed or not run) keep their label: they
    hold no numbers.
    """
    identities: dict[str, set[str]] = {}
    for rec in records:
        identity = data_identity(rec)
        if identity:
            identities.setdefault(rec.cell.dataset_label, set()).add(identity)
    out = []
    for rec in records:
        identity = data_identity(rec)
        if identity and len(identities.get(rec.cell.dataset_label, ())) > 1:
            cell = replace(rec.cell, dataset_label=f"{rec.cell.dataset_label} @{identity}")
            rec = replace(rec, cell=cell)
        out.append(rec)
    return out


def data_by_dataset(records: list[CellRecord]) -> dict[str, dict[str, str]]:
    """Dataset label -> {file name: short checksum} of its completed records ({} for a synthetic world).

    Call it on :func:`separate_data`'s output: a label then has one identity.
    """
    out: dict[str, dict[str, str]] = {}
    for rec in records:
        if rec.result is None:
            continue
        files = out.setdefault(rec.cell.dataset_label, {})
        files.update({name: short(sha) for name, sha in data_checksums(rec).items()})
    return out


def describe_data(files: dict[str, str]) -> str:
    """``aces.clf.bz2 sha256 b663e2976ed0, aces.relations sha256 11a15800a751`` (plain text)."""
    if not files:
        return (
            "no data file recorded (a synthetic world, named by the code version, or a result written before "
            "data checksums were recorded)"
        )
    return ", ".join(f"{name} sha256 {sha}" for name, sha in sorted(files.items()))


def data_lines(records: list[CellRecord]) -> list[str]:
    """``label: files`` per dataset label and data identity (plain text; one line per identity).

    For pages that show records of several results folders side by side,
    where one label may have been run on different data in each.
    """
    seen: dict[tuple[str, str], str] = {}
    for rec in records:
        if rec.result is None:
            continue
        key = (rec.cell.dataset_label, data_identity(rec))
        if key not in seen:
            files = {name: short(sha) for name, sha in data_checksums(rec).items()}
            seen[key] = f"{rec.cell.dataset_label}: {describe_data(files)}"
    return list(seen.values())


def bench_argument(plan: GridPlan) -> str:
    """What to give ``albot1 bench`` to run the plan's suite again: its name when that finds its file, else the path.

    A page's "Regenerate" line used to say ``albot1 bench robot`` for a
    user's own ``robot.toml``, which ``albot1 bench`` looks up among the
    shipped suites and does not find.
    """
    if plan.suite_path is None:
        return plan.suite
    try:
        same = find_suite(plan.suite).resolve() == Path(plan.suite_path).resolve()
    except SuiteError:
        same = False
    return plan.suite if same else plan.suite_path


def bench_command(suite: str, results_root: Path) -> str:
    """``albot1 bench SUITE``, with ``--results ROOT`` unless ``results_root`` is the default (``results``).

    ``albot1 bench`` writes into ``ROOT/<suite>``: a page drawn from a store
    elsewhere that printed the bare command would send a re-run (or the
    resume of unfinished cells) into another folder than the one it shows.
    """
    option = "" if results_root == RESULTS_ROOT else f" --results {shlex.quote(str(results_root))}"
    return f"albot1 bench {shlex.quote(suite)}{option}"


def rerun_command(plan: GridPlan, results_dir: Path) -> str:
    """``albot1 bench`` of the plan's suite into the store at ``results_dir`` (a run again, or the resume)."""
    return bench_command(bench_argument(plan), Path(results_dir).parent)


def regenerate_command(plan: GridPlan, results_dir: Path | None = None, out: Path | None = None) -> str:
    """The commands that write a page again: the suite run into its store, then the report of it into ``out``.

    ``results_dir`` is the store as the report was given it (printed as
    given, as the pages link relative to it). ``albot1 bench`` writes into
    ``<its parent>/<suite>``: that is the folder the report reads again (the
    same one unless the store was renamed). ``--out`` is named when the report
    did not go to its default place. None: the defaults (``results/<suite>``,
    ``reports/<suite>``).
    """
    results_dir = RESULTS_ROOT / plan.suite if results_dir is None else Path(results_dir)
    store = results_dir.parent / plan.suite
    out = default_out(store) if out is None else out
    report = f"albot1 report {shlex.quote(str(store))}"
    if Path(out).resolve() != default_out(store).resolve():
        report += f" --out {shlex.quote(str(out))}"
    return f"{rerun_command(plan, results_dir)} && {report}"
