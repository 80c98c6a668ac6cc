"""What the head of a CARMEN log says before any scan is decoded, and the refusal of mixed laser kinds.

:func:`probe` reads the log until its first scan (at most 2 MiB, in small
reads so it stays cheap on compressed logs): which front laser it holds, its
PARAM values, whether it has TRUEPOS lines, and the message names the loader
will skip (:func:`skipped_note`: the sentence the loader logs and ``datasets
info`` prints). :func:`refuse_mixed` turns front-laser messages of two kinds
(FLASER, ROBOTLASER1, RAWLASER1) into one clear ParseError, counting each
kind over the whole log only on that error path.
"""

from __future__ import annotations

from contextlib import closing
from pathlib import Path

from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.parse import (
    FRONT_LASERS,
    LASER_MESSAGES,
    ParsedChunk,
    probe_chunk,
    split_messages,
)
from albot1.data.loaders.carmen.source import CHUNK_BYTES, iter_line_chunks

PROBE_BYTES = 1 << 18
PROBE_LIMIT = CHUNK_BYTES
#: Skipped message kinds that hold no sensor data, so skipping them is not worth a warning at every load
#: (``datasets info`` still lists them): GMapping's effective particle count, after every scan of the
#: corrected logs (``radish-corrected/``).
QUIET_SKIPS = frozenset(("NEFF",))


def probe(path: Path, laser: str | None) -> ParsedChunk:
    """Read the head of the log until the first scan (at most 2 MiB): laser type, PARAM values,
    TRUEPOS presence, skipped message names. ``laser`` is the kind chosen by the loader option, if any."""
    merged = ParsedChunk()
    seen = lines = 0
    with closing(iter_line_chunks(path, chunk_bytes=PROBE_BYTES, parallel_bz2=False)) as chunks:
        for chunk in chunks:
            part = probe_chunk(path, chunk.first_line, chunk.lines, laser)
            merged.params.extend(part.params)
            merged.ignored.update(part.ignored)
            for name, line in part.ignored_first.items():
                merged.ignored_first.setdefault(name, line)
            merged.message_lines += part.message_lines
            lines = chunk.first_line + len(chunk.lines) - 1
            if not len(merged.truepos.lines):
                merged.truepos = part.truepos
            seen += sum(len(line) + 1 for line in chunk.lines)
            if part.first_laser is not None or seen >= PROBE_LIMIT:
                merged.first_laser, merged.lasers = part.first_laser, part.lasers
                merged.last_line = lines
                return merged
    if seen == 0:
        raise ParseError(path, "the file is empty; expected a CARMEN log (one message per line)")
    if merged.message_lines == 0:
        raise ParseError(
            path, f"the log holds only comments and blank lines ({lines} lines); expected CARMEN messages", line=lines
        )
    merged.last_line = lines
    return merged


def skipped_note(laser: str, parsed: ParsedChunk) -> str:
    """The message kinds the loader skips, as one sentence ('' when none): each with its count and first line
    among the lines :func:`probe` read (the log's head), so a user learns what is not read without a pass."""
    if not parsed.ignored:
        return ""
    kinds = sorted(parsed.ignored, key=lambda name: parsed.ignored_first[name])
    listed = ", ".join(
        f"{parsed.ignored[name]} {name} line{'' if parsed.ignored[name] == 1 else 's'} "
        f"{'at' if parsed.ignored[name] == 1 else 'from'} line {parsed.ignored_first[name]}"
        + (f" (a laser: read it with laser={name})" if name in LASER_MESSAGES else "")
        for name in kinds
    )
    return (
        f"{listed}, counted in the first {parsed.last_line} lines; message kinds other than {laser}, ODOM, "
        f"TRUEPOS and PARAM are not read"
    )


def noteworthy_skips(parsed: ParsedChunk) -> bool:
    """Whether a skipped kind may hold data a user wants (anything but :data:`QUIET_SKIPS`)."""
    return any(name not in QUIET_SKIPS for name in parsed.ignored)


def refuse_mixed(path: Path, laser: str, parsed: ParsedChunk) -> None:
    """A ParseError if ``parsed`` holds front-laser messages of another kind than ``laser``."""
    other = next((name for name in FRONT_LASERS if name != laser and parsed.ignored.get(name)), None)
    if other is None:
        return
    counts, first = count_messages(path, FRONT_LASERS)
    kinds = [name for name in FRONT_LASERS if counts.get(name)]
    listed = " and ".join(f"{counts[name]} {name} lines (first at line {first[name]})" for name in kinds)
    choices = " or ".join(f"laser={name}" for name in kinds)
    raise ParseError(
        path,
        f"the log mixes front-laser message kinds: {listed}; expected one kind (they may be the same scans "
        f"written twice or two recordings, so none is merged or dropped silently); choose with the loader "
        f"option {choices} (e.g. 'FILE?laser={kinds[0]}'), the other kind is then skipped",
        line=parsed.ignored_first.get(other, first.get(other)),
    )


def count_messages(path: Path, names: tuple[str, ...]) -> tuple[dict[str, int], dict[str, int]]:
    """Count and first line of each message in ``names`` over the whole log (only on the error path)."""
    counts: dict[str, int] = {}
    first: dict[str, int] = {}
    try:
        for chunk in iter_line_chunks(path):
            for name, rows in split_messages(path, chunk.first_line, chunk.lines).items():
                if name in names:
                    counts[name] = counts.get(name, 0) + len(rows)
                    first.setdefault(name, rows[0][0])
    except ParseError:
        pass  # a damaged tail: the counts so far still describe the mix
    return counts, first
