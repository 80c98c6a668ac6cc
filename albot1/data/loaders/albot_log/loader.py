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
"""

from __future__ import annotations

import gzip
import itertools
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any, ClassVar

import numpy as np

from albot1.data.errors import DataError, ParseError
from albot1.data.loaders.albot_log.lines import (
    FRAME,
    MAGIC,
    UNITS,
    VERSION,
    ViewParser,
    check_ranges,
    read_header,
    sensor_line,
    view_line,
)
from albot1.data.model import FloatArray, Frame, Sequence, SequenceMetadata

__all__ = ["AlbotLogLoader", "AlbotLogWriter"]


def _create_text(path: Path) -> IO[str]:
    if path.suffix == ".gz":
        # Level 6: nearly the size of level 9 at a fraction of the time for this number-heavy text.
        return gzip.open(path, "xt", encoding="utf-8", compresslevel=6)
    return path.open("x", encoding="utf-8")


def _lines(path: Path) -> Iterator[tuple[int, str]]:
    """``(1-based line number, text)``; bad UTF-8 names its line, bad gzip the last good line."""
    lineno = 0
    try:
        with gzip.open(path, "rb") if path.suffix == ".gz" else path.open("rb") as fh:
            for lineno, raw in enumerate(fh, start=1):
                try:
                    text = raw.decode("utf-8")
                except UnicodeDecodeError as exc:
                    raise ParseError(
                        path, f"not UTF-8 text ({exc.reason} at byte {exc.start} of the line)", line=lineno
                    ) from exc
                yield lineno, text
    except (EOFError, zlib.error, gzip.BadGzipFile) as exc:
        raise ParseError(
            path, f"cannot decompress past line {lineno} (truncated or corrupt gzip file?): {exc}", line=lineno + 1
        ) from exc


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
        if not path.is_file():
            return False
        try:
            with gzip.open(path, "rb") if path.suffix == ".gz" else path.open("rb") as fh:
                return fh.read(len(MAGIC)) == MAGIC.encode()
        except (OSError, EOFError, zlib.error):
            return False

    def load(self, path: Path, **options: Any) -> Sequence:
        path = Path(path)
        unknown = sorted(k for k, v in options.items() if v is not None)
        if unknown:
            raise DataError(f"{path}: an albot log takes no loading options, got {', '.join(unknown)}")
        if not path.is_file():
            raise DataError(f"{path}: no such file")
        name, _ = read_header(path, _lines(path))
        stem = path.name.removesuffix(".gz").removesuffix(".albotlog")
        metadata = SequenceMetadata(
            source=str(path),
            format=self.format_name,
            odometry_source="VIEW odometry poses",
            reference_source="VIEW reference poses (where a view has one)",
        )
        return Sequence(name or stem, lambda: _frames(path), metadata)


class AlbotLogWriter:
    """Writes a Sequence as an albot log (gzip-compressed when the name ends in ``.gz``)."""

    format_name: ClassVar[str] = "albot-log"

    def write(self, sequence: Sequence, path: Path) -> None:
        path = Path(path)
        if path.exists():
            raise DataError(f"{path} exists already; remove it or choose another output path")
        try:
            with _create_text(path) as fh:
                fh.write(f"{MAGIC} {VERSION}\n# written by albot1; format: docs/formats.md\n")
                if sequence.metadata.source:
                    fh.write(f"# source: {' '.join(sequence.metadata.source.split())}\n")
                fh.write(f"UNITS {UNITS}\nFRAME {FRAME}\nNAME {' '.join(sequence.name.split()) or 'unnamed'}\n")
                geometry: tuple[FloatArray, float] | None = None
                for i, frame in enumerate(sequence.frames()):
                    if frame.index != i:
                        raise DataError(f"frame {i} has index {frame.index}; expected consecutive indices from 0")
                    scan = frame.scan
                    check_ranges(frame)
                    if geometry is None or not (
                        scan.max_range == geometry[1] and np.array_equal(scan.angles, geometry[0])
                    ):
                        fh.write(sensor_line(scan) + "\n")
                        geometry = (scan.angles, scan.max_range)
                    fh.write(view_line(frame) + "\n")
        except BaseException:
            path.unlink(missing_ok=True)
            raise
