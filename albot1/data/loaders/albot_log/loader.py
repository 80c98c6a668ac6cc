"""The robot's own log ("albot-log", version 1): what Albot1's Algorithm 4 consumes.

Per view the log holds the odometry pose and the scan as Cartesian points
with the robot at the origin facing +y (the thesis's frame: a beam at angle
``a``, counter-clockwise from forward, with range ``r`` hits
``x = -r sin a, y = r cos a``), listed left to right as the thesis orders
surfaces. It is a line-oriented UTF-8 text file (optionally ``.gz``) so it
can be read, diffed and written by hand; the full specification with an
example is in ``docs/formats.md``::

    ALBOT1-LOG 1
    UNITS length=m angle=rad time=s
    FRAME thesis
    NAME aces
    SENSOR <beams> <max_range> <angle_min> <angle_increment>
    VIEW <index> <t> <x> <y> <theta> <- | rx ry rtheta> <x_1> <y_1> ... <x_n> <y_n>

Every beam keeps its entry (``nan nan`` for no return) so that beam angles
and ranges survive a round trip: the range is ``hypot(x, y)`` and the angle
comes from the SENSOR line, never from the point. Numbers are written with
Python's shortest round-trip ``repr``, so poses, timestamps and angles come
back bit-identical and ranges to within 2 ulp.

A log must hold at least one VIEW: ``load`` reads up to the first one and
refuses a log without, naming the file, so an empty log never becomes an
empty run. The writer refuses what the reader refuses (see :mod:`.lines`),
an empty sequence included.
"""

from __future__ import annotations

import gzip
import itertools
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any, ClassVar

import numpy as np

from albot1.data.errors import DataError, ParseError, UnwritableError
from albot1.data.loaders.albot_log.lines import (
    FRAME,
    MAGIC,
    UNITS,
    VERSION,
    ViewParser,
    check_frame,
    mount_line,
    read_header,
    sensor_line,
    view_line,
)
from albot1.data.loaders.base import COMMON_OPTIONS, reference_keyword_problem, reference_presence_problem
from albot1.data.loaders.compressed import DamagedStream, iter_lines, read_head
from albot1.data.loaders.output import prepare_output, writing
from albot1.data.model import Frame, Sequence, SequenceMetadata, mount_problem
from albot1.geometry.types import FloatArray

__all__ = ["AlbotLogLoader", "AlbotLogWriter"]


def _create_text(path: Path) -> IO[str]:
    if path.suffix == ".gz":
        # Level 6: nearly the size of level 9 at a fraction of the time for this number-heavy text.
        return gzip.open(path, "xt", encoding="utf-8", compresslevel=6)
    return path.open("x", encoding="utf-8")


def _lines(path: Path) -> Iterator[tuple[int, str]]:
    """``(1-based line number, text)``; bad UTF-8 names its line, damaged gzip data the last complete line."""
    lineno = 0
    try:
        for lineno, raw in enumerate(iter_lines(path), start=1):
            try:
                text = raw.decode("utf-8")
            except UnicodeDecodeError as exc:
                raise ParseError(
                    path, f"not UTF-8 text ({exc.reason} at byte {exc.start} of the line)", line=lineno
                ) from exc
            yield lineno, text
    except DamagedStream as damage:
        if lineno == 0:
            raise ParseError(path, damage.describe(" before its first line could be decompressed")) from None
        raise ParseError(path, damage.describe(" after this line (the last complete one)"), line=lineno) from None


def _frames(path: Path) -> Iterator[Frame]:
    lines = _lines(path)
    _, pending = read_header(path, lines)
    parser = ViewParser(path)
    for lineno, text in itertools.chain(pending, lines):
        stripped = text.strip()
        if not stripped or stripped.startswith("#"):
            continue
        tokens = stripped.split()
        if tokens[0] == "VIEW":
            yield parser.view_line(lineno, tokens)
        elif tokens[0] in ("SENSOR", "SENSOR-ANGLES"):
            parser.sensor_line(lineno, tokens)
        else:
            raise ParseError(
                path, f"unknown record {tokens[0][:40]!r}; expected SENSOR, SENSOR-ANGLES or VIEW", line=lineno
            )


class AlbotLogLoader:
    """Reads ``.albotlog`` (and ``.albotlog.gz``) files; takes no options."""

    format_name: ClassVar[str] = "albot-log"
    suffixes: ClassVar[tuple[str, ...]] = (".albotlog",)

    def sniff(self, path: Path) -> bool:
        return path.is_file() and read_head(path, len(MAGIC)) == MAGIC.encode()

    def load(self, path: Path, **options: Any) -> Sequence:
        path = Path(path)
        keyword = reference_keyword_problem(options, "an albot log")
        if keyword is not None:
            raise DataError(f"{path}: {keyword}")
        unknown = sorted(k for k, v in options.items() if v is not None)
        if unknown:
            raise DataError(
                f"{path}: an albot log takes no loading options of its own, got {', '.join(unknown)}; "
                f"expected only the options of every source: {', '.join(COMMON_OPTIONS)}"
            )
        if not path.is_file():
            raise DataError(f"{path}: no such file")
        header, _ = read_header(path, _lines(path))
        if next(_frames(path), None) is None:  # reads up to the first VIEW only
            last = sum(1 for _ in _lines(path))
            raise ParseError(
                path,
                "the log holds no VIEW line, so no scans; expected at least one VIEW after a SENSOR line",
                line=last,
            )
        stem = path.name.removesuffix(".gz").removesuffix(".albotlog")
        metadata = SequenceMetadata(
            source=str(path),
            format=self.format_name,
            sensor_offset=header.mount,
            odometry_source="VIEW odometry poses",
            reference_source="VIEW reference poses (every view has one, or none does)",
        )
        return Sequence(header.name or stem, lambda: _frames(path), metadata)


class AlbotLogWriter:
    """Writes a Sequence as an albot log (gzip-compressed when the name ends in ``.gz``)."""

    format_name: ClassVar[str] = "albot-log"

    def write(self, sequence: Sequence, path: Path) -> None:
        path = prepare_output(path)
        try:
            with writing(path), _create_text(path) as fh:
                fh.write(f"{MAGIC} {VERSION}\n# written by albot1; format: docs/formats.md\n")
                if sequence.metadata.source:
                    fh.write(f"# source: {' '.join(sequence.metadata.source.split())}\n")
                fh.write(f"UNITS {UNITS}\nFRAME {FRAME}\nNAME {' '.join(sequence.name.split()) or 'unnamed'}\n")
                offset = tuple(float(v) for v in sequence.metadata.sensor_offset)
                if any(offset):  # the laser's mount: without it the scans would be read as taken at the robot's centre
                    problem = mount_problem((offset[0], offset[1], offset[2]))  # the reader's own rule
                    if problem is not None:
                        raise UnwritableError(problem)
                    fh.write(mount_line((offset[0], offset[1], offset[2])) + "\n")
                geometry: tuple[FloatArray, float] | None = None
                first: Frame | None = None
                for i, frame in enumerate(sequence.frames()):
                    if frame.index != i:
                        raise UnwritableError(f"frame {i} has index {frame.index}; expected consecutive indices from 0")
                    scan = frame.scan
                    check_frame(frame)
                    first = frame if first is None else first
                    gap = reference_presence_problem(first, frame, "an albot log", "its reader refuses the others")
                    if gap is not None:
                        raise UnwritableError(gap)
                    if geometry is None or not (
                        scan.max_range == geometry[1] and np.array_equal(scan.angles, geometry[0])
                    ):
                        fh.write(sensor_line(scan) + "\n")
                        geometry = (scan.angles, scan.max_range)
                    fh.write(view_line(frame) + "\n")
                if geometry is None:
                    raise UnwritableError("the sequence has no scans; the albot-log reader refuses a log without VIEW")
        except UnwritableError as exc:
            path.unlink(missing_ok=True)
            raise UnwritableError(f"{path}: {exc}") from None
        except BaseException:
            path.unlink(missing_ok=True)
            raise
