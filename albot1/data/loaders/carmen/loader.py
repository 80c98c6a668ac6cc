"""CARMEN logs (``.clf``/``.log``, plain, gzip or bzip2) as streamed Sequences.

Poses: ``Frame.odometry`` and ``Frame.reference`` are *robot* poses (the
robot centre), as the odometry fields of FLASER/ROBOTLASER1 lines are; the
laser's pose on the robot is ``metadata.sensor_offset`` (PARAM
``robot_frontlaser_offset``, or the laser-vs-robot pose of the first
ROBOTLASER1 line).

Odometry sources (option ``odometry``):

``"laser-pose"``
    the odometry fields written into every laser line by the CARMEN logger
    (FLASER ``odom_x odom_y odom_theta``, ROBOTLASER1 ``robot_x robot_y
    robot_theta``).
``"odom"``
    SE(2) interpolation of the ODOM lines at the scan's ipc timestamp. ODOM
    stamps may jitter backwards by up to ``time_tolerance`` (the Intel log
    does, by up to 0.9 s); they are sorted, and a scan is only emitted once
    an ODOM stamp later than ``scan time + time_tolerance`` has been read, so
    the result does not depend on chunking. Scans before the first (after
    the last) ODOM line take the first (last) ODOM pose, within
    ``time_tolerance`` of it; farther out they are refused (:mod:`.interp`).
``"odom-segments"``
    the GMapping-corrected logs of ``radish-corrected/``: after every FLASER
    the ODOM stream is *re-anchored* at the scan's corrected pose and then
    integrates the raw odometry until the next scan. The odometry of scan k
    is ``odometry[k-1] * between(anchor[k-1], last ODOM before scan k)``,
    starting at the first scan's logged pose; each anchor is checked to
    repeat the preceding scan's pose (see docs/datasets.md for the check on
    all 13 logs).

Reference sources (option ``reference``): ``"none"``; ``"laser-pose"`` (the
FLASER/RLASER ``x y theta`` / ROBOTLASER1 ``laser_x laser_y laser_theta``
fields, the corrected pose in the SLAM-corrected logs: in CARMEN these are the
*laser's* pose, so each is composed with the inverse mount to give the robot's,
:mod:`.poses`); ``"truepos"`` (TRUEPOS lines interpolated at scan
time); ``"auto"`` (TRUEPOS when the first chunk of the log has TRUEPOS lines,
else none).

ROBOTLASER1 lines carry the mount on every line (laser pose vs robot pose).
Where the log states it (PARAM ``robot_frontlaser_offset`` and its side and
angular parts, what CARMEN's robot module composed the laser poses with), the
PARAM mount is used, and a line whose laser pose is not the robot pose composed
with it is a corrected one (``vasco`` corrects the laser pose only), read as
such. Without those PARAMs the loader applies the first line's mount to every
scan and refuses a later line whose own mount differs by more than
:data:`.poses.MOUNT_TOLERANCE`: nothing else could tell a corrected line from
a second laser's.

ODOM and TRUEPOS lines are only decoded when a pose source uses them.

Streaming: the log is decoded chunk by chunk (2 MiB of text); only scans
waiting for a later ODOM/TRUEPOS line and the ODOM lines that can still
bracket them are buffered. Message types other than the chosen laser, ODOM,
TRUEPOS and PARAM (SYNC, NEFF, NMEA-GGA, a rear laser, ...) are skipped
by design, never silently: the kinds seen at the start of the log are listed in
``metadata.extra["ignored_messages"]``, and counted with their first lines in
``metadata.extra["skipped_messages"]``, which ``albot1 datasets info`` prints
and every load logs as a warning (unless only kinds without sensor data,
:data:`.probe.QUIET_SKIPS`, are skipped).

Old and new front-laser messages (FLASER, ROBOTLASER1, RAWLASER1) in one
log are refused unless the ``laser`` option names the kind to read: they may
be the same scans written twice (CARMEN's logger writes RAWLASER1 beside
ROBOTLASER1) or two recordings run together, and the loader cannot tell
which, so it neither merges them nor drops one kind without a word. The
error names the count and first line of each kind.

Modules: this one (:class:`CarmenLoader`: sniffing, the sequence and its
metadata), :mod:`.options` (every loader option, validated), :mod:`.probe`
(the log's head, the mixed-laser refusal), :mod:`.frames` (chunks to
frames), :mod:`.poses` (odometry and reference sources, the corrected logs'
anchors), and below them :mod:`.source` (chunked, decompressed reading),
:mod:`.parse` (vectorised message parsing), :mod:`.geometry` (beam
geometry), :mod:`.interp` (pose look-ahead buffers) and :mod:`.checks`.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any, ClassVar

from albot1.data.errors import DataError, ParseError
from albot1.data.loaders.carmen import geometry as geom
from albot1.data.loaders.carmen.frames import FrameStream
from albot1.data.loaders.carmen.options import describe_odometry, describe_reference, parse_options
from albot1.data.loaders.carmen.parse import LASER_MESSAGES, REAR_LASERS, ROBOT_LASERS, UNREAD_LASERS
from albot1.data.loaders.carmen.probe import noteworthy_skips, probe, refuse_mixed, skipped_note
from albot1.data.loaders.carmen.source import read_head
from albot1.data.model import Sequence, SequenceMetadata
from albot1.data.relations import read_relations
from albot1.geometry import se2

log = logging.getLogger(__name__)

#: A file is taken for a CARMEN log if a line of its first 64 KiB starts with one of these messages
#: (or the "# CARMEN" comment the logger writes first).
_SNIFF_NAMES = frozenset(
    name.encode() for name in LASER_MESSAGES + UNREAD_LASERS + ("ODOM", "PARAM", "TRUEPOS", "SYNC")
)
_SNIFF_BYTES = 1 << 16


class CarmenLoader:
    """Reads CARMEN logs; options as in :class:`~albot1.data.loaders.carmen.options.CarmenOptions`, plus
    ``relations`` (a relations file path) and ``license``/``citation`` (copied into the metadata; the catalog
    passes the manifest's), all parsed by :func:`~albot1.data.loaders.carmen.options.parse_options`."""

    format_name: ClassVar[str] = "carmen"
    suffixes: ClassVar[tuple[str, ...]] = (".clf", ".log", ".clf.gz", ".log.gz", ".clf.bz2", ".log.bz2")

    def sniff(self, path: Path) -> bool:
        if path.is_dir():
            return False
        for line in read_head(path, _SNIFF_BYTES).split(b"\n"):
            words = line.split(None, 1)
            if words and (words[0] in _SNIFF_NAMES or line.lstrip().startswith(b"# CARMEN")):
                return True
        return False

    def load(self, path: Path, **options: Any) -> Sequence:
        path = Path(path)
        given = parse_options(path, options)
        opts = given.carmen
        if not path.is_file():
            raise DataError(f"{path}: no such file")
        head = probe(path, opts.laser)
        laser = opts.laser or head.first_laser
        if laser is None:
            others = sorted(name for name in head.ignored if name in LASER_MESSAGES)
            unread = sorted(name for name in head.ignored if name in UNREAD_LASERS)
            hint = (
                f"; the log has {', '.join(f'{head.ignored[n]} {n}' for n in others)} lines: read them with "
                f"the loader option laser={others[0]} (e.g. 'FILE?laser={others[0]}')"
                if others
                else ""
            )
            if unread:
                hint += (
                    f"; it has {', '.join(f'{head.ignored[n]} {n}' for n in unread)} lines, a laser this loader "
                    f"does not read (laser= takes {', '.join(LASER_MESSAGES)})"
                )
            raise ParseError(
                path,
                f"no front-laser scans in the first 2 MiB of the log; expected FLASER, ROBOTLASER1 or "
                f"RAWLASER1 lines{hint}",
                line=1,
            )
        if opts.laser is None:
            refuse_mixed(path, laser, head)
        if opts.odometry == "laser-pose" and laser.startswith("RAWLASER"):
            raise DataError(f"{path}: {laser} lines carry no pose; use odometry='odom' (ODOM lines)")
        if opts.reference == "laser-pose" and laser.startswith("RAWLASER"):
            raise DataError(f"{path}: {laser} lines carry no pose; reference='laser-pose' is impossible")
        reference = opts.reference
        if reference == "auto":
            reference = "truepos" if len(head.truepos.lines) else "none"
        # The values in effect at the first scan (a PARAM block may restate a name, the last value counts), then
        # those first stated after it; a mount PARAM changing after the first scan is refused (frames.py).
        first_scan = int(head.lasers[0].lines[0]) if head.lasers else None
        before = {name: value for at, name, value in head.params if first_scan is None or at < first_scan}
        params = dict(before)
        for _, name, value in head.params:
            params.setdefault(name, value)
        rear = laser in REAR_LASERS
        offset = geom.sensor_offset(params, rear=rear)
        lines_state_mount = laser in ROBOT_LASERS and not geom.states_mount(params, rear=rear)
        if lines_state_mount and head.lasers:
            first = head.lasers[0]
            assert first.robot is not None and first.sensor is not None
            rel = se2.between(first.robot[0], first.sensor[0])
            offset = (float(rel[0]), float(rel[1]), float(rel[2]))
        metadata = SequenceMetadata(
            source=str(path),
            format="carmen",
            license=given.license,
            citation=given.citation,
            sensor_offset=offset,
            odometry_source=describe_odometry(opts.odometry, laser),
            reference_source=describe_reference(reference, laser),
            extra={
                "laser_message": laser,
                "max_range_option": opts.max_range,
                "no_return_rule": f"r >= max_range - {geom.NO_RETURN_MARGIN} m or r == 0",
                "time_tolerance_s": opts.time_tolerance,
                "ignored_messages": sorted(head.ignored),
                "skipped_messages": skipped_note(laser, head),
            },
        )
        if noteworthy_skips(head):
            log.warning("%s: skipped: %s", path, metadata.extra["skipped_messages"])
        if head.lasers:
            first = head.lasers[0]
            line = int(first.lines[0])
            start = None if first.start is None else float(first.start[0])
            step = None if first.step is None else float(first.step[0])
            for note in geom.first_line_notes(f"{path}:{line}", laser, first.beams, start, step, before):
                log.warning(note)
        relations = (
            read_relations(given.relations, repeats=given.relations_repeats) if given.relations is not None else None
        )
        name = opts.name or _stem(path)
        stream = FrameStream(path, opts, laser, reference, offset, check_mount=lines_state_mount)
        return Sequence(name, stream.frames, metadata, relations)


def _stem(path: Path) -> str:
    name = path.name
    for suffix in (".gz", ".bz2", ".clf", ".log"):
        if name.endswith(suffix):
            name = name[: -len(suffix)]
    return name or path.name
