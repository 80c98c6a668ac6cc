"""``albot1 runs [ROOT]``: what run folders a runs root holds (``albot1 run --out ROOT`` writes them)."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Annotated, Any

import typer


def register(app: typer.Typer) -> None:
    app.command("runs")(runs)


def runs(
    root: Annotated[
        Path, typer.Argument(help="a folder of run folders (`albot1 run --out`; a bench's RESULTS/SUITE/runs)")
    ] = Path("runs"),
    as_json: Annotated[bool, typer.Option("--json", help="print one JSON object")] = False,
) -> None:
    """List the run folders under ROOT, oldest first: status, method, dataset, degradation, seed, scans.

    Status: evaluated (metrics.json present), done (not evaluated yet), incomplete (no DONE: the run
    was interrupted), failed (a bench cell's FAILED.json), unreadable (result.json does not fit).
    ROOT/latest links the folder `albot1 run` wrote last.

    Examples:\n
      albot1 runs\n
      albot1 runs results/quick/runs --json \\
          | jq '.runs[] | select(.status == "failed")'
    """
    # The runs layer is imported by the command, not by this module: see albot1.cli.app.
    from albot1.runs.folder import LATEST, list_runs

    listing = list_runs(root)
    latest_link = root / LATEST
    latest = latest_link.resolve().name if latest_link.is_symlink() else None
    rows: list[dict[str, Any]] = []
    for item in listing:
        info = item.info
        rows.append(
            {
                "folder": str(item.path),
                "key": item.path.name,
                "status": item.status,
                "latest": item.path.name == latest,
                "modified": time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(item.modified)),
                "method": info.method if info else None,
                "preset": info.preset if info else None,
                "dataset": info.dataset if info else None,
                "degradation": info.degradation if info else None,
                "seed": info.seed if info else None,
                "scans": info.scans if info else None,
                "problem": item.problem,
            }
        )
    if as_json:
        typer.echo(json.dumps({"root": str(root), "runs": rows}))
        return
    if not rows:
        typer.echo(f"{root}: no run folders")
        return
    for row in rows:
        what = (
            f"{row['method']}:{row['preset']} on {row['dataset']} [{row['degradation']}, seed {row['seed']}], "
            f"{row['scans']} scans"
            if row["method"] is not None
            else (row["problem"] or "-")
        )
        mark = " <- latest" if row["latest"] else ""
        typer.echo(f"{row['modified']}  {row['key']}  {row['status']:<10} {what}{mark}")
    typer.echo(f"{len(rows)} run folders in {root}")
