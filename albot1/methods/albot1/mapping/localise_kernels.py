"""Albot1+'s start poses from the thesis's localisation, compiled: ``localise`` and ``start_poses`` in one kernel.

Issue 24 asks for Albot1+ at most a third of KISS-ICP's per-scan cost. After
the kernels of :mod:`.step_kernels`, the dearest Python left in a ``plus``
scan was :func:`~.localisation.localise` (about 15 us: a loop over the
recognised landmarks on Python floats), the start poses built from its
result, and the landmark rows gathered for the pose fit (a dict look-up per
landmark, three numpy conversions, the stable endpoint pairs: about 10 us
more). :func:`robust_starts` does all of it in one compiled call: the rows,
the same candidates, scores, outlier rule, choice and start poses.

Bit for bit: localisation measures lengths and distances with CPython's
``math.hypot``, whose result differs in the last bit from C's ``hypot``
(what numba calls) on about 0.3-0.6 % of inputs. Those values rank the
candidates, so a compiled ``math.hypot`` could pick another candidate in a
near tie. :func:`python_hypot` is CPython 3.11's algorithm for two arguments
(``vector_norm`` in ``Modules/mathmodule.c``: scaling by a power of two,
Dekker's exact squares, compensated sums and one correction step), written
out in the same operations and order, so compiled it gives ``math.hypot``'s
bits (checked on 10 million random inputs and the edge cases in the tests).
The other operations are the ones :mod:`.localisation` makes, on the same
values in the same order (``landmark_pose`` and ``goodness`` are the same
functions, compiled in; sums left to right from 0.0 as CPython 3.11's
``sum`` of floats does).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import jitable, kernel
from albot1.methods.albot1.mapping.localisation import goodness, landmark_pose
from albot1.methods.albot1.perception.endpoints import STABLE
from albot1.methods.albot1.perception.recognition import IntArray

BoolArray = NDArray[np.bool_]

#: Veltkamp's constant 2**27 + 1: ``t - (t - x)`` with ``t = x * _SPLIT`` keeps the top 26 bits of ``x``.
_SPLIT = 134217729.0

# the two functions localisation's loop calls, compiled into the kernel below (the same source either way)
jitable(landmark_pose)
jitable(goodness)


@jitable
def python_hypot(x: float, y: float) -> float:
    """``math.hypot(x, y)`` with CPython 3.11's bits: its ``vector_norm`` for two arguments, step for step.

    Numba's ``math.hypot`` is C's, which rounds differently in the last bit
    on a fraction of a percent of inputs. CPython's: infinities first, then
    NaN, then the largest magnitude scaled to [0.5, 1) by a power of two
    (lossless), each square split exactly (Dekker) and summed with the
    errors kept, the square root, and one differential correction. A largest
    magnitude below 2**-1023 (subnormal) cannot be scaled so; it is divided
    by instead, as CPython does.
    """
    ax = abs(x)
    ay = abs(y)
    big = 0.0
    if ax > big:
        big = ax
    if ay > big:
        big = ay
    if math.isinf(big):
        return big
    if ax != ax or ay != ay:
        return math.nan
    if big == 0.0:
        return big
    csum = 1.0
    frac1 = 0.0
    frac2 = 0.0
    frac3 = 0.0
    max_e = math.frexp(big)[1]
    if max_e < -1023:
        for v in (ax, ay):
            q = v / big
            q = q * q
            old = csum
            csum += q
            frac1 += (old - csum) + q
        return big * math.sqrt(csum - 1.0 + frac1)
    scale = math.ldexp(1.0, -max_e)
    for v in (ax, ay):
        q = v * scale
        t = q * _SPLIT
        hi = t - (t - q)
        lo = q - hi
        q = hi * hi
        old = csum
        csum += q
        frac1 += (old - csum) + q
        q = 2.0 * hi * lo
        old = csum
        csum += q
        frac2 += (old - csum) + q
        frac3 += lo * lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2 + frac3))
    t = h * _SPLIT
    hi = t - (t - h)
    lo = h - hi
    q = -hi * hi
    old = csum
    csum += q
    frac1 += (old - csum) + q
    q = -2.0 * hi * lo
    old = csum
    csum += q
    frac2 += (old - csum) + q
    q = -lo * lo
    old = csum
    csum += q
    frac3 += (old - csum) + q
    q = csum - 1.0 + (frac1 + frac2 + frac3)
    return (h + q / (2.0 * h)) / scale


@kernel
def robust_starts(
    surfaces: FloatArray,
    kinds: IntArray,
    ids: IntArray,
    sides: IntArray,
    d_prev: FloatArray,
    gaps: FloatArray,
    angle_diffs: FloatArray,
    lm_ids: IntArray,
    lm_segs: FloatArray,
    lm_kinds: IntArray,
    odometry_x: float,
    odometry_y: float,
    odometry_phi: float,
    turns: FloatArray,
    min_candidates: int,
    gap_floor: float,
    angle_floor: float,
) -> tuple[FloatArray, FloatArray, FloatArray, BoolArray, int]:
    """Albot1+'s start poses, its landmark rows, and the thesis localisation's chosen row (-1: none placed the robot).

    ``surfaces`` ... ``angle_diffs``: the recognised landmark list (a
    :class:`~albot1.methods.albot1.perception.recognition.Tracked`'s arrays;
    ``d_prev`` its ``prev_distance`` or ``prev_distance_current``, NaN for a
    list reset from a view). ``lm_ids``, ``lm_segs``, ``lm_kinds``: the
    landmark map, each landmark as placed at the update that introduced it;
    a tracked landmark's record is the last row with its id (as the dict
    :func:`~.localisation.localise` reads keeps the last). Returns, over the tracked rows that have a
    record (in their order):

    * what ``start_poses(odometry, loc.pose, loc.poses)`` returns for ``loc
      = localise(...)``: the thesis pose, the odometry, every candidate
      (without a candidate: the odometry turned by each of ``turns``);
    * their surfaces now and in the map (``(k, 4)``), and which endpoints
      are stable both now and there (``(k, 2)``): the pose fit's inputs;
    * the tracked row of ``loc``'s landmark (-1 when ``loc`` is None).
    """
    n = surfaces.shape[0]
    record = np.empty(n, dtype=np.int64)
    k = 0
    for r in range(n):
        record[r] = -1
        for m in range(lm_ids.shape[0] - 1, -1, -1):
            if lm_ids[m] == ids[r]:
                record[r] = m
                k += 1
                break
    lm_view = np.empty((k, 4))
    lm_map = np.empty((k, 4))
    ok = np.empty((k, 2), dtype=np.bool_)
    side_of = np.empty(k, dtype=np.int64)
    rows = np.empty(k, dtype=np.int64)
    c = 0
    j = 0
    for r in range(n):
        m = record[r]
        if m < 0:
            continue
        for q in range(4):
            lm_view[j, q] = surfaces[r, q]
            lm_map[j, q] = lm_segs[m, q]
        for s in range(2):
            ok[j, s] = STABLE[kinds[r, s]] and STABLE[lm_kinds[m, s]]
        # localise's rule: the matched side first, then the other (P1 first when unmatched); stable now and there
        first = sides[r] if sides[r] >= 0 else 0
        side_of[j] = -1
        for s in (first, 1 - first):
            if ok[j, s]:
                side_of[j] = s
                c += 1
                break
        rows[j] = r
        j += 1
    if c == 0:
        starts = np.empty((turns.shape[0], 3))
        for i in range(turns.shape[0]):
            starts[i, 0] = odometry_x
            starts[i, 1] = odometry_y
            starts[i, 2] = odometry_phi + turns[i]
        return starts, lm_view, lm_map, ok, -1
    starts = np.empty((2 + c, 3))
    scores = np.empty(c)
    chosen = np.empty(c, dtype=np.int64)
    i = 0
    for j in range(k):
        if side_of[j] < 0:
            continue
        r = rows[j]
        x, y, phi = landmark_pose(lm_map[j], lm_view[j], side_of[j])
        starts[2 + i, 0] = x
        starts[2 + i, 1] = y
        starts[2 + i, 2] = phi
        length = python_hypot(lm_view[j, 2] - lm_view[j, 0], lm_view[j, 3] - lm_view[j, 1])
        d_r = d_prev[r] if d_prev[r] == d_prev[r] else 1.0
        g = gaps[r] if gaps[r] == gaps[r] else gap_floor
        a = angle_diffs[r] if angle_diffs[r] == angle_diffs[r] else angle_floor
        scores[i] = goodness(length, d_r, g, a, gap_floor, angle_floor)
        chosen[i] = r
        i += 1
    # outlier_keep, then the first best-scored kept candidate (max's rule: only a strictly larger score replaces)
    best = -1
    if c < min_candidates:
        best = 0
        for i in range(1, c):
            if scores[i] > scores[best]:
                best = i
    else:
        mx = 0.0
        for i in range(c):
            mx += starts[2 + i, 0]
        mx = mx / c
        my = 0.0
        for i in range(c):
            my += starts[2 + i, 1]
        my = my / c
        dist = np.empty(c)
        squares = 0.0
        for i in range(c):
            dist[i] = python_hypot(starts[2 + i, 0] - mx, starts[2 + i, 1] - my)
            squares += dist[i] * dist[i]
        sigma = math.sqrt(squares / c)
        for i in range(c):
            if dist[i] <= sigma * (1.0 + 1e-12) and (best < 0 or scores[i] > scores[best]):
                best = i
        if best < 0:
            raise ValueError("localisation: no candidate pose within the outlier rule's bound (non-finite poses)")
    starts[0, 0] = starts[2 + best, 0]
    starts[0, 1] = starts[2 + best, 1]
    starts[0, 2] = starts[2 + best, 2]
    starts[1, 0] = odometry_x
    starts[1, 1] = odometry_y
    starts[1, 2] = odometry_phi
    return starts, lm_view, lm_map, ok, chosen[best]
