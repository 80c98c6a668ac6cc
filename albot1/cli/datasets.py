"""``albot1 datasets list | fetch NAME | info NAME|PATH``: the dataset registry from the shell.

Thin: every fact comes from :mod:`albot1.data.catalog` and
:meth:`albot1.data.model.Sequence.summary`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated, Any

import typer

from albot1.cli.columns import aligned
from albot1.cli.progress import with_progress
from albot1.settings import get_settings

app = typer.Typer(
    help="Public datasets: what is registered, what is here, download, inspect.",
    no_args_is_help=True,
)

DataDir = Annotated[Path | None, typer.Option(help="dataset folder (default: $ALBOT1_DATA_DIR)")]


def _synthetic_worlds() -> dict[str, str]:
    """Embedded synthetic worlds (name -> description)."""
    # The data layer is imported by the commands, not by this module: see albot1.cli.app.
    from albot1.data.synthetic import worlds

    return {name: getattr(spec, "description", "") for name, spec in worlds.WORLDS.items()}


@app.command("list")
def list_(
    data_dir: DataDir = None, as_json: Annotated[bool, typer.Option("--json", help="print one JSON object")] = False
) -> None:
    """Each registered dataset with its local availability, then the embedded synthetic worlds.

    Examples:\n
      albot1 datasets list\n
      ALBOT1_DATA_DIR=/data/albot1 albot1 datasets list --json
    """
    from albot1.data import catalog

    settings = get_settings(data_dir=data_dir)
    rows: list[dict[str, Any]] = []
    for name in catalog.names():
        manifest = catalog.get(name)
        found = catalog.find_file(manifest.log, settings)
        available = catalog.is_available(name, settings)
        rows.append(
            {
                "name": name,
                "available": available,
                "checksum_problem": catalog.copy_problem(name, settings) if available else None,
                "path": str(found) if found else None,
                "local_only": manifest.local_only,
                "description": manifest.description,
            }
        )
    worlds = _synthetic_worlds()
    for name, description in sorted(worlds.items()):
        rows.append(
            {
                "name": name,
                "available": True,
                "path": None,
                "local_only": False,
                "synthetic": True,
                "description": description,
            }
        )
    if as_json:
        typer.echo(json.dumps({"datasets": rows, "search_roots": [str(r) for r in settings.search_roots()]}))
        return
    lines: list[tuple[str, str, str]] = []
    for row in rows:
        state = (
            "synthetic"
            if row.get("synthetic")
            else ("local" if row["available"] else ("missing (local only)" if row["local_only"] else "missing (fetch)"))
        )
        if row.get("checksum_problem"):
            state = "wrong copy (sha256)"  # `albot1 datasets info NAME` says which file and how to fix it
        lines.append((row["name"], state, _first_sentence(row["description"])))
    for line in aligned(lines):
        typer.echo(line)
    typer.echo(f"searched: {settings.roots_text()}")


def _first_sentence(text: str, width: int = 80) -> str:
    head = text.split(": ", 1)[0]
    return head if len(head) <= width else head[: width - 3] + "..."


@app.command("fetch")
def fetch(
    name: Annotated[str, typer.Argument(help="a dataset name (see `albot1 datasets list`)")],
    data_dir: DataDir = None,
    base_url: Annotated[
        str | None, typer.Option(help="download from BASE_URL/<path> instead of the manifest URLs (a mirror)")
    ] = None,
) -> None:
    """Download NAME's files into the cache (sha256-verified, atomic); no-op if a verified copy exists.

    Examples:\n
      albot1 datasets fetch intel\n
      ALBOT1_CACHE_DIR=/data/cache albot1 datasets fetch aces
    """
    from albot1.data import catalog

    settings = get_settings(data_dir=data_dir)
    path = catalog.fetch(name, settings, base_url=base_url)
    typer.echo(f"{name}: {path}")
    problem = catalog.copy_problem(name, settings)  # a wrong copy earlier in the search roots would still be read
    if problem is not None:
        typer.echo(f"albot1: error: fetched, but the dataset cannot be used yet: {problem}", err=True)
        raise typer.Exit(1)


def geometry_lines(summary: dict[str, Any]) -> list[str]:
    """Field of view, beam spacing (per distinct layout) and the laser's mount, as ``datasets info`` prints them."""
    lines = []
    layouts = summary.get("scan_geometry", [])
    for layout in layouts[:5]:
        share = f" ({layout['scans']} of {summary['scans']} scans)" if len(layouts) > 1 else ""
        lines.append(
            f"field of view: {layout['first_deg']:+.2f}..{layout['last_deg']:+.2f} deg "
            f"({layout['last_deg'] - layout['first_deg']:.2f} deg), {layout['beams']} beams "
            f"every {layout['spacing_deg']:.4g} deg{share}"
        )
    if len(layouts) > 5:
        lines.append(f"... and {len(layouts) - 5} more beam layouts (see --json)")
    offset = summary.get("sensor_offset", [0.0, 0.0, 0.0])
    source = summary.get("sensor_offset_source") or ""
    lines.append(
        f"laser mount (x, y, yaw): ({offset[0]:.4g} m, {offset[1]:.4g} m, {math.degrees(offset[2]):.4g} deg)"
        + (f"; {source}" if source else "")
    )
    return lines


@app.command("info")
def info(
    ref: Annotated[
        str,
        typer.Argument(help="NAME, NAME[:N], NAME?key=value (see `albot1 --help`), a synthetic world or a log path"),
    ],
    as_json: Annotated[bool, typer.Option("--json", help="print Sequence.summary() as one JSON object")] = False,
    scan_topic: Annotated[str | None, typer.Option(help="bag: the sensor_msgs/LaserScan topic")] = None,
    odom_topic: Annotated[str | None, typer.Option(help="bag: the nav_msgs/Odometry topic")] = None,
    reference_topic: Annotated[str | None, typer.Option(help="bag: the reference-pose topic")] = None,
    data_dir: DataDir = None,
) -> None:
    """Scans, beams, duration, odometry path length, reference poses and relations of a dataset.

    Decodes the whole log once. Examples:\n
      albot1 datasets info intel --json\n
      albot1 datasets info recording.bag \\
          --scan-topic /base_scan --odom-topic /odom_raw
    """
    from albot1.data.open import open_sequence

    options = {
        key: value
        for key, value in (("scan_topic", scan_topic), ("odom_topic", odom_topic), ("reference_topic", reference_topic))
        if value is not None
    }
    sequence = open_sequence(ref, settings=get_settings(data_dir=data_dir), **options)
    summary = with_progress(sequence, f"reading {ref}").summary()
    summary["data_sha256"] = dict(sequence.metadata.checksums)  # the files' content the numbers describe
    if as_json:
        typer.echo(json.dumps(summary))
        return
    beams = summary["beams"]
    typer.echo(
        f"{summary['name']}: {summary['scans']} scans x {beams} beams, {summary['duration_s']:.1f} s, "
        f"odometry path {summary['odometry_path_m']:.1f} m"
    )
    typer.echo(
        f"  reference poses: {'yes' if summary['has_reference'] else 'no'}"
        f"{' (' + summary['reference_source'] + ')' if summary.get('reference_source') else ''}; "
        f"relations: {summary['relations']}"
    )
    typer.echo(f"  odometry: {summary.get('odometry_source', '')}")
    for line in geometry_lines(summary):
        typer.echo(f"  {line}")
    if summary.get("skipped_messages"):
        typer.echo(f"  skipped: {summary['skipped_messages']}")
    typer.echo(f"  source: {summary.get('source', '')} ({summary.get('format', '')})")
    checksums = summary["data_sha256"]
    typer.echo(
        "  data: " + (", ".join(f"{n} sha256 {sha}" for n, sha in checksums.items()) or "generated (no data file)")
    )


@app.command("reference")
def reference(
    ref: Annotated[
        str,
        typer.Argument(help="NAME, NAME[:N], NAME?key=value (see `albot1 --help`), a synthetic world or a log path"),
    ],
    output: Annotated[Path, typer.Argument(metavar="OUT", help="the TUM file to create (t x y z qx qy qz qw)")],
    retime: Annotated[
        bool,
        typer.Option(help="move stamps that repeat or go backwards as `albot1 convert --retime` does"),
    ] = False,
    data_dir: DataDir = None,
) -> None:
    """Write the reference pose of every scan as a TUM trajectory file (OUT must not exist).

    The reference trajectory of a log, for `?reference=FILE`, `albot1 evaluate
    --reference` or evo. Examples:\n
      albot1 datasets reference aces-corrected gt.tum\n
      albot1 datasets reference 'synthetic-office-loop[:200]' loop-gt.tum
    """
    from albot1.data.open import open_sequence
    from albot1.data.reference_tum import write_reference_tum

    sequence = open_sequence(ref, settings=get_settings(data_dir=data_dir))
    done = write_reference_tum(with_progress(sequence, f"reading {ref}"), output, retime=retime)
    shifted = f"; {done.retimed} timestamps shifted by --retime" if done.retimed else ""
    typer.echo(f"wrote {done.poses} reference poses from {done.source} to {done.output} (tum){shifted}")
