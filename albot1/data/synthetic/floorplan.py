"""Floor plans of corridors, rooms and doorways, with the walls as segments.

A plan is described the way an architect would sketch it: axis-aligned
rectangles of free floor (``Space``: corridor pieces, rooms, alcoves) separated
by walls of a given thickness, ``DoorwaySpec`` openings cut through those
walls, and furniture (``obstacles``: rectangles, or polygons for pieces standing askew) on the floor. Shapely
unions the free floor and subtracts the furniture; the walls the laser sees
are the boundary of that free region, as line segments. Deriving the walls
from the free region (rather than listing wall lines by hand) guarantees the
plan is closed and watertight: every ray from inside hits something or leaves
through nothing, and a doorway is a true gap in the wall with jamb edges that
give the occluding points Albot1 relies on.

Each doorway keeps a *threshold*: the segment across the opening at the wall's
mid-plane. A robot crossing it moves from one space to another, which is what
chapter 4's places are built from; :func:`doorway_crossings` finds those
crossings exactly on a sampled route.

Shapely is imported inside the functions that need it, so importing this
module (e.g. from the CLI's world registry) stays cheap.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from albot1.data.synthetic.errors import SyntheticWorldError
from albot1.geometry.types import FloatArray

if TYPE_CHECKING:
    from shapely.geometry.base import BaseGeometry

Rect = tuple[float, float, float, float]  # xmin, ymin, xmax, ymax
#: A piece of furniture: an axis-aligned :data:`Rect`, or a polygon as its corners ``((x, y), ...)``.
Obstacle = Rect | tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class Space:
    """A named rectangle of free floor; rectangles with the same name form one space."""

    name: str
    rect: Rect

    def contains(self, x: float, y: float) -> bool:
        x0, y0, x1, y1 = self.rect
        return x0 <= x <= x1 and y0 <= y <= y1


@dataclass(frozen=True)
class DoorwaySpec:
    """An opening of ``width`` metres centred at ``centre`` in a wall running along ``wall`` ('x' or 'y')."""

    id: str
    centre: tuple[float, float]
    wall: Literal["x", "y"]
    width: float = 0.9


@dataclass(frozen=True)
class Doorway:
    """A doorway of a built plan: its threshold segment ``a``-``b`` and the spaces on either side.

    ``spaces[0]`` lies to the left of ``a -> b`` and ``spaces[1]`` to its right,
    so the side a point is on tells which space it is entering.
    """

    id: str
    a: tuple[float, float]
    b: tuple[float, float]
    spaces: tuple[str, str]

    @property
    def width(self) -> float:
        return math.hypot(self.b[0] - self.a[0], self.b[1] - self.a[1])

    @property
    def centre(self) -> tuple[float, float]:
        return ((self.a[0] + self.b[0]) / 2.0, (self.a[1] + self.b[1]) / 2.0)

    def as_dict(self) -> dict[str, Any]:
        return {"id": self.id, "a": list(self.a), "b": list(self.b), "width_m": self.width, "spaces": list(self.spaces)}


@dataclass(frozen=True, eq=False)
class FloorPlan:
    """A built plan: wall segments ``(M, 4)``, doorways, and the rectangles it was made from."""

    name: str
    walls: FloatArray
    doorways: tuple[Doorway, ...]
    spaces: tuple[Space, ...]
    obstacles: tuple[Obstacle, ...]
    wall_thickness: float

    def doorway(self, doorway_id: str) -> Doorway:
        for door in self.doorways:
            if door.id == doorway_id:
                return door
        raise SyntheticWorldError(
            f"plan {self.name!r} has no doorway {doorway_id!r}; doorways: {', '.join(d.id for d in self.doorways)}"
        )

    def space_at(self, x: float, y: float) -> str | None:
        """The name of the space containing a point (None in a wall or doorway gap)."""
        for space in self.spaces:
            if space.contains(x, y):
                return space.name
        return None

    def free_space(self) -> BaseGeometry:
        """The free floor as a shapely geometry (spaces and doorway passages, minus furniture)."""
        return _free_space(self.spaces, [_passage(d, self.wall_thickness) for d in self.doorways], self.obstacles)


def build_plan(
    name: str,
    spaces: Sequence[Space],
    doorways: Sequence[DoorwaySpec] = (),
    obstacles: Sequence[Obstacle] = (),
    *,
    wall_thickness: float = 0.2,
) -> FloorPlan:
    """Build a :class:`FloorPlan` and check it: every doorway must join two different spaces."""
    if wall_thickness <= 0:
        raise SyntheticWorldError(f"plan {name!r}: expected a positive wall thickness, got {wall_thickness}")
    for space in spaces:
        x0, y0, x1, y1 = space.rect
        if not (x1 > x0 and y1 > y0):
            raise SyntheticWorldError(
                f"plan {name!r}: space {space.name!r} rect {space.rect} must have xmin < xmax and ymin < ymax"
            )
    ids = [d.id for d in doorways]
    if len(set(ids)) != len(ids):
        raise SyntheticWorldError(f"plan {name!r}: doorway ids must be unique, got {ids}")
    built = tuple(_doorway(name, spec, spaces, wall_thickness) for spec in doorways)
    passages = [_passage(d, wall_thickness) for d in built]
    free = _free_space(spaces, passages, obstacles)
    return FloorPlan(
        name=name,
        walls=boundary_segments(free),
        doorways=built,
        spaces=tuple(spaces),
        obstacles=tuple(obstacles),
        wall_thickness=wall_thickness,
    )


def _doorway(plan: str, spec: DoorwaySpec, spaces: Sequence[Space], thickness: float) -> Doorway:
    """The threshold of a doorway and the two spaces it joins (probed just beyond the wall)."""
    if not 0 < spec.width:
        raise SyntheticWorldError(f"plan {plan!r}: doorway {spec.id!r} needs a positive width, got {spec.width}")
    cx, cy = spec.centre
    half, probe = spec.width / 2.0, thickness / 2.0 + 0.05
    if spec.wall == "x":  # wall along x: the door is passed in the y direction
        a, b = (cx - half, cy), (cx + half, cy)
        left, right = (cx, cy + probe), (cx, cy - probe)
    elif spec.wall == "y":
        a, b = (cx, cy - half), (cx, cy + half)
        left, right = (cx - probe, cy), (cx + probe, cy)
    else:
        raise SyntheticWorldError(f"plan {plan!r}: doorway {spec.id!r} wall must be 'x' or 'y', got {spec.wall!r}")
    names = []
    for point in (left, right):
        found = [s.name for s in spaces if s.contains(*point)]
        if not found:
            raise SyntheticWorldError(
                f"plan {plan!r}: doorway {spec.id!r} at {spec.centre} does not open into a space at {point}; "
                f"expected its centre on the mid-line of a {thickness} m wall between two spaces"
            )
        names.append(found[0])
    if names[0] == names[1]:
        raise SyntheticWorldError(f"plan {plan!r}: doorway {spec.id!r} joins space {names[0]!r} to itself")
    return Doorway(spec.id, a, b, (names[0], names[1]))


def _passage(door: Doorway, thickness: float) -> Rect:
    """The free rectangle through the wall that a doorway opens (overlapping both spaces a little)."""
    reach = thickness / 2.0 + 0.05
    xs, ys = (door.a[0], door.b[0]), (door.a[1], door.b[1])
    if ys[0] == ys[1]:
        return (min(xs), ys[0] - reach, max(xs), ys[0] + reach)
    return (xs[0] - reach, min(ys), xs[0] + reach, max(ys))


def _free_space(spaces: Iterable[Space], passages: Iterable[Rect], obstacles: Iterable[Obstacle]) -> BaseGeometry:
    from shapely.geometry import Polygon, box
    from shapely.ops import unary_union

    free = unary_union([box(*s.rect) for s in spaces] + [box(*r) for r in passages])
    blocked = [Polygon(r) if isinstance(r[0], tuple) else box(*r) for r in obstacles]
    if blocked:
        free = free.difference(unary_union(blocked))
    return free.simplify(0.0)


def boundary_segments(region: BaseGeometry) -> FloatArray:
    """The boundary of a (multi)polygon as ``(M, 4)`` segments, collinear vertices merged."""
    polygons = list(getattr(region, "geoms", [region]))
    rows: list[FloatArray] = []
    for polygon in polygons:
        for ring in [polygon.exterior, *polygon.interiors]:
            xy = np.asarray(ring.coords, dtype=float)
            rows.append(np.hstack([xy[:-1], xy[1:]]))
    if not rows:
        return np.empty((0, 4))
    seg = np.vstack(rows)
    return seg[np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1]) > 0]


def check_route(plan: FloorPlan, waypoints: Sequence[tuple[float, float]], *, clearance: float = 0.0) -> None:
    """Raise SyntheticWorldError unless every leg stays on the free floor, ``clearance`` m from any wall.

    A route through a wall would make ray-cast scans from impossible poses;
    catching it when a world is built names the offending leg.
    """
    from shapely.geometry import LineString

    free = plan.free_space()
    allowed = free.buffer(-clearance) if clearance > 0 else free.buffer(1e-9)
    for i, (a, b) in enumerate(zip(waypoints[:-1], waypoints[1:], strict=True)):
        if not allowed.covers(LineString([a, b])):
            raise SyntheticWorldError(
                f"plan {plan.name!r}: route leg {i} from {tuple(a)} to {tuple(b)} leaves the free floor"
                + (f" or passes within {clearance} m of a wall" if clearance > 0 else "")
                + "; expected legs through rooms, corridors and doorways only"
            )


@dataclass(frozen=True)
class DoorwayCrossing:
    """The route passing through a doorway: the first scan at or beyond the threshold, its time, and where it crossed.

    ``time`` (s) is that scan's timestamp: a run that saw a selection of the
    scans (a ``[::STEP]`` slice, ``?views=`` spacing, a dropout) numbers them
    afresh, and the scan's time is what finds the crossing among them
    (:func:`albot1.metrics.places.crossings_in_run`).
    """

    scan: int
    time: float
    position: tuple[float, float]
    doorway: str
    from_space: str
    to_space: str

    def as_dict(self) -> dict[str, Any]:
        return {
            "scan": self.scan,
            "t": self.time,
            "x": self.position[0],
            "y": self.position[1],
            "doorway": self.doorway,
            "from": self.from_space,
            "to": self.to_space,
        }


def doorway_crossings(plan: FloorPlan, poses: ArrayLike, times: ArrayLike) -> list[DoorwayCrossing]:
    """Every crossing of a doorway threshold by the polyline through ``poses`` (N, 3) at ``times`` (N,), in route order.

    The route crosses when it passes from one strict side of the threshold to
    the other; the crossing's scan is the first one on the threshold or
    beyond it, and its position is where the straight path between the last
    scan before and the first scan after meets the threshold line. A route
    that touches a threshold and turns back has not crossed it.
    """
    p = np.asarray(poses, dtype=float)[:, :2]
    t = np.asarray(times, dtype=float)
    found: list[DoorwayCrossing] = []
    for door in plan.doorways:
        ax, ay = door.a
        ex, ey = door.b[0] - ax, door.b[1] - ay
        side = np.sign(ex * (p[:, 1] - ay) - ey * (p[:, 0] - ax))  # +1: left of a->b
        strict = np.flatnonzero(side != 0)
        for k in np.flatnonzero(side[strict[:-1]] != side[strict[1:]]):
            i, j = strict[k], strict[k + 1]
            s0 = ex * (p[i, 1] - ay) - ey * (p[i, 0] - ax)
            s1 = ex * (p[j, 1] - ay) - ey * (p[j, 0] - ax)
            f = s0 / (s0 - s1)
            x = p[i, 0] + f * (p[j, 0] - p[i, 0])
            y = p[i, 1] + f * (p[j, 1] - p[i, 1])
            along = ((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey)
            if not 0.0 <= along <= 1.0:
                continue
            src, dst = (door.spaces[0], door.spaces[1]) if side[i] > 0 else (door.spaces[1], door.spaces[0])
            found.append(DoorwayCrossing(int(i + 1), float(t[i + 1]), (float(x), float(y)), door.id, src, dst))
    found.sort(key=lambda c: c.scan)
    return found
