"""Routes through a floor plan, sampled into the poses at which scans are taken.

The robot is a differential drive (the thesis's Pioneer 3-DX): it drives
straight between waypoints and turns on the spot at them. That matches how
Albot1 was guided in all the thesis's experiments (``move 1 m`` / ``turn 45
deg`` commands, or arrow keys), and it makes every scan pose exact and
reproducible, with no controller in the loop.

A :class:`Sampling` says when a scan is taken:

- continuous motion, as the thesis's Experiment 4 logger: a scan every
  0.1 m of translation or 1 degree of rotation (``CONTINUOUS``);
- start-stop, as Experiments 1-3: a scan after every 1 m move or 45 degree
  turn (``START_STOP``), with a dwell while the robot stands still to scan;
  at Experiment 5's spacing, 1 m or 10 degrees (``START_STOP_10DEG``).

Each move or turn is cut into full steps plus one shorter remainder step, so
the steps are exactly the commanded size (a straight 5.5 m leg in start-stop
mode is five 1 m steps and one 0.5 m step), as a robot commanded in fixed
increments would move. A closed route ends with a turn back to its starting
heading, so its last pose equals its first pose exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from albot1.data.synthetic.errors import SyntheticWorldError
from albot1.geometry import se2
from albot1.geometry.types import FloatArray

# Legs or turns shorter than this are rounding noise, not motion.
_TINY = 1e-9


@dataclass(frozen=True)
class Sampling:
    """Scan spacing: one scan per ``step_m`` of travel or ``step_deg`` of turning."""

    step_m: float
    step_deg: float
    speed_mps: float = 0.5
    turn_rate_dps: float = 45.0
    dwell_s: float = 0.0

    def __post_init__(self) -> None:
        for field, value in (
            ("step_m", self.step_m),
            ("step_deg", self.step_deg),
            ("speed_mps", self.speed_mps),
            ("turn_rate_dps", self.turn_rate_dps),
        ):
            if not (math.isfinite(value) and value > 0):
                raise SyntheticWorldError(f"sampling: expected a positive finite {field}, got {value}")
        if not (math.isfinite(self.dwell_s) and self.dwell_s >= 0):
            raise SyntheticWorldError(f"sampling: expected dwell_s >= 0, got {self.dwell_s}")


CONTINUOUS = Sampling(step_m=0.1, step_deg=1.0)
START_STOP = Sampling(step_m=1.0, step_deg=45.0, dwell_s=1.0)
#: Experiment 5's view spacing (a view every 1 m or 10 deg), driven start-stop.
START_STOP_10DEG = Sampling(step_m=1.0, step_deg=10.0, dwell_s=1.0)


@dataclass(frozen=True)
class Route:
    """Waypoints ``(K, 2)`` driven in order; ``closed`` routes end where (and as) they started.

    ``start_heading`` (rad) defaults to facing the second waypoint;
    ``end_heading`` (rad) is an optional final turn of an open route.
    """

    waypoints: tuple[tuple[float, float], ...]
    closed: bool = False
    start_heading: float | None = None
    end_heading: float | None = None

    def __post_init__(self) -> None:
        if len(self.waypoints) < 2:
            raise SyntheticWorldError(f"route: expected at least 2 waypoints, got {len(self.waypoints)}")
        if self.closed and self.waypoints[0] != self.waypoints[-1]:
            raise SyntheticWorldError(
                f"route: a closed route must end at its first waypoint {self.waypoints[0]}, not {self.waypoints[-1]}"
            )
        for i, (a, b) in enumerate(zip(self.waypoints[:-1], self.waypoints[1:], strict=True)):
            if math.hypot(b[0] - a[0], b[1] - a[1]) <= _TINY:
                raise SyntheticWorldError(f"route: waypoints {i} and {i + 1} coincide at {a}; legs must have length")

    @property
    def length(self) -> float:
        w = np.asarray(self.waypoints, dtype=float)
        return float(np.sum(np.hypot(np.diff(w[:, 0]), np.diff(w[:, 1]))))


def start_at(route: Route, waypoint: int) -> Route:
    """The same closed loop driven from ``route.waypoints[waypoint]`` (facing the waypoint after it).

    Chapter 4's first experiment repeats one loop from three start points; the
    loop is the same, only where it is cut open changes.
    """
    if not route.closed:
        raise SyntheticWorldError("route: only a closed route can start at another waypoint")
    last = len(route.waypoints) - 1
    if not 0 <= waypoint < last:
        raise SyntheticWorldError(f"route: start waypoint {waypoint} is not one of the loop's 0..{last - 1}")
    if waypoint == 0:
        return route
    w = route.waypoints
    return Route(waypoints=(*w[waypoint:], *w[1 : waypoint + 1]), closed=True)


def sample(route: Route, sampling: Sampling) -> FloatArray:
    """The scan poses ``(N, 3)`` along ``route``: the start pose, then one per step."""
    w = np.asarray(route.waypoints, dtype=float)
    headings = np.arctan2(np.diff(w[:, 1]), np.diff(w[:, 0]))
    start = float(headings[0] if route.start_heading is None else route.start_heading)
    poses = [np.array([w[0, 0], w[0, 1], float(se2.wrap(start))])]
    step_rad = math.radians(sampling.step_deg)
    heading = start
    for leg, target in enumerate(headings):
        heading = _turn(poses, heading, float(target), step_rad)
        _drive(poses, w[leg], w[leg + 1], step=sampling.step_m)
    final = start if route.closed else route.end_heading
    if final is not None:
        _turn(poses, heading, float(final), step_rad)
        if route.closed:
            poses[-1] = poses[0].copy()  # exact closure, free of accumulated rounding
    return np.vstack(poses)


def _turn(poses: list[FloatArray], heading: float, target: float, step_rad: float) -> float:
    """Append the poses of an on-the-spot turn by the shortest way (a half turn goes clockwise)."""
    delta = float(se2.wrap(target - heading))
    x, y = poses[-1][0], poses[-1][1]
    parts = _increments(abs(delta), step_rad)
    turned = 0.0
    for k, angle in enumerate(parts):
        turned += angle
        now = heading + delta if k == len(parts) - 1 else heading + math.copysign(turned, delta)
        poses.append(np.array([x, y, float(se2.wrap(now))]))
    return heading + delta


def _drive(poses: list[FloatArray], a: FloatArray, b: FloatArray, *, step: float) -> None:
    """Append the poses of a straight move from ``a`` to ``b`` (heading unchanged)."""
    length = float(np.hypot(*(b - a)))
    theta = poses[-1][2]
    travelled = 0.0
    for inc in _increments(length, step):
        travelled += inc
        point = b if abs(travelled - length) <= _TINY else a + (b - a) * (travelled / length)
        poses.append(np.array([point[0], point[1], theta]))


def _increments(total: float, step: float) -> list[float]:
    """``total`` cut into full ``step``s and one shorter remainder (none if ``total`` is ~0)."""
    if total <= _TINY:
        return []
    full = int(math.floor(total / step + _TINY))
    parts = [step] * full
    rest = total - full * step
    if rest > _TINY:
        parts.append(rest)
    elif parts:
        parts[-1] += rest  # absorb a rounding residue so the parts sum to total
    return parts


def timestamps(poses: ArrayLike, sampling: Sampling, *, start: float = 0.0) -> FloatArray:
    """Scan times from constant driving and turning speeds (plus the dwell of each stop).

    Each step takes the longer of its travel time and its turn time, so the
    times are strictly increasing whenever consecutive poses differ.
    """
    steps = se2.relative_steps(poses)
    travel = np.hypot(steps[:, 0], steps[:, 1]) / sampling.speed_mps
    turn = np.abs(steps[:, 2]) / math.radians(sampling.turn_rate_dps)
    dt = np.maximum(travel, turn) + sampling.dwell_s
    return start + np.concatenate([[0.0], np.cumsum(dt)])


def repeat_laps(poses: ArrayLike, laps: int) -> FloatArray:
    """A closed lap's poses driven ``laps`` times (the shared start/end pose appears once between laps)."""
    p = np.asarray(poses, dtype=float)
    if laps < 1:
        raise SyntheticWorldError(f"route: expected at least 1 lap, got {laps}")
    if laps == 1:
        return p.copy()
    if not np.array_equal(p[0], p[-1]):
        raise SyntheticWorldError("route: only a closed route (last pose == first pose) can be driven in laps")
    return np.vstack([np.tile(p[:-1], (laps, 1)), p[-1:]])
