"""Beam geometry and no-return rules of CARMEN scans (pure functions, no I/O).

FLASER/RLASER lines carry only ranges, so their geometry comes from PARAM
lines when the logger wrote them, else from documented defaults by beam count
(the conventions of the Radish/Freiburg logs, which were recorded with SICK
LMS 2xx scanners covering 180 degrees):

=========  ===================  ====================================
beams      angle step           beams at
=========  ===================  ====================================
180        1 deg                -90, -89, ..., +89 deg
360        0.5 deg              -90, -89.5, ..., +89.5 deg
181, 361   180/(n-1) deg        -90 ... +90 deg (both ends included)
other n    180/(n-1) deg        -90 ... +90 deg
=========  ===================  ====================================

A beam count other than 180, 181, 360, 361 without PARAM geometry is
probably not a SICK LMS 2xx: the default still applies (as in CARMEN) and
the loader warns when the log's first laser line is such a line (:func:`first_line_notes`).

PARAM lines that override the defaults (front laser; ``rear`` for RLASER):
``laser_front_laser_resolution`` / ``laser_frontlaser_resolution`` (degrees),
``laser_front_laser_fov`` (degrees, or radians when <= 2*pi as in the CSAIL
log), ``robot_front_laser_max`` (metres), ``robot_frontlaser_offset``
(metres forward of the robot centre). Their values must be numbers in range
(:func:`param_problem`, checked by the parser at the PARAM line): a value
that cannot be used is an error, never silently replaced by a default.

No-return rule: a reading ``r >= max_range - 0.005`` (half the 1 cm
resolution of the logs, so a value printed as the maximum counts) or
``r == 0`` becomes NaN. Negative and non-finite readings are parse errors.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from albot1.data.loaders.beams import seam_note, seam_repeat
from albot1.data.model import MAX_MOUNT_M
from albot1.geometry.types import FloatArray

#: SICK LMS 2xx maximum (8191 cm is its "no echo" code); used when a log states no maximum.
DEFAULT_MAX_RANGE = 81.9
NO_RETURN_MARGIN = 0.005


@dataclass(frozen=True, slots=True)
class BeamGeometry:
    """First beam angle and step (radians, CCW, 0 = forward) and the sensor's max range (m)."""

    start: float
    step: float
    max_range: float
    source: str


#: Beam counts of a 180-degree SICK LMS 2xx at 1 and 0.5 deg, which CARMEN's defaults describe. A FLASER line
#: of another count without PARAM geometry gets the same 180-degree spread, but it is likely another scanner
#: (a 270-degree Hokuyo's 1081 readings, a 360-degree scanner's 1440), so the loader warns.
SICK_BEAM_COUNTS = (180, 181, 360, 361)


def guessed_geometry_note(source: object, laser: str, beams: int) -> str:
    """The warning for FLASER/RLASER lines whose beam count CARMEN's defaults do not describe (once per load)."""
    which = "rear" if laser == "RLASER" else "front"
    return (
        f"{source}: {laser} lines of {beams} readings and no PARAM laser_{which}_laser_fov or "
        f"laser_{which}_laser_resolution before them: their beams are taken to span -90..+90 deg (CARMEN's "
        f"default, made for a 180-degree SICK LMS 2xx, which gives {', '.join(map(str, SICK_BEAM_COUNTS))} "
        f"readings); a scanner with another field of view needs those PARAM lines (or ROBOTLASER1 lines)"
    )


def first_line_notes(
    where: str, laser: str, beams: int, start: float | None, step: float | None, params: dict[str, str]
) -> list[str]:
    """The warnings the log's first laser line calls for: a FLASER/RLASER beam count CARMEN's defaults do not
    describe, a 360-degree scan whose last beam repeats its first (:func:`seam_repeat`).

    Said by the loader when it opens the log (from its head, :mod:`.probe`), not
    while frames stream: decoded frames are cached (:mod:`albot1.data.decoded`)
    and a cached read decodes nothing, so a warning logged while streaming
    would be lost. ``start``/``step``: the line's own geometry (ROBOTLASER1,
    RAWLASER), None for FLASER/RLASER, whose geometry comes from ``params``.
    """
    notes = []
    if start is None or step is None:
        geometry = param_geometry(beams, params, rear=laser == "RLASER")
        start, step = geometry.start, geometry.step
        if geometry.source.startswith("default") and beams not in SICK_BEAM_COUNTS:
            notes.append(guessed_geometry_note(where, laser, beams))
    if seam_repeat(beam_angles(beams, start, step)):
        notes.append(seam_note(where, laser, beams))
    return notes


def default_geometry(beams: int) -> tuple[float, float]:
    """``(start, step)`` in radians for a FLASER line of ``beams`` readings without PARAM hints."""
    if beams in (180, 360):
        return -math.pi / 2, math.pi / beams
    return -math.pi / 2, math.pi / max(beams - 1, 1)


def mount_params(rear: bool = False) -> tuple[str, str, str]:
    """The PARAM names that state the front (or rear) laser's mount: its offset, side and angular parts."""
    which = "rear" if rear else "front"
    return f"robot_{which}laser_offset", f"robot_{which}laser_side_offset", f"robot_{which}laser_angular_offset"


def _param_rules() -> dict[str, tuple[str, Callable[[float], bool]]]:
    """PARAM names this module interprets -> (what the value must be, its test). Other PARAMs are free text."""
    angle = ("an angle between beams in degrees, > 0 and <= 360", lambda v: 0 < v <= 360)
    fov = ("a field of view > 0 and <= 360 degrees (or <= 2 pi radians)", lambda v: 0 < v <= 360)
    rules: dict[str, tuple[str, Callable[[float], bool]]] = {}
    for which in ("front", "rear"):
        rules[f"laser_{which}_laser_resolution"] = rules[f"laser_{which}laser_resolution"] = angle
        rules[f"laser_{which}_laser_fov"] = rules[f"laser_{which}laser_fov"] = fov
        rules[f"robot_{which}_laser_max"] = ("a maximum range in metres, > 0", lambda v: v > 0)
        offset, side, angular = mount_params(rear=which == "rear")
        # the combined mount is held to MAX_MOUNT_M again when the log is opened (data/finite.py)
        mount = (f"an offset in metres, at most {MAX_MOUNT_M:g} m (metres on a robot)", lambda v: abs(v) <= MAX_MOUNT_M)
        rules[offset] = rules[side] = mount
        rules[angular] = ("an angle in radians", lambda v: True)
    return rules


_PARAM_RULES = _param_rules()


def param_problem(name: str, value: str) -> str | None:
    """Why a PARAM value this loader interprets cannot be used (None if it can, or if the name is free text)."""
    rule = _PARAM_RULES.get(name)
    if rule is None:
        return None
    meaning, accept = rule
    try:
        number = float(value)
    except ValueError:
        number = math.nan
    if math.isfinite(number) and accept(number):
        return None
    return f"PARAM {name} is {value[:40]!r}, expected {meaning}"


def _number(params: dict[str, str], *names: str) -> float | None:
    """The first of ``names`` that is set (values were checked by :func:`param_problem` when parsed)."""
    for name in names:
        if name in params:
            return float(params[name])
    return None


def param_geometry(beams: int, params: dict[str, str], rear: bool = False) -> BeamGeometry:
    """Geometry of an old-style laser line from PARAM values seen so far, else the defaults."""
    which = "rear" if rear else "front"
    start, step = default_geometry(beams)
    source = f"default for {beams} beams"
    resolution = _number(params, f"laser_{which}_laser_resolution", f"laser_{which}laser_resolution")
    fov = _number(params, f"laser_{which}_laser_fov", f"laser_{which}laser_fov")
    if fov is not None:
        fov_rad = fov if fov <= 2 * math.pi + 1e-6 else math.radians(fov)
        start = -fov_rad / 2
        step = fov_rad / max(beams - 1, 1) if resolution is None else step
        source = "PARAM fov"
    if resolution is not None:
        step = math.radians(resolution)
        source = "PARAM resolution" if fov is None else "PARAM fov+resolution"
    max_range = _number(params, f"robot_{which}_laser_max")
    return BeamGeometry(start, step, max_range if max_range is not None else DEFAULT_MAX_RANGE, source)


def states_mount(params: dict[str, str], rear: bool = False) -> bool:
    """Whether the log's PARAM lines state the front (or rear) laser's mount (any of its parts)."""
    return any(name in params for name in mount_params(rear))


def mount_change_problem(
    params: dict[str, str], name: str, value: str, mount: tuple[float, float, float], rear: bool = False
) -> str | None:
    """Why a PARAM line after the first scan that moves the laser off ``mount`` cannot be read (None if it can).

    A sequence has one ``sensor_offset`` (``mount``, what the loader placed
    every scan with); a log whose mount PARAM changes part way (two
    recordings joined, a parameter changed while logging) would have every
    scan on one side of the change placed with the other side's mount.
    ``params`` holds the values in effect before this line. The line is
    compared with the mount it implies, not with the previous value: a
    logger repeating its parameters is no change, and a part first stated
    after the log's head (which the loader read the mount from) is one when
    it differs from the 0 the loader took for it. The caller asks only for
    PARAM lines after the first scan: a PARAM block before it may restate a
    name (belgioioso-corrected: 0.0, then -0.04), the last value counting.
    """
    if name not in mount_params(rear):
        return None
    implied = sensor_offset({**params, name: value}, rear=rear)
    if implied == mount:
        return None
    before = f"from {params[name]}" if name in params else "(not stated before it: 0)"
    shown, used = (", ".join(f"{v:.6g}" for v in pose) for pose in (implied, mount))
    return (
        f"PARAM {name} changes {before} to {value}; expected one laser mount for the whole log: it puts the laser "
        f"at ({shown}) (x m, y m, yaw rad) on the robot, the scans were placed with ({used}) (a sequence has one "
        f"sensor_offset, so the scans on one side of this line would be placed with the other side's mount): split "
        f"the log at this line and load each part"
    )


def sensor_offset(params: dict[str, str], rear: bool = False) -> tuple[float, float, float]:
    """Laser pose in the robot frame from PARAM ``robot_frontlaser_offset`` (and side/angular, if logged).

    CARMEN's rear laser looks backwards: its robot module writes an RLASER line's laser pose as
    ``theta = odom_theta + pi``, ``x = odom_x + offset * cos(theta)`` (``robot_laser.c``,
    ``construct_laser_message``), so ``robot_rearlaser_offset`` is measured along the rear laser's own
    heading. Its mount is therefore the rear PARAMs composed after a half turn, ``(-offset, -side, pi +
    angular)``; taken as ``(offset, side, angular)`` every rear scan was placed facing forwards (a map
    mirrored front to back).
    """
    x, y, theta = (float(params.get(name, "0")) for name in mount_params(rear))  # checked by param_problem
    if not rear:
        return x, y, theta
    return 0.0 - x, 0.0 - y, math.remainder(math.pi + theta, 2 * math.pi)


_ANGLE_CACHE: dict[tuple[int, float, float], FloatArray] = {}


def beam_angles(beams: int, start: float, step: float) -> FloatArray:
    """Read-only angle array, shared between scans with the same geometry."""
    key = (beams, start, step)
    angles = _ANGLE_CACHE.get(key)
    if angles is None:
        if len(_ANGLE_CACHE) > 256:
            _ANGLE_CACHE.clear()
        angles = start + step * np.arange(beams, dtype=np.float64)
        angles.flags.writeable = False
        _ANGLE_CACHE[key] = angles
    return angles


def clean_block(ranges: FloatArray, max_range: FloatArray) -> FloatArray:
    """A copy of a ``(k, n)`` block (one max range per row) with max-range and zero readings as NaN
    (the no-return rule above), in one numpy pass."""
    out = ranges.copy()
    out[(out >= (max_range - NO_RETURN_MARGIN)[:, None]) | (out == 0.0)] = np.nan
    return out
