"""Progress bars of the long single-log commands (``run``, ``convert``, ``datasets info``, ``evaluate``).

Shown on stderr and only when stderr is a terminal: piped or captured
output (``--json | jq``, CI logs, tests) stays free of bar redraws. A log's
scan count is used as the bar's total when it is known without decoding
(:attr:`~albot1.data.model.Sequence.known_scan_count`); otherwise the bar
counts scans and shows the rate.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from albot1.data.model import Frame, Sequence


def enabled() -> bool:
    """Whether to draw bars: stderr is a terminal."""
    return sys.stderr.isatty()


def _bar(total: int | None, desc: str) -> Any:
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit="scan", file=sys.stderr, dynamic_ncols=True, leave=False)


def with_progress(sequence: Sequence, desc: str) -> Sequence:
    """``sequence`` whose every pass over the frames advances a bar (unchanged when bars are off)."""
    if not enabled():
        return sequence
    total = sequence.known_scan_count

    def frames(source: Iterator[Frame]) -> Iterator[Frame]:
        bar = _bar(total, desc)
        try:
            for frame in source:
                yield frame
                bar.update(1)
        finally:
            bar.close()

    return sequence.with_frames(frames, scan_count=total)
