"""A sequence's reference poses written as a TUM trajectory file, the form other tools' ground truth takes.

A researcher scoring their own recording brings its reference trajectory as
a file (``?reference=gt.tum`` on any source, ``albot1 evaluate --reference``,
evo). To show that path on a public log, the log's reference poses (a
corrected CARMEN log's, a synthetic world's exact ones) must become such a
file: this module writes them, one TUM line per scan at the scan's stamp.

The file must read back as it was meant, so what the trajectory reader
refuses is refused here before anything is written: a scan without a
reference pose (all or nothing, as the ``reference=`` option requires), and
a stamp that repeats or goes backwards (two poses with one stamp cannot be
told apart). ``retime`` moves such stamps exactly as ``albot1 convert
--retime`` does (:func:`albot1.data.convert.retimed`), so the file's stamps
equal those of a bag converted with ``--retime`` from the same source.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from albot1.atomic import atomic_write
from albot1.data.convert import retimed
from albot1.data.errors import UnwritableError
from albot1.data.loaders.output import check_output, prepare_output, writing
from albot1.data.model import Frame, Sequence
from albot1.data.trajectory import write_tum


@dataclass(frozen=True)
class ReferenceExport:
    """What :func:`write_reference_tum` wrote; ``retimed`` counts scans whose stamp was moved."""

    source: str
    output: Path
    poses: int
    retimed: int = 0


def write_reference_tum(sequence: Sequence, dst: str | Path, *, retime: bool = False) -> ReferenceExport:
    """Write every scan's reference pose of ``sequence`` to the TUM file ``dst`` (which must not exist).

    Raises :class:`UnwritableError` naming the output and the scan when a
    scan has no reference pose or its stamp does not follow the previous
    one (without ``retime``); nothing is written then.
    """
    out = check_output(dst)  # refused before the (maybe long) load, as for every writer
    shifted = [0]
    frames: Iterator[Frame] = retimed(sequence.frames(), shifted) if retime else sequence.frames()
    stamps: list[float] = []
    poses: list[np.ndarray] = []
    for frame in frames:
        if frame.reference is None:
            raise UnwritableError(
                f"{out}: scan {frame.index} (t = {frame.scan.timestamp:.6f} s) of {sequence.name} has no "
                "reference pose; expected one for every scan (a source without reference poses has no "
                "reference trajectory; `albot1 datasets info` says whether it has one)"
            )
        t = frame.scan.timestamp
        if stamps and t <= stamps[-1]:
            raise UnwritableError(
                f"{out}: scan {frame.index} of {sequence.name} is stamped {t:.6f} s, not after the previous "
                f"scan's {stamps[-1]:.6f} s; expected increasing stamps (a TUM file matches poses by time); "
                "--retime moves such stamps as `albot1 convert --retime` does"
            )
        stamps.append(t)
        poses.append(frame.reference)
    if not stamps:
        raise UnwritableError(f"{out}: {sequence.name} holds no scan; expected at least one reference pose")
    prepare_output(out)
    with writing(out):
        atomic_write(out, lambda tmp: write_tum(tmp, np.asarray(stamps), np.asarray(poses, dtype=float)))
    return ReferenceExport(
        source=sequence.metadata.source or sequence.name, output=out, poses=len(stamps), retimed=shifted[0]
    )
