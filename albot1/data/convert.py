"""Conversion between the formats of :data:`~albot1.data.loaders.registry.FORMATS`.

A conversion is "load as a Sequence, write with the target format's
writer": the data model is the only interchange, so every pair of formats
works and round trips are testable format by format. The target format is
named, or guessed from the output name's suffix.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from albot1.data.errors import UnknownFormatError
from albot1.data.loaders.output import check_output
from albot1.data.loaders.registry import writer_for
from albot1.data.model import Frame, Sequence
from albot1.data.open import open_sequence
from albot1.data.retime import RETIME_STEP_S, next_stamp

if TYPE_CHECKING:
    from albot1.settings import Settings

#: Output name endings -> format (longest ending first wins). ROS2 bags are
#: folders; naming them ``*.db3`` / ``*.mcap`` picks the storage.
SUFFIX_FORMATS: tuple[tuple[str, str], ...] = (
    (".albotlog.gz", "albot-log"),
    (".albotlog", "albot-log"),
    (".bag", "ros1"),
    (".db3", "ros2-sqlite3"),
    (".mcap", "ros2-mcap"),
    (".clf.gz", "carmen"),
    (".clf.bz2", "carmen"),
    (".log.gz", "carmen"),
    (".log.bz2", "carmen"),
    (".clf", "carmen"),
    (".log", "carmen"),
    (".rawlog.gz", "rawlog"),
    (".rawlog", "rawlog"),
)


def guess_format(path: str | Path) -> str:
    """The output format implied by ``path``'s name, or UnknownFormatError listing the endings."""
    name = Path(path).name.lower()
    for suffix, format_name in SUFFIX_FORMATS:
        if name.endswith(suffix):
            return format_name
    endings = ", ".join(f"{s} ({f})" for s, f in SUFFIX_FORMATS)
    raise UnknownFormatError(f"{path}: cannot tell the output format from its name; use --format or one of: {endings}")


@dataclass(frozen=True)
class Conversion:
    """What :func:`convert` did; ``retimed`` counts scans whose timestamp was shifted.

    ``not_carried`` names what the source holds beyond its frames that the output cannot hold
    (:func:`not_carried`), so the caller can say so instead of dropping it silently.
    """

    source: str
    output: Path
    format_name: str
    scans: int
    retimed: int = 0
    not_carried: tuple[str, ...] = ()


#: ``metadata.extra`` keys of a synthetic world's floor plan (:func:`albot1.data.synthetic.generate.world_metadata`),
#: the truth the places metrics score against, with the noun each count is shown with.
_FLOOR_PLAN = (("spaces", "rooms"), ("doorways", "doorways"), ("doorway_crossings", "doorway crossings"))


def not_carried(sequence: Sequence) -> tuple[str, ...]:
    """What of ``sequence`` beyond its frames no writer stores, e.g. ``("1279 relations", "licence and citation")``.

    Every output format holds scans, odometry, reference poses and the sensor
    mounting, nothing else: ground-truth relations (scored by the relations
    metric), a synthetic world's rooms, doorways and crossings (scored by the
    places metrics) and the data's licence and citation are lost in the
    conversion. A relations file can be attached again (``OUT?relations=FILE``).
    """
    out = []
    if sequence.relations is not None and len(sequence.relations):
        out.append(f"{len(sequence.relations)} relations")
    extra = sequence.metadata.extra
    plan = [f"{len(extra[key])} {noun}" for key, noun in _FLOOR_PLAN if isinstance(extra.get(key), list) and extra[key]]
    walls = extra.get("wall_segments")
    if isinstance(walls, int) and walls:
        plan.insert(0, f"{walls} wall segments")
    if plan:
        out.append(f"the floor plan ({', '.join(plan)})")
    meta = sequence.metadata
    told = [what for what, text in (("licence", meta.license), ("citation", meta.citation)) if text]
    if told:
        out.append(" and ".join(told))
    return tuple(out)


def retimed(frames: Iterator[Frame], shifted: list[int]) -> Iterator[Frame]:
    """Frames whose timestamp is at least ``RETIME_STEP_S`` after the previous one's.

    Only stamps that repeat or go backwards move, and only as far as needed
    (:func:`albot1.data.retime.next_stamp`, the rule the MRPT rawlog's stamp
    fill shares); ``shifted[0]`` counts them so the caller can report it.
    """
    previous: float | None = None
    for frame in frames:
        t = next_stamp(frame.scan.timestamp, previous, step=RETIME_STEP_S, resolution=RETIME_STEP_S)
        if t != frame.scan.timestamp and not math.isnan(t):  # a NaN stamp is never moved (as before)
            shifted[0] += 1
            frame = replace(frame, scan=replace(frame.scan, timestamp=t))
        previous = t
        yield frame


def convert(
    src: str | Path | Sequence,
    dst: str | Path,
    format_name: str | None = None,
    *,
    source_format: str | None = None,
    settings: Settings | None = None,
    retime: bool = False,
    **load_options: Any,
) -> Conversion:
    """Write ``src`` (a Sequence, a dataset name or any loadable path) to ``dst`` in ``format_name``.

    ``source_format`` overrides sniffing the input; ``settings`` locate
    dataset names; ``load_options`` (e.g. ``scan_topic``) go to the
    source's loader, dropping those that are None so CLI defaults pass
    through. The output must not exist (writers never overwrite); an output
    that cannot be created (a parent that is a file, a folder that is not
    writable, a read-only file system) is refused before the input is read
    (:mod:`albot1.data.loaders.output`); missing parent folders are created.

    ``retime`` shifts scans whose timestamp repeats or goes backwards to
    ``RETIME_STEP_S`` after the previous scan. Bags need strictly increasing
    stamps and several public CARMEN logs repeat or jitter theirs; since
    this changes data it is never done unless asked for, and the count is
    returned.
    """
    target = format_name or guess_format(dst)
    writer = writer_for(target)
    check_output(dst)  # one policy for every writer, checked before the (maybe long) load
    if isinstance(src, Sequence):
        sequence = src
    else:
        options = {k: v for k, v in load_options.items() if v is not None}
        sequence = open_sequence(src, settings=settings, format_name=source_format, **options)
    count, shifted = [0], [0]

    def counted(frames: Iterator[Frame]) -> Iterator[Frame]:
        count[0] = shifted[0] = 0  # per pass: a writer may read the sequence more than once
        for frame in retimed(frames, shifted) if retime else frames:
            count[0] += 1
            yield frame

    writer.write(sequence.with_frames(counted), Path(dst))
    return Conversion(
        source=sequence.metadata.source or sequence.name,
        output=Path(dst),
        format_name=target,
        scans=count[0],
        retimed=shifted[0],
        not_carried=not_carried(sequence),
    )
