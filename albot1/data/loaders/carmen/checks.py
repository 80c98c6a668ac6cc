"""What a CARMEN scan line may hold: one set of rules for the reader and the writer.

:mod:`.parse` applies them to whole blocks of parsed lines (numpy, one pass per
block) and :mod:`.writer` to each frame before writing it, so the writer can
never produce a log the reader refuses. Each check returns ``None`` or the
index of the first offending row with a one-line description of what was
found and what was expected (the caller adds the file and line).

The rules (``docs/datasets.md``, "What the CARMEN reader refuses"):

* 1 to ``MAX_BEAMS`` beams; ranges finite and >= 0; not *every* range 0 (0 is
  CARMEN's "no reading", so such a line is a dead or disconnected laser, not
  a scan);
* ROBOTLASER1/RAWLASER geometry: finite start angle within a full turn either
  way; angular resolution > 0 (>= 0 for a single beam); the beams spanning at
  most a full turn; the field of view, when stated (> 0), agreeing with the
  resolution to within one beam (loggers write ``n * res`` or
  ``(n - 1) * res``); max range finite and >= 0 (0 = not stated);
* timestamps (and poses) finite; the scan stamps never going back by more
  than the loader's ``time_tolerance``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray

#: More beams than this is not a planar laser but a corrupt count.
MAX_BEAMS = 100_000
FULL_TURN = 2 * math.pi
#: Angle slack (radians): the logs print angles with 6 decimals, so a 180-beam
#: field of view rebuilt from a printed resolution misses by up to ~1e-4 rad.
ANGLE_SLACK = 1e-3


def beam_count_problem(beams: int) -> str | None:
    if 1 <= beams <= MAX_BEAMS:
        return None
    return f"beam count is {beams}, expected 1 to {MAX_BEAMS} beams"


def ranges_problem(ranges: FloatArray) -> tuple[int, str] | None:
    """Rows of readings ``(k, n)``: a non-finite or negative reading, or a row of zeros."""
    bad = ~np.isfinite(ranges) | (ranges < 0)
    if bad.any():
        row, beam = (int(v) for v in np.argwhere(bad)[0])
        value = float(ranges[row, beam])
        return row, f"range {beam + 1} is {value!r}, expected a finite non-negative distance in metres"
    if ranges.shape[1]:
        dead = ~ranges.any(axis=1)
        if dead.any():
            row = int(np.argmax(dead))
            return row, (
                f"all {ranges.shape[1]} ranges are 0, expected at least one reading (0 means 'no reading': "
                f"a line of zeros is a dead or disconnected laser, not a scan)"
            )
    return None


def span_problem(beams: int, step: float) -> str | None:
    """Evenly spaced beams ``step`` radians apart must not cover more than a full turn."""
    span = (beams - 1) * step
    if span <= FULL_TURN + ANGLE_SLACK:
        return None
    return (
        f"{beams} beams {math.degrees(step):.6g} deg apart span {math.degrees(span):.6g} deg, "
        f"expected at most a full turn (360 deg)"
    )


def geometry_problem(
    beams: int, start: FloatArray, fov: FloatArray, resolution: FloatArray, max_range: FloatArray
) -> tuple[int, str] | None:
    """ROBOTLASER1/RAWLASER header fields, one value per row (radians, metres)."""
    checks: list[tuple[NDArray[np.bool_], str]] = [
        (
            ~np.isfinite(start) | (np.abs(start) > FULL_TURN + ANGLE_SLACK),
            "start_angle is {start!r} rad, expected a finite angle within a full turn (-2 pi to 2 pi)",
        ),
        (
            ~np.isfinite(resolution) | (resolution < 0) | ((resolution == 0) & (beams > 1)),
            "angular_resolution is {res!r} rad, expected a positive angle between beams (beams are listed "
            "counter-clockwise)",
        ),
        (
            ~np.isfinite(max_range) | (max_range < 0),
            "maximum_range is {max_range!r} m, expected a finite distance >= 0 (0 = not stated)",
        ),
    ]
    span = (beams - 1) * resolution
    with np.errstate(invalid="ignore"):
        checks += [
            (span > FULL_TURN + ANGLE_SLACK, ""),
            (
                ~np.isfinite(fov) | (fov < 0) | (fov > FULL_TURN + ANGLE_SLACK),
                "field_of_view is {fov!r} rad, expected 0 (not stated) to 2 pi",
            ),
        ]
    for bad, template in checks:
        if bad.any():
            row = int(np.argmax(bad))
            if not template:  # the span: said in degrees, with the resolution that makes it
                problem = span_problem(beams, float(resolution[row]))
                return row, f"{problem} (angular_resolution {float(resolution[row])!r} rad)"
            return row, template.format(
                start=float(start[row]),
                res=float(resolution[row]),
                max_range=float(max_range[row]),
                fov=float(fov[row]),
            )
    stated = fov > 0
    off = stated & (np.abs(fov - span) > resolution + ANGLE_SLACK)
    if off.any():
        row = int(np.argmax(off))
        return row, (
            f"field_of_view {float(fov[row])!r} rad disagrees with {beams} beams at angular_resolution "
            f"{float(resolution[row])!r} rad (they span {float(span[row])!r} rad), expected the two to agree "
            f"to within one beam"
        )
    return None


def time_problem(previous: float, stamp: float, tolerance: float, since: str = "") -> str | None:
    """A scan stamp going back more than ``tolerance`` seconds from the latest one (``since`` says where that was)."""
    if stamp >= previous - tolerance:
        return None
    back = previous - stamp
    shown = f"{stamp:.6f}" if abs(stamp) < 1e12 else f"{stamp:.6g}"
    back_shown = f"{back:.3f}" if back < 1e12 else f"{back:.6g}"
    return (
        f"timestamp {shown} goes back {back_shown} s{since}; expected "
        f"non-decreasing ipc timestamps (tolerance {tolerance} s)"
    )
