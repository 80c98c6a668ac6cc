"""Albot1+'s overlap rule: a view point is matched to an update-view surface only where that surface was seen.

The scan refinement (:func:`~albot1.methods.albot1.mapping.pose_kernels.refine_pose`) associates every view
point with the nearest surface of the last update view within the gate (0.5 m), measured to the *segment*,
and then uses the point's distance to the surface's *line*. A point up to the gate beyond a surface's end is
therefore matched to the surface's extension, which the update view never saw: the far side of an occluding
corner, a wall that turns, a surface cut by the edge of the update view's field of view or range. Seen from a
new viewpoint, such points are where the two views' overlap is asymmetric, and measured with perfect odometry
(``docs/albot1-mapper.md``, "The overlap rule") they carry most of the refinement's heading bias on
``freiburg-079-corrected``.

With ``scan_overlap = "surface"`` (:class:`~albot1.methods.albot1.mapping.config.Albot1Config`) a point whose
projection on a surface's line falls more than ``scan_overhang_m`` beyond either end is not associated with
that surface (another surface may still take it; none within the gate: it is unused, and in the robust cost
it costs the gate as any unmatched point does). The default, ``"gate"``, passes :data:`NO_LIMIT`, which never
excludes anything, so the kernels' arithmetic, and every pose, is that of before.
"""

from __future__ import annotations

import math

from albot1.methods.albot1.compiled import jitable

#: The overhang that excludes nothing (``scan_overlap = "gate"``): a point within the gate of a segment
#: projects at most the gate beyond its ends, and an infinite limit is never exceeded.
NO_LIMIT = math.inf


@jitable
def overhangs(x: float, y: float, ax: float, ay: float, bx: float, by: float, limit: float) -> bool:
    """Whether the projection of ``(x, y)`` on the line through a-b falls more than ``limit`` m beyond a or b.

    A degenerate segment (a = b) has no line to project on: never excluded (the caller's distance to it is
    the distance to the point, as before). ``limit`` :data:`NO_LIMIT` never excludes.
    """
    ex = bx - ax
    ey = by - ay
    l2 = ex * ex + ey * ey
    return overhangs_along((x - ax) * ex + (y - ay) * ey, l2, math.sqrt(l2), limit)


@jitable
def overhangs_along(along: float, l2: float, length: float, limit: float) -> bool:
    """:func:`overhangs` from the projection ``along`` (``(p - a) . (b - a)``, the projection times the length),
    the squared length ``l2`` and the length ``sqrt(l2)``.

    Albot1+'s nearest surface (:func:`~albot1.methods.albot1.mapping.pose_kernels.nearest_surface`) has them
    already: it clips ``along / l2`` for the distance next, and computes the length once per surface, not once
    per point and surface.
    """
    if limit == NO_LIMIT or not l2 > 0.0:
        return False
    reach = limit * length
    return along < -reach or along > l2 + reach
