"""Progress bars of the long commands (``run``, ``convert``, ``datasets info``, ``evaluate``, ``report``).

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


def slice_bound(ref: str) -> int | None:
    """At most how many scans ``NAME[:STOP]`` / ``NAME[:STOP:STEP]`` yields (None without a STOP).

    A CARMEN log's length is unknown until it is decoded, but a slice's stop
    bounds it: the bar of ``run 'intel[:3000]'`` gets a total and an ETA
    (it ends early only when the log is shorter than the slice).
    """
    from albot1.data.open import split_slice

    _, stop, step = split_slice(ref)
    if stop is None:
        return None
    return -(-stop // step) if step is not None else stop


def with_progress(sequence: Sequence, desc: str, at_most: int | None = None) -> Sequence:
    """``sequence`` whose every pass over the frames advances a bar (unchanged when bars are off).

    The bar's total is the scan count when known without decoding, else
    ``at_most`` (a slice's bound, :func:`slice_bound`), else none (a rate).
    """
    if not enabled():
        return sequence
    known = sequence.known_scan_count
    total = known if known is not None else at_most

    def frames(source: Iterator[Frame]) -> Iterator[Frame]:
        bar = _bar(total, desc)
        try:
            for frame in source:
                yield frame
                bar.update(1)
        finally:
            bar.close()

    return sequence.with_frames(frames, scan_count=known)


class FigureBar:
    """The bar of ``albot1 report``: datasets whose figures are drawn, of those to draw, with an ETA.

    Drawing is most of a report's time (30-40 s for the quick suite, minutes
    for the default one). Created on the first :meth:`update` (the report
    knows the count only once it has read the results), never when stderr is
    not a terminal, nor when every figure comes from the cache.
    """

    def __init__(self) -> None:
        self._bar: Any = None

    def update(self, done: int, total: int) -> None:
        if not enabled() or total == 0:
            return
        if self._bar is None:
            from tqdm import tqdm

            self._bar = tqdm(
                total=total,
                desc="report: drawing",
                unit="dataset",
                file=sys.stderr,
                dynamic_ncols=True,
                leave=False,
                mininterval=0,  # one update per dataset: every one is shown
            )
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
