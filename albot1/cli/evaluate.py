"""``albot1 evaluate RUN_DIR``: compute a run's metrics into ``metrics.json``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

import typer


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
    from albot1.runs.evaluate import METRIC_KEYS, METRICS_FILE, evaluate_run
    from albot1.settings import get_settings

    metrics = evaluate_run(run_dir, settings=get_settings(data_dir=data_dir))
    written = run_dir / METRICS_FILE
    if as_json:
        # Re-read what was written, so stdout and the file agree exactly (NaN -> null included).
        typer.echo(json.dumps(json.loads(written.read_text())))
        return
    typer.echo(str(written))
    for key in METRIC_KEYS:
        block = metrics.get(key)
        line = _headline(key, block) if block is not None else f"null: {metrics.get(key + '_reason')}"
        typer.echo(f"  {key:12s} {line}")


def _headline(key: str, block: dict[str, Any]) -> str:
    """One line per metric for people; the JSON has everything."""

    def f(value: Any, fmt: str = ".3f") -> str:
        return "n/a" if value is None else format(value, fmt)

    if key == "ate":
        return f"rmse {f(block['rmse_m'])} m, max {f(block['max_m'])} m ({block['alignment']} alignment)"
    if key == "rpe":
        return (
            f"delta {block['delta']} {block['delta_unit']}: {f(block['translation_m']['rmse'])} m, "
            f"{f(block['rotation_deg']['rmse'])} deg rmse"
        )
    if key == "loop_gap":
        pairs = block.get("translation_m")
        extra = f", {block['pairs']} revisit pairs mean {f(pairs['mean'])} m max {f(pairs['max'])} m" if pairs else ""
        return f"route gap {f(block['route']['gap_m'])} m{extra}"
    if key == "orientation":
        return (
            f"{block['stops']} stops, bearing |err| mean {f(block['bearing_abs_error_mean_deg'], '.2f')} deg, "
            f"distance |err| mean {f(block['distance_abs_error_mean_m'])} m"
        )
    if key == "relations":
        t, r = block["translation_m"], block["rotation_deg"]
        return f"{f(t['mean'])} +/- {f(t['std'])} m, {f(r['mean'], '.2f')} +/- {f(r['std'], '.2f')} deg, N = {t['n']}"
    if key == "map_shape":
        return f"precision {f(block['precision'])}, coverage {f(block['coverage'])} (within {block['tolerance_m']} m)"
    if key == "updates":
        return f"{block['updates']} updates / {block['views']} views"
    if key == "cost":
        return (
            f"{f(block['per_scan_ms_median'])} ms/scan median, p95 {f(block['per_scan_ms_p95'])} ms, "
            f"peak {f(block['peak_mb'], '.1f')} MiB"
        )
    return ""
