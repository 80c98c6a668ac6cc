"""``albot1 run METHOD DATASET``: one method on one dataset into a run folder."""

from __future__ import annotations

import contextlib
import json
import sys
from pathlib import Path
from typing import Annotated

import typer

from albot1.cli.choices import METHOD_HELP, PRESET_HELP, RegistryHelpCommand
from albot1.cli.progress import enabled, slice_bound, with_progress
from albot1.runs.output import writable_folder
from albot1.settings import get_settings

_DEGRADE_HELP = "none | thesis | gauss:SXY_M:STH_DEG | bias:DX_M:DTH_DEG | offset:DX_M:DY_M:DTH_DEG | dropout:P"


def register(app: typer.Typer) -> None:
    app.command("run", cls=RegistryHelpCommand)(run)


def run(
    method: Annotated[str, typer.Argument(help=METHOD_HELP)],
    dataset: Annotated[
        str,
        typer.Argument(
            help="NAME (`albot1 datasets list`), NAME[:N] (first N scans), NAME?key=value (loader options) "
            "or a log file path; see `albot1 --help`"
        ),
    ],
    preset: Annotated[str, typer.Option(help=PRESET_HELP)] = "default",
    degrade: Annotated[str, typer.Option(help=_DEGRADE_HELP)] = "none",
    seed: Annotated[int, typer.Option(help="seed of the degradation and of any random choice")] = 0,
    out: Annotated[
        Path, typer.Option(help="results root; the run folder is OUT/<hash>, OUT/latest links it (`albot1 runs`)")
    ] = Path("runs"),
    set_: Annotated[list[str] | None, typer.Option("--set", help="config override FIELD=VALUE (repeatable)")] = None,
    data_dir: Annotated[Path | None, typer.Option(help="dataset folder (default: $ALBOT1_DATA_DIR)")] = None,
    limit: Annotated[
        int | None, typer.Option(help="use only the first N scans (same as DATASET[:N]; part of the run's name)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print one JSON object")] = False,
) -> None:
    """Run METHOD on DATASET and write the run folder (trajectory, map, counters, preview).

    The folder is named by a hash of its inputs; OUT/latest points at the last one written and
    `albot1 runs OUT` lists them all. A progress bar shows on stderr when it is a terminal.

    Examples:\n
      albot1 run albot1 aces --preset thesis --out runs\n
      albot1 run gtsam-graph intel-corrected --degrade gauss:0.1:1 --seed 1
    """
    # The layers that do the work are imported by the command, not by this module: see albot1.cli.app.
    from albot1.data.degrade import check_seed, parse_spec
    from albot1.data.errors import SliceError
    from albot1.data.open import canonical_reference, open_sequence
    from albot1.methods.registry import parse_overrides
    from albot1.records import dump_record
    from albot1.report.preview import render_preview
    from albot1.report.tuning import held_in_line, run_held_in
    from albot1.runs.execute import run_method
    from albot1.runs.folder import mark_latest, read_result, write_run

    # Bad arguments fail before the log is opened and the method runs, not after.
    overrides = parse_overrides(set_ or [])
    check_seed(seed)
    # Recorded in its one spelling: `GAUSS:0.10:1` and `gauss:0.1:1` are one run key, one table row (as in a suite).
    degrade = parse_spec(degrade).spec
    if limit is not None and limit < 1:
        raise SliceError(f"--limit {limit}: expected a positive number of scans (at least 1)")
    writable_folder(out, "--out")
    # The limit is part of the dataset's name (NAME[:N], as in the bench), so it is in the run's key and
    # result.json: runs on different prefixes get different folders, and `albot1 evaluate` reopens the prefix.
    # In the one spelling of its slice (as a suite's cells are): `NAME[0:30]`, `NAME[:030]`, `NAME[::1][:30]`
    # and `NAME --limit 30` are one run, so one key and one folder, not five.
    dataset = canonical_reference(dataset if limit is None else f"{dataset}[:{limit}]")
    sequence = open_sequence(dataset, settings=get_settings(data_dir=data_dir))
    sequence = with_progress(sequence, f"{method} on {dataset}", at_most=slice_bound(dataset))
    # What the method prints (a plugin's progress lines, a library's banner) goes to stderr: stdout carries the
    # command's result alone, so `--json` is one JSON object a script can parse.
    with contextlib.redirect_stdout(sys.stderr):
        result = run_method(
            method,
            sequence,
            preset=preset,
            overrides=overrides,
            degradation=degrade,
            seed=seed,
            dataset_name=dataset,
            # Said once, on a terminal: a method's start-up (e.g. numba compiling on a code version's first run).
            announce=(lambda line: typer.echo(line, err=True)) if enabled() else None,
        )
    run_dir = write_run(result, out, preview=render_preview)
    mark_latest(out, run_dir)
    record = read_result(run_dir)  # the headline says what result.json says
    # its counts and timings were measured on a dataset the preset may have been tuned on: say so, as the pages do
    files = record.dataset_info.data_sha256.values()
    if as_json:
        summary = {
            "run_dir": str(run_dir),
            "method": record.method,
            "dataset": record.dataset,
            "preset": record.preset,
            "degradation": record.degradation,
            "seed": record.seed,
            "scans": record.scans,
            "status": "done",
            "counters": record.counters,
            "timing": dump_record(record.timing),
            "held_in": run_held_in(record.method, record.preset, record.dataset, files),
        }
        typer.echo(json.dumps(summary))
    else:
        median = record.timing.per_scan_ms_median
        typer.echo(
            f"{record.method} on {record.dataset}: {record.scans} scans, {record.counters.get('updates')} updates, "
            f"{'n/a' if median is None else format(median, '.3f')} ms/scan median -> {run_dir}"
        )
        line = held_in_line(record.method, record.preset, record.dataset, files)
        if line is not None:
            typer.echo(line)
