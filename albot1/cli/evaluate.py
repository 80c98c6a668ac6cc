"""``albot1 evaluate``: score a run folder, or any trajectory file, into ``metrics.json``."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from albot1.cli.progress import with_progress
from albot1.errors import Albot1Error
from albot1.settings import get_settings

if TYPE_CHECKING:
    from albot1.metrics.record import MetricsRecord
    from albot1.runs.scored import Scored
    from albot1.settings import Settings

DATASET_HELP = (
    "the dataset the trajectory was made on: NAME, NAME[:N] (its first N scans), NAME?key=value "
    "(loader options) or a log path (see `albot1 datasets list`)"
)
#: ``albot1.runs.external.MAX_DT_S`` as the help states it; written out so that the help does not import the
#: runs layer (see albot1.cli.app), kept equal to it by tests/unit/cli/test_cli_evaluate.py.
MAX_DT_HELP = "largest pose-to-scan time difference (s; default 0.01, evo's t_max_diff)"
#: ``albot1.runs.pair.ALIGN_CHOICES`` in words (kept equal by tests/unit/cli/test_cli_evaluate_pair.py).
ALIGN_HELP = (
    "se2 (rigid on all pairs, evo --align) | origin (first poses made equal, evo --align_origin) | "
    "first:N (rigid on the first N pairs, evo --n_to_align N) | none"
)


def register(app: typer.Typer) -> None:
    app.command("evaluate")(evaluate)


def evaluate(
    run_dir: Annotated[
        Path | None,
        typer.Argument(help="a run folder written by `albot1 run` (holds result.json, DONE); or use --trajectory"),
    ] = None,
    trajectory: Annotated[
        Path | None,
        typer.Option(
            help="score this trajectory file of another tool instead of a run folder (needs --dataset or --reference)"
        ),
    ] = None,
    dataset: Annotated[str | None, typer.Option(help=DATASET_HELP)] = None,
    format_name: Annotated[
        str | None,
        typer.Option(
            "--format",
            help="tum (t x y z qx qy qz qw) | kitti (3x4 [R|t] per line, one per scan) | carmen (corrected log); "
            "default: from the file",
        ),
    ] = None,
    label: Annotated[
        str | None, typer.Option(help="the method's name in the metrics (default: the file's stem)")
    ] = None,
    max_dt: Annotated[float | None, typer.Option(help=MAX_DT_HELP)] = None,
    reference: Annotated[
        Path | None,
        typer.Option(
            help="with --trajectory, instead of --dataset: score against this reference trajectory file "
            "(tum | kitti | carmen corrected log), like evo_ape/evo_rpe"
        ),
    ] = None,
    reference_format: Annotated[
        str | None, typer.Option(help="the --reference file's format (default: from the file)")
    ] = None,
    align: Annotated[
        str | None,
        typer.Option(
            help=f"ATE alignment: {ALIGN_HELP} (default se2)",
        ),
    ] = None,
    time_offset: Annotated[
        float | None,
        typer.Option(help="seconds added to the trajectory's timestamps before matching (evo's --t_offset)"),
    ] = None,
    out: Annotated[Path | None, typer.Option(help="with --trajectory: write the metrics JSON to this file")] = None,
    evo: Annotated[
        Path | None,
        typer.Option(help="also write evo result files (NAME.ape.zip, NAME.rpe.zip) into this folder, for evo_res"),
    ] = None,
    data_dir: Annotated[
        Path | None, typer.Option(help="dataset folder for the reference (default: $ALBOT1_DATA_DIR)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print the metrics as one JSON object")] = False,
    # --- plots (evo_ape --plot / evo_traj): albot1.report.evaluate_plots
    plot: Annotated[
        Path | None,
        typer.Option(help="draw the trajectory coloured by error, error over time and distance, into this folder"),
    ] = None,
    plot_also: Annotated[
        list[Path] | None,
        typer.Option(help="with --plot: more trajectory files drawn beside it, scored against the same dataset"),
    ] = None,
) -> None:
    """Score a run, or any trajectory, against the dataset's reference poses and relations.

    With --trajectory FILE --reference GT: score two trajectory files against each other,
    like evo_ape/evo_rpe (--align se2|origin|first:N|none, --time-offset S), no dataset needed.

    With RUN_DIR: write RUN_DIR/metrics.json. With --trajectory FILE --dataset NAME: score a
    trajectory made by another tool (Cartographer, slam_toolbox, GMapping, ...) with the same
    metrics; its poses are matched to the dataset's scans by time (TUM, CARMEN) or by order
    (KITTI), and poses left out are counted and reported. Metrics that cannot be computed (no
    reference poses, no relations; map, counters and timing for a trajectory file) are null
    with a reason beside them.

    Examples:\n
      albot1 evaluate runs/3f2a9c0d11e4b7a2\n
      albot1 evaluate runs/3f2a9c0d11e4b7a2 --json | jq .ate.rmse_m\n
      albot1 evaluate --trajectory cartographer.tum --dataset intel-corrected \\
          --out carto.json\n
      albot1 evaluate --trajectory intel.gfs.log --format carmen \\
          --dataset intel-corrected --evo evo-results/\n
      albot1 evaluate --trajectory est.tum --reference gt.tum \\
          --align origin --time-offset 0.05
    """
    # The runs layer is imported by the command, not by this module: see albot1.cli.app.
    from albot1.records import dump_record
    from albot1.runs.evaluate import evaluate_run, evaluate_trajectory
    from albot1.runs.folder import METRICS_FILE, read_run
    from albot1.runs.scored import scored_run

    settings = get_settings(data_dir=data_dir)
    if plot_also and plot is None:
        raise typer.BadParameter("--plot-also adds files to the figures of --plot DIR; give --plot DIR too")
    if (run_dir is None) == (trajectory is None):
        raise typer.BadParameter("give either RUN_DIR or --trajectory FILE (with --dataset NAME), not both")
    if trajectory is None:
        assert run_dir is not None
        for flag, value in (
            ("--dataset", dataset),
            ("--format", format_name),
            ("--label", label),
            ("--out", out),
            ("--reference", reference),
            ("--reference-format", reference_format),
            ("--align", align),
            ("--time-offset", time_offset),
        ):
            if value is not None:
                raise typer.BadParameter(f"{flag} goes with --trajectory; a run folder names its own dataset")
        metrics = evaluate_run(run_dir, settings=settings)
        written = run_dir / METRICS_FILE
        if evo is not None:
            _evo(scored_run(read_run(run_dir)), evo, f"{metrics.run.method}_{metrics.run.key}")
        if plot is not None:
            _plot(scored_run(read_run(run_dir)), metrics.run.dataset, plot, plot_also or [], max_dt, settings)
        if as_json:
            # Re-read what was written, so stdout and the file agree exactly (NaN -> null included).
            typer.echo(json.dumps(json.loads(written.read_text())))
            return
        typer.echo(str(written))
        _print_headlines(metrics)
        _print_held_in(metrics)
        return
    if reference is not None or reference_format is not None:
        if dataset is not None or reference is None:
            raise typer.BadParameter("give --trajectory FILE with either --dataset NAME or --reference FILE, not both")
        _evaluate_pair(
            trajectory,
            reference,
            out=out,
            evo=evo,
            plot=plot,
            plot_also=plot_also or [],
            as_json=as_json,
            format_name=format_name,
            reference_format=reference_format,
            label=label,
            max_dt_s=max_dt,
            time_offset_s=time_offset,
            align=align,
        )
        return
    if dataset is None:
        raise typer.BadParameter(
            "--trajectory needs --dataset NAME (the dataset whose reference scores it) or --reference FILE"
        )
    metrics, scored = evaluate_trajectory(
        trajectory,
        dataset,
        format_name=format_name,
        label=label,
        max_dt_s=max_dt,
        settings=settings,
        out=out,
        wrap=lambda sequence: with_progress(sequence, f"reading {dataset}"),
        time_offset_s=time_offset,
        align=align,
    )
    _note_left_out(metrics)
    if evo is not None:
        _evo(scored, evo, _file_name(metrics.run.method))
    if plot is not None:
        _plot(scored, dataset, plot, plot_also or [], max_dt, settings)
    if as_json:
        typer.echo(json.dumps(dump_record(metrics)))
        return
    typer.echo(f"{trajectory} on {dataset}" + (f" -> {out}" if out is not None else ""))
    _print_reference_coverage(metrics)
    _print_headlines(metrics)


def _evaluate_pair(
    trajectory: Path,
    reference: Path,
    *,
    out: Path | None,
    evo: Path | None,
    plot: Path | None,
    plot_also: list[Path],
    as_json: bool,
    **options: Any,
) -> None:
    """``--trajectory EST --reference REF``: two files scored like evo_ape/evo_rpe (see albot1.runs.pair).

    ``--plot`` draws the same figures as with a dataset (it used to be ignored here without a word), the
    ``--plot-also`` files matched to the same reference file with the same options.
    """
    from albot1.records import dump_record
    from albot1.runs.evaluate import evaluate_pair
    from albot1.runs.pair import load_pair

    metrics, scored = evaluate_pair(trajectory, reference, out=out, **options)
    _note_left_out(metrics)
    if evo is not None:
        _evo(scored, evo, _file_name(metrics.run.method))
    if plot is not None:
        also = {key: value for key, value in options.items() if key != "label"}  # each file its own name
        _draw([scored] + [load_pair(path, reference, **also) for path in plot_also], plot)
    if as_json:
        typer.echo(json.dumps(dump_record(metrics)))
        return
    typer.echo(f"{trajectory} against {reference}" + (f" -> {out}" if out is not None else ""))
    _print_reference_coverage(metrics)
    _print_headlines(metrics)


def _print_reference_coverage(metrics: MetricsRecord) -> None:
    """One summary line: how many reference poses (scans) were scored and how many had no pose of the file."""
    source = metrics.trajectory
    if source is None or source.reference_without_pose is None:
        return
    total = source.matched + source.reference_without_pose
    extra = []
    if source.time_offset_s:
        extra.append(f"time offset {source.time_offset_s:g} s")
    if source.alignment:
        extra.append(f"--align {source.alignment}")
    typer.echo(
        f"  reference    {source.matched} of {total} reference poses scored, {source.reference_without_pose} "
        f"had no pose of the trajectory" + (f" ({', '.join(extra)})" if extra else "")
    )


def _print_headlines(metrics: MetricsRecord) -> None:
    for line in headlines(metrics):
        typer.echo(line)


def _print_held_in(metrics: MetricsRecord) -> None:
    """One line when the run's method was tuned on its dataset (the pages' mark, albot1.report.tuning).

    A trajectory file's scores print none: the system that made it records no tuning here (unknown, not "not
    tuned"), and the mark is about a method's preset, which a file has not.
    """
    from albot1.report.tuning import held_in_line

    run = metrics.run
    line = held_in_line(run.method, run.preset, run.dataset, run.data_sha256.values())
    if line is not None:
        typer.echo(f"  {line}")


def headlines(metrics: MetricsRecord) -> list[str]:
    """One line per metric of the registry: its own headline, or ``null:`` and the reason it does not apply.

    A number the report leaves out although it was computed (a column's ``applies``: a loop gap on a route that
    never returns) says so, with the report's reason: it used to print ``route gap 3.552 m`` for a straight
    corridor, or for a robot that never moved, where the report's column says n/a.
    """
    from albot1.metrics.registry import metric_registry

    lines = []
    for metric in metric_registry():
        block = metrics.block(metric.name)
        line = metric.headline(block) if block is not None else f"null: {metrics.reason(metric.name)}"
        for spec in metric.columns if block is not None else ():
            why = spec.applies(block, metrics) if spec.applies is not None else None
            if why is not None and why not in line:  # a headline that says it already (orientation, places)
                line += f"; the report's {spec.header.split(' (')[0]} column: n/a ({why})"
        lines.append(f"  {metric.name:12s} {line}")
    return lines


def _note_left_out(metrics: MetricsRecord) -> None:
    """One line on stderr when poses of the file were not scored (the counts are in the JSON too)."""
    source = metrics.trajectory
    if source is None or not (source.unmatched or source.duplicates):
        return
    typer.echo(
        f"note: {source.matched} of {source.poses} poses of {source.file} matched a scan within "
        f"{source.max_dt_s:g} s and were scored; left out: {source.unmatched} with no scan that near, "
        f"{source.duplicates} whose scan had a nearer pose",
        err=True,
    )


def _evo(scored: Scored, folder: Path, name: str) -> None:
    from albot1.runs.evo_results import write_evo_results

    try:
        written = write_evo_results(scored, folder, prefix=f"{name}.")
    except Albot1Error as exc:
        typer.echo(f"note: no evo result files: {exc}", err=True)
        return
    typer.echo(f"evo results: {', '.join(str(p) for p in written)}", err=True)


def _plot(
    first: Scored, dataset: str, folder: Path, also: list[Path], max_dt: float | None, settings: Settings
) -> None:
    """``--plot``: ``first`` and the ``also`` files scored against ``dataset``, drawn (:func:`_draw`)."""
    from albot1.runs.external import load_external

    _draw([first] + [load_external(p, dataset, max_dt_s=max_dt, settings=settings) for p in also], folder)


def _draw(items: list[Scored], folder: Path) -> None:
    """The figures of :mod:`albot1.report.evaluate_plots` for ``items`` (the first the main one), listed on stderr."""
    from albot1.report.evaluate_plots import plot_scored

    drawn = plot_scored(items, folder)
    typer.echo(f"plots: {', '.join(str(p) for p in drawn.files)}", err=True)
    if drawn.missing is not None:
        typer.echo(f"note: {drawn.missing}", err=True)


def _file_name(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "trajectory"
