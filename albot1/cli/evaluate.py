"""``albot1 evaluate RUN_DIR``: compute a run's metrics into ``metrics.json``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

if TYPE_CHECKING:
    from albot1.records import MetricBlock


def register(app: typer.Typer) -> None:
    app.command("evaluate")(evaluate)


def evaluate(
    run_dir: Annotated[Path, typer.Argument(help="a run folder written by `albot1 run` (holds result.json, DONE)")],
    data_dir: Annotated[
        Path | None, typer.Option(help="dataset folder for the reference map (default: $ALBOT1_DATA_DIR)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print metrics.json as one JSON object")] = False,
) -> None:
    """Score the run against the dataset's reference and write RUN_DIR/metrics.json.

    Metrics that cannot be computed (no reference poses, no relations) are
    null with a reason beside them.

    Examples:\n
      albot1 evaluate runs/3f2a9c0d11e4b7a2\n
      albot1 evaluate runs/3f2a9c0d11e4b7a2 --json | jq .ate.rmse_m
    """
    from albot1.records import METRIC_NAMES
    from albot1.runs.evaluate import METRICS_FILE, evaluate_run
    from albot1.settings import get_settings

    metrics = evaluate_run(run_dir, settings=get_settings(data_dir=data_dir))
    written = run_dir / METRICS_FILE
    if as_json:
        # Re-read what was written, so stdout and the file agree exactly (NaN -> null included).
        typer.echo(json.dumps(json.loads(written.read_text())))
        return
    typer.echo(str(written))
    for name in METRIC_NAMES:
        block = metrics.block(name)
        line = _headline(block) if block is not None else f"null: {metrics.reason(name)}"
        typer.echo(f"  {name:12s} {line}")


def _f(value: float | None, fmt: str = ".3f") -> str:
    return "n/a" if value is None else format(value, fmt)


def _headline(block: MetricBlock) -> str:
    """One line per metric for people; the JSON has everything."""
    from albot1.records import (
        AteBlock,
        AteWindowsBlock,
        ClosedRouteGapBlock,
        DriftBlock,
        LoopGapBlock,
        MapShapeBlock,
        OrientationBlock,
        RelationsBlock,
        RpeBlock,
        UpdatesBlock,
    )

    f = _f
    if isinstance(block, AteBlock):
        return f"rmse {f(block.rmse_m)} m, max {f(block.max_m)} m ({block.alignment} alignment)"
    if isinstance(block, AteWindowsBlock):
        return (
            f"mean rmse {f(block.mean_rmse_m)} m over {block.windows} windows of {block.window_m:g} m "
            f"(max {f(block.window_rmse.max_m)} m)"
        )
    if isinstance(block, DriftBlock):
        at = block.at_10m
        if at is None:
            return f"no 10 m segment: {block.at_10m_reason}"
        return f"at 10 m: {f(at.translation_m)} m, {f(at.rotation_deg, '.2f')} deg mean over {at.pairs} segments"
    if isinstance(block, RpeBlock):
        return (
            f"delta {block.delta} {block.delta_unit}: {f(block.translation_m.rmse)} m, "
            f"{f(block.rotation_deg.rmse)} deg rmse"
        )
    if isinstance(block, (LoopGapBlock, ClosedRouteGapBlock)):
        pairs = block.translation_m if isinstance(block, LoopGapBlock) else None
        extra = f", {block.pairs} revisit pairs mean {f(pairs.mean)} m max {f(pairs.max)} m" if pairs else ""
        return f"route gap {f(block.route.gap_m)} m{extra}"
    if isinstance(block, OrientationBlock):
        return (
            f"{block.stops} stops, bearing |err| mean {f(block.bearing_abs_error_mean_deg, '.2f')} deg, "
            f"distance |err| mean {f(block.distance_abs_error_mean_m)} m"
        )
    if isinstance(block, RelationsBlock):
        t, r = block.translation_m, block.rotation_deg
        return f"{f(t.mean)} +/- {f(t.std)} m, {f(r.mean, '.2f')} +/- {f(r.std, '.2f')} deg, N = {t.n}"
    if isinstance(block, MapShapeBlock):
        return f"precision {f(block.precision)}, coverage {f(block.coverage)} (within {block.tolerance_m} m)"
    if isinstance(block, UpdatesBlock):
        return f"{block.updates} updates / {block.views} views"
    return (
        f"{f(block.per_scan_ms_median)} ms/scan median, p95 {f(block.per_scan_ms_p95)} ms, "
        f"peak {f(block.peak_mb, '.1f')} MiB"
    )
