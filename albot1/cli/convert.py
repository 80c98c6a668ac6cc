"""``albot1 convert IN OUT``: any loadable log or dataset name -> another format."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from albot1.cli.progress import with_progress
from albot1.settings import get_settings

#: The formats each side takes, spelled out here because this module may not import the data layer (it is
#: heavy; see albot1.cli.app); a unit test keeps them equal to albot1.data.loaders.registry.
READ_FORMATS = ("carmen", "ros1", "ros2-sqlite3", "ros2-mcap", "albot-log")
WRITE_FORMATS = (*READ_FORMATS, "rawlog")
FORMAT_HELP = f"{' | '.join(WRITE_FORMATS)} (default: from OUT's name; rawlog is write-only, for MRPT's applications)"
FROM_HELP = f"IN's format, when sniffing is not enough: {' | '.join(READ_FORMATS)}"


def register(app: typer.Typer) -> None:
    app.command("convert")(convert)


def convert(
    source: Annotated[
        str,
        typer.Argument(metavar="IN", help="NAME, NAME[:N], NAME?key=value (see `albot1 --help`) or a log path"),
    ],
    output: Annotated[Path, typer.Argument(metavar="OUT", help="the file (or ROS2 bag folder) to create")],
    format_name: Annotated[str | None, typer.Option("--format", help=FORMAT_HELP)] = None,
    source_format: Annotated[str | None, typer.Option("--from", help=FROM_HELP)] = None,
    scan_topic: Annotated[str | None, typer.Option(help="bag input: the LaserScan topic")] = None,
    odom_topic: Annotated[str | None, typer.Option(help="bag input: the Odometry topic, or /tf")] = None,
    reference_topic: Annotated[str | None, typer.Option(help="bag input: a ground-truth Odometry topic")] = None,
    odom_frame: Annotated[str | None, typer.Option(help="bag input with /tf: parent frame (default odom)")] = None,
    base_frame: Annotated[str | None, typer.Option(help="bag input with /tf: robot frame")] = None,
    outside_odometry: Annotated[
        str | None, typer.Option(help="bag input: scans outside the odometry time span -> error (default) | drop")
    ] = None,
    retime: Annotated[
        bool,
        typer.Option(
            help="shift scans whose timestamp repeats or goes backwards to 1 us after the previous one "
            "(bags need strictly increasing stamps)"
        ),
    ] = False,
    limit: Annotated[int | None, typer.Option(min=1, help="convert only the first N scans")] = None,
    data_dir: Annotated[Path | None, typer.Option(help="dataset folder (default: $ALBOT1_DATA_DIR)")] = None,
) -> None:
    """Convert IN to OUT (scans, odometry and reference poses; OUT must not exist).

    OUT's name picks the format unless --format is given: .bag (ROS1),
    .db3 / .mcap (ROS2 bag folder), .albotlog[.gz] (the robot's own log),
    .clf / .log [.gz|.bz2] (CARMEN), .rawlog[.gz] (MRPT; written for
    MRPT's applications, never read back).

    Examples:\n
      albot1 convert aces aces.bag\n
      albot1 convert radish/aces.clf.bz2 aces.mcap\n
      albot1 convert run1/ aces.albotlog \\
          --scan-topic /base_scan --odom-topic /odom_raw
    """
    # The data layer is imported by the command, not by this module: see albot1.cli.app.
    from albot1.data.convert import convert as run_conversion
    from albot1.data.loaders.output import check_output
    from albot1.data.open import open_sequence
    from albot1.data.transforms import head

    options = {
        "scan_topic": scan_topic,
        "odom_topic": odom_topic,
        "reference_topic": reference_topic,
        "odom_frame": odom_frame,
        "base_frame": base_frame,
        "outside_odometry": outside_odometry,
    }
    settings = get_settings(data_dir=data_dir)
    check_output(output)  # refused before the (maybe long) load, as for every writer
    sequence = open_sequence(
        source, settings=settings, format_name=source_format, **{k: v for k, v in options.items() if v is not None}
    )
    if limit is not None:
        sequence = head(sequence, limit)
    done = run_conversion(with_progress(sequence, f"converting {source}"), output, format_name, retime=retime)
    shifted = f"; {done.retimed} timestamps shifted by --retime" if done.retimed else ""
    typer.echo(f"wrote {done.scans} scans from {done.source} to {done.output} ({done.format_name}){shifted}")
    if done.not_carried:  # ground truth no format holds: said, never dropped silently
        lost = ", ".join(done.not_carried)
        typer.echo(f"note: not carried over ({done.format_name} cannot hold it): {lost}", err=True)
