"""Where the laser sits on the robot, read from a bag's ``/tf_static`` (else ``/tf``).

A LaserScan is measured in its header's frame (``laser``); odometry moves the
robot's base frame (``base_link``). When the laser is mounted away from the
base, treating the scan as if taken at the base bends every map, so the
transform ``base -> laser`` becomes the sequence's ``sensor_offset``
(x, y, yaw), which the runner applies once for every method
(:func:`albot1.data.transforms.sensor_frame`).

The chain is walked up from the laser frame through the transforms' parent
links (``base_link -> laser_mount -> laser`` composes in 3D, then is
projected onto the plane) until the base frame: the named or odometry's
child frame, else the frame whose parent is ``odom_frame``, else the root of
the tree. ``/tf_static`` is preferred; ``/tf`` is read only when the static
tree does not reach the laser (older bags publish mounts on ``/tf``), adding
the links the static tree lacks and taking each link's first transform (a
mount is rigid). Odometry on ``/tf`` names its base as an Odometry topic does
(the child of ``odom_frame``), so a laser tree that does not reach it gets
the same warning, never an unrelated root's mount. A laser mounted upside
down (its z axis within :data:`MAX_TILT_DEG` of the base's -z, a roll or
pitch of pi, as many robots carry a Hokuyo under a plate) still scans the
base's plane, but its y axis points to the base's right: a beam at angle
``a`` of the scan lies at ``-a`` in the plane. Its mount is the (x, y, yaw)
of its x axis and ``mirrored`` is set, for the loader to mirror each scan's
beam angles (``msg.scan_arrays``); such a mount used to be refused, so no
bag of such a robot could be read. A laser tilted more than
:data:`MAX_TILT_DEG` from both (looking at the floor) cannot be put on the
plane and is refused. When no transform is found the offset is zero and the
result says so; the loader logs it as a warning and records it in the metadata.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from albot1.data.errors import DataError, ParseError
from albot1.data.loaders.rosbag.msg import quaternion_problem
from albot1.data.loaders.rosbag.reader import topic_messages
from albot1.data.loaders.rosbag.topics import TF_MESSAGE, TopicChoice, TopicInfo

if TYPE_CHECKING:
    from collections.abc import Mapping

    from rosbags.highlevel import AnyReader
    from scipy.spatial.transform import Rotation

log = logging.getLogger(__name__)

#: Largest angle (degrees) between the laser's z axis and the base's for which the scan is taken as planar.
MAX_TILT_DEG = 5.0
STATIC_TOPIC = "/tf_static"
DYNAMIC_TOPIC = "/tf"


@dataclass(frozen=True)
class Mounting:
    """The laser's planar offset on the base and where it came from (``found`` False: assumed zero)."""

    offset: tuple[float, float, float]
    found: bool
    note: str
    #: mounted upside down: beam angle ``a`` of a scan lies at ``-a`` in the base's plane
    mirrored: bool = False


@dataclass(frozen=True)
class _Link:
    parent: str
    translation: np.ndarray
    rotation: Rotation


def _first_frame_id(reader: AnyReader, topic: str, shown: Path) -> str:
    for _, msg in topic_messages(reader, topic, shown):
        return str(msg.header.frame_id).lstrip("/")
    return ""


def odometry_child_frame(reader: AnyReader, topic: str, shown: Path) -> str | None:
    """The ``child_frame_id`` of an Odometry topic's first message (the robot's base), or None if empty."""
    for _, msg in topic_messages(reader, topic, shown):
        child = str(msg.child_frame_id).lstrip("/")
        return child or None
    return None


def tf_child_frame(reader: AnyReader, topic: str, odom_frame: str, shown: Path) -> str | None:
    """The child of the first ``odom_frame -> child`` transform on a TFMessage topic (the robot's base), or None.

    What :func:`odometry_child_frame` is for a ``nav_msgs/Odometry`` topic:
    odometry read from ``/tf`` moves this frame, so the mount is looked up
    from it, not from whatever root the laser's tree happens to have.
    """
    for _, msg in topic_messages(reader, topic, shown):
        for tf in msg.transforms:
            if str(tf.header.frame_id).lstrip("/") == odom_frame:
                return str(tf.child_frame_id).lstrip("/") or None
    return None


def _links(reader: AnyReader, topic: str, shown: Path) -> dict[str, _Link]:
    """``child -> first transform from its parent`` of a TFMessage topic."""
    from scipy.spatial.transform import Rotation  # imported here: ~0.2 s that importing the loader (tests, CLI) skips

    links: dict[str, _Link] = {}
    for i, msg in topic_messages(reader, topic, shown):
        for tf in msg.transforms:
            child = str(tf.child_frame_id).lstrip("/")
            if child in links:
                continue
            t, q = tf.transform.translation, tf.transform.rotation
            quaternion = (float(q.x), float(q.y), float(q.z), float(q.w))
            translation = np.array([float(t.x), float(t.y), float(t.z)])
            problem = quaternion_problem(*quaternion)
            if problem is not None or not np.isfinite(translation).all():
                what = problem or f"translation {translation.tolist()}, expected finite numbers"
                raise ParseError(shown, f"topic {topic} ({tf.header.frame_id} -> {child}): {what}", index=i)
            links[child] = _Link(str(tf.header.frame_id).lstrip("/"), translation, Rotation.from_quat(quaternion))
    return links


def _chain(links: Mapping[str, _Link], laser: str, base: str | None, odom_frame: str) -> list[_Link] | None:
    """The links from the base down to ``laser`` (base first; empty when ``laser`` is the base), or None.

    None: ``base`` is not above the laser (or, with no base named, the laser
    has no parent at all, or the links loop).
    """
    path: list[_Link] = []
    frame, seen = laser, {laser}
    while frame != base:
        link = links.get(frame)
        if link is None:  # the root of the tree: the base when none is named and the laser hangs below it
            return path[::-1] if base is None and path else None
        if base is None and link.parent == odom_frame:
            return path[::-1]  # frame is the base: odometry moves it
        path.append(link)
        frame = link.parent
        if frame in seen:
            return None
        seen.add(frame)
    return path[::-1]


def _planar(path: list[_Link], laser: str, base: str, shown: Path) -> tuple[tuple[float, float, float], bool]:
    """The (x, y, yaw) of the laser on the base's plane, and whether it is mounted upside down (mirrored)."""
    from scipy.spatial.transform import Rotation

    translation, rotation = np.zeros(3), Rotation.identity()
    for link in path:
        translation = translation + rotation.apply(link.translation)
        rotation = rotation * link.rotation
    z_axis = rotation.apply([0.0, 0.0, 1.0])
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, float(z_axis[2])))))
    mirrored = tilt >= 180.0 - MAX_TILT_DEG
    if MAX_TILT_DEG < tilt < 180.0 - MAX_TILT_DEG:
        raise DataError(
            f"{shown}: the laser frame {laser!r} is tilted {tilt:.1f} deg from the base frame {base!r} "
            f"(not level); expected at most {MAX_TILT_DEG} deg (or upside down within {MAX_TILT_DEG} deg), as a "
            f"2D scan is taken in the base's plane"
        )
    x_axis = rotation.apply([1.0, 0.0, 0.0])
    yaw = math.atan2(float(x_axis[1]), float(x_axis[0]))
    return (float(translation[0]), float(translation[1]), yaw), mirrored


def read_mounting(
    reader: AnyReader,
    topics: Mapping[str, TopicInfo],
    scan_topic: str,
    base_frame: str | None,
    odom_frame: str,
    shown: Path,
) -> Mounting:
    """The ``base -> laser`` offset of a bag (see the module docstring for the search rules)."""
    laser = _first_frame_id(reader, scan_topic, shown)
    if not laser:
        return Mounting((0.0, 0.0, 0.0), False, f"{scan_topic} has no header frame_id, so no laser mount to look up")
    if laser == base_frame:
        return Mounting((0.0, 0.0, 0.0), True, f"the scans' frame {laser!r} is the base frame")
    searched: list[str] = []
    links: dict[str, _Link] = {}
    for topic in (STATIC_TOPIC, DYNAMIC_TOPIC):
        if topics.get(topic, TopicInfo("", 0)).msgtype != TF_MESSAGE:
            continue
        searched.append(topic)
        # /tf adds the links /tf_static lacks (a tree split over both: odom -> base_footprint -> base_link on
        # /tf, base_link -> laser static); a link both publish keeps its static transform.
        links = {**_links(reader, topic, shown), **links}
        path = _chain(links, laser, base_frame, odom_frame)
        where = " + ".join(searched)
        if path is not None and not path:
            return Mounting((0.0, 0.0, 0.0), True, f"the scans' frame {laser!r} is the base frame ({where})")
        if path is not None:
            base = base_frame or path[0].parent
            offset, mirrored = _planar(path, laser, base, shown)
            shown_offset = ", ".join(f"{v:.6g}" for v in offset)
            flipped = "; mounted upside down: beam angles mirrored (a -> -a)" if mirrored else ""
            note = f"{where} {base} -> {laser}: (x, y, yaw) = ({shown_offset}){flipped}"
            return Mounting(offset, True, note, mirrored)
    where = " or ".join(searched) if searched else "the bag (it has no /tf_static or /tf topic)"
    base = base_frame or "the base frame"
    return Mounting(
        (0.0, 0.0, 0.0),
        False,
        f"no transform {base} -> {laser!r} (the scans' frame) in {where}; the laser is taken to sit at the base's "
        f"origin (sensor_offset 0)",
    )


def bag_mounting(
    reader: AnyReader,
    shown: Path,
    topics: Mapping[str, TopicInfo],
    choice: TopicChoice,
    base_frame: str | None,
    odom_frame: str,
) -> Mounting:
    """:func:`read_mounting` for a bag with chosen topics; the base frame defaults to the frame odometry moves
    (an Odometry topic's child frame, or the child of ``odom_frame`` on ``/tf``).

    ``reader`` is the bag opened by the caller, which read its topics from it (one opening, not two).
    A missing mount is logged as a warning (and the caller records the note in the sequence metadata).
    """
    if base_frame is None:
        base_frame = (
            tf_child_frame(reader, choice.odom, odom_frame, shown)
            if choice.odom_is_tf
            else odometry_child_frame(reader, choice.odom, shown)
        )
    mounting = read_mounting(reader, topics, choice.scan, base_frame, odom_frame, shown)
    if not mounting.found:
        log.warning("%s: %s", shown, mounting.note)
    return mounting
