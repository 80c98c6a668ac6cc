"""Small streamed transforms of a Sequence (prefix, stride)."""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import replace

from albot1.data.model import Frame, Sequence


def head(sequence: Sequence, count: int) -> Sequence:
    """The first ``count`` frames (still streamed)."""
    if count < 1:
        raise ValueError(f"expected a positive scan count, got {count}")
    return sequence.with_frames(lambda frames: itertools.islice(frames, count))


def stride(sequence: Sequence, step: int) -> Sequence:
    """Every ``step``-th frame, renumbered from 0."""
    if step < 1:
        raise ValueError(f"expected a positive stride, got {step}")

    def pick(frames: Iterator[Frame]) -> Iterator[Frame]:
        for i, frame in enumerate(itertools.islice(frames, 0, None, step)):
            yield replace(frame, index=i)

    return sequence.with_frames(pick)
