"""ROS1 and ROS2 (sqlite3, MCAP) bags -> a streamed Sequence, through ``rosbags``.

What is read:

* scans: ``sensor_msgs/LaserScan`` of one topic, at their *header* stamps
  (the time the scan was taken, not when the recorder received it);
* odometry: ``nav_msgs/Odometry`` of one topic, or the ``odom_frame ->
  base_frame`` transforms of ``/tf``, read in a first pass over that topic
  only and SE(2)-interpolated to each scan stamp;
* reference (optional): the ``nav_msgs/Odometry`` topic named by
  ``reference_topic`` (e.g. simulator ground truth), else ``/ground_truth``
  when present (the layout ``albot1 convert`` writes), interpolated the same
  way. Topic choice rules live in :mod:`.rosbag_topics`;
* the laser's mount on the base (``metadata.sensor_offset``) from
  ``/tf_static`` (else ``/tf``), a warning when absent: :mod:`.mounting`.

A scan outside the odometry (or reference) time span is an error by default
because extrapolating a pose would invent data; ``outside_odometry="drop"``
skips such scans and logs how many. Scans stream: the bag is not decoded
before the first frame is yielded. ``rosbags`` is imported lazily.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from albot1.data.errors import DataError, ParseError, TopicError
from albot1.data.loaders.base import (
    DEFAULT_MAX_POSE_GAP_S,
    max_pose_gap,
    option_names,
    pose_gap_problem,
    reference_keyword_problem,
    unknown_option_hint,
)
from albot1.data.loaders.beams import seam_note
from albot1.data.loaders.rosbag.bag1_check import version_problem
from albot1.data.loaders.rosbag.mounting import bag_mounting
from albot1.data.loaders.rosbag.msg import PoseTrack, laserscan_problem, reading_problem, scan_arrays
from albot1.data.loaders.rosbag.reader import header_stamp, odometry_track, opened_bag, tf_track, topic_messages
from albot1.data.loaders.rosbag.topics import LASER_SCAN, TopicChoice, TopicInfo, choose_topics, normalize_type
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata

if TYPE_CHECKING:
    from rosbags.highlevel import AnyReader

log = logging.getLogger(__name__)

_OPTIONS = (
    "scan_topic",
    "odom_topic",
    "reference_topic",
    "odom_frame",
    "base_frame",
    "outside_odometry",
    "max_pose_gap",
)
_OUTSIDE = ("error", "drop")


@dataclass
class _BagSource:
    """One bag with its chosen topics; reads the pose tracks once, streams the scans each pass."""

    bag: Path
    shown: Path
    choice: TopicChoice
    odom_frame: str
    base_frame: str | None
    outside: str
    #: largest gap (s) between the two pose messages a scan's pose is interpolated between (loaders/base.py)
    max_gap: float = DEFAULT_MAX_POSE_GAP_S
    #: the laser is mounted upside down (mounting.Mounting.mirrored): every scan's beam angles are mirrored
    mirrored: bool = False

    def __post_init__(self) -> None:
        self._tracks: tuple[PoseTrack, PoseTrack | None] | None = None
        self._seam_said = False

    def tracks(self, reader: AnyReader) -> tuple[PoseTrack, PoseTrack | None]:
        """The odometry and reference tracks, read from ``reader`` (the pass's open bag) on the first pass only."""
        if self._tracks is None:
            if self.choice.odom_is_tf:
                odom = tf_track(reader, self.choice.odom, self.odom_frame, self.base_frame, self.shown)
            else:
                odom = odometry_track(reader, self.choice.odom, self.shown)
            ref = odometry_track(reader, self.choice.reference, self.shown) if self.choice.reference else None
            self._tracks = (odom, ref)
        return self._tracks

    def _outside(self, index: int, t: float, track: PoseTrack, topic: str) -> None:
        if self.outside == "error":
            raise ParseError(
                self.shown,
                f"topic {self.choice.scan}: scan stamp {t:.9f} s is outside the time span "
                f"[{track.start:.9f}, {track.end:.9f}] s of {topic}; poses are never extrapolated "
                f"(load with outside_odometry='drop' to skip such scans)",
                index=index,
            )

    def _check_gap(self, index: int, t: float, track: PoseTrack, topic: str) -> None:
        problem = pose_gap_problem(t, *track.bracket(t), self.max_gap, f"messages of {topic}")
        if problem is not None:
            raise ParseError(self.shown, f"topic {self.choice.scan}: {problem}", index=index)

    def frames(self) -> Iterator[Frame]:
        """One pass over the scans; the bag is opened once for it (opening parses its index: most of a small
        bag's load), and the pose tracks are read in that same opening on the first pass."""
        topic = self.choice.scan
        out, dropped, last = 0, 0, -math.inf
        first_frame: str | None = None
        with opened_bag(self.bag, self.shown) as reader:
            odom, ref = self.tracks(reader)
            for i, msg in topic_messages(reader, topic, self.shown):
                t = header_stamp(msg)
                frame_id = str(msg.header.frame_id).lstrip("/")
                if first_frame is None:
                    first_frame = frame_id
                elif frame_id != first_frame:
                    # two lasers publishing on one topic: one mount (the first scan's frame's) would place both
                    raise ParseError(
                        self.shown,
                        f"topic {topic}: scan in frame {frame_id!r}, but the topic's first scan is in frame "
                        f"{first_frame!r}; expected one laser per topic (the laser's mount is read for one frame; "
                        f"two lasers publishing on one topic cannot be told apart by time)",
                        index=i,
                    )
                if t < last:
                    raise ParseError(
                        self.shown,
                        f"topic {topic}: scan stamp {t:.9f} s is earlier than the previous "
                        f"scan's {last:.9f} s; scans must be in time order",
                        index=i,
                    )
                last = t
                pose = odom.at(t)
                if pose is None:
                    self._outside(i, t, odom, self.choice.odom)
                    dropped += 1
                    continue
                self._check_gap(i, t, odom, self.choice.odom)
                reference = None
                if ref is not None:
                    reference = ref.at(t)
                    if reference is None:
                        self._outside(i, t, ref, str(self.choice.reference))
                        dropped += 1
                        continue
                    self._check_gap(i, t, ref, str(self.choice.reference))
                yield Frame(out, self._scan(msg, t, i), pose, reference)
                out += 1
        if dropped:
            log.warning("%s: dropped %d scans of %s outside the pose time span", self.shown, dropped, topic)
        if out == 0 and dropped:
            raise DataError(
                f"{self.shown}: all {dropped} scans of {topic} lie outside the pose time span "
                f"(outside_odometry='drop' left none); expected scans stamped within the odometry"
                f"{' and reference' if ref is not None else ''} messages"
            )

    def _scan(self, msg: Any, t: float, index: int) -> Scan:
        geometry = (float(msg.angle_min), float(msg.angle_increment), float(msg.range_min), float(msg.range_max))
        n = len(msg.ranges)
        problem = laserscan_problem(n, geometry[0], float(msg.angle_max), *geometry[1:])
        raw = np.asarray(msg.ranges)
        if problem is None:
            problem = reading_problem(raw, geometry[2], geometry[3])
        if problem is not None:
            raise ParseError(self.shown, f"topic {self.choice.scan}: LaserScan {problem}", index=index)
        ranges, angles = scan_arrays(raw, *geometry, mirrored=self.mirrored)
        if ranges.shape[0] < n and not self._seam_said:
            self._seam_said = True
            log.warning(seam_note(str(self.shown), f"topic {self.choice.scan} (message #{index})", n))
        return Scan(ranges=ranges, angles=angles, timestamp=t, max_range=geometry[3])


def _options(options: dict[str, Any], shown: Path) -> dict[str, Any]:
    keyword = reference_keyword_problem(options, "a bag")
    if keyword is not None:
        raise DataError(f"{shown}: {keyword}")
    unknown = sorted(k for k, v in options.items() if k not in _OPTIONS and v is not None)
    if unknown:
        raise DataError(
            f"{shown}: unknown bag option(s) {', '.join(unknown)}; expected: {', '.join(option_names(_OPTIONS))}"
            f"{unknown_option_hint(unknown, option_names(_OPTIONS))}"
        )
    opts = {k: options.get(k) for k in _OPTIONS}
    opts["outside_odometry"] = opts["outside_odometry"] or "error"
    if opts["outside_odometry"] not in _OUTSIDE:
        raise DataError(
            f"{shown}: outside_odometry={opts['outside_odometry']!r}; expected one of {', '.join(_OUTSIDE)}"
        )
    opts["odom_frame"] = opts["odom_frame"] or "odom"
    opts["max_pose_gap"] = max_pose_gap(opts["max_pose_gap"], shown)
    return opts


def _load_bag(bag: Path, shown: Path, name: str, format_name: str, options: dict[str, Any]) -> Sequence:
    opts = _options(options, shown)
    # One opening for the topics and the laser's mount: opening parses the bag's index (a ROS2 bag's
    # metadata.yaml), most of what loading a small bag costs; the scans' passes open it again, once each.
    with opened_bag(bag, shown) as reader:
        topics = {
            name_: TopicInfo(normalize_type(info.msgtype or "?"), int(info.msgcount))
            for name_, info in reader.topics.items()
        }
        choice = choose_topics(shown, topics, opts["scan_topic"], opts["odom_topic"], opts["reference_topic"])
        for topic, role in ((choice.scan, "scans"), (choice.odom, "odometry"), (choice.reference, "reference poses")):
            if topic is not None and topics[topic].count == 0:
                raise TopicError(f"{shown}: topic {topic} ({role}) has no messages; expected at least one")
        mounting = bag_mounting(reader, shown, topics, choice, opts["base_frame"], opts["odom_frame"])
    source = _BagSource(
        bag,
        shown,
        choice,
        opts["odom_frame"],
        opts["base_frame"],
        opts["outside_odometry"],
        opts["max_pose_gap"],
        mounting.mirrored,
    )
    odom_desc = (
        f"{choice.odom} transforms {opts['odom_frame']} -> {opts['base_frame'] or '(its only child)'}"
        if choice.odom_is_tf
        else f"{choice.odom} ({topics[choice.odom].msgtype})"
    )
    metadata = SequenceMetadata(
        source=str(shown),
        format=format_name,
        sensor_offset=mounting.offset,
        odometry_source=f"{odom_desc}, SE(2)-interpolated to the {LASER_SCAN} header stamps of {choice.scan}",
        reference_source=(
            f"{choice.reference} (nav_msgs/msg/Odometry), SE(2)-interpolated to the scan stamps"
            if choice.reference
            else ""
        ),
        extra={
            "scan_topic": choice.scan,
            "odom_topic": choice.odom,
            "reference_topic": choice.reference,
            "outside_odometry": opts["outside_odometry"],
            "sensor_offset_source": mounting.note,
        },
    )
    return Sequence(name, source.frames, metadata)


class Ros1BagLoader:
    """ROS1 ``.bag`` files (format 2.0). Options: see :func:`Ros2BagLoader.load`."""

    format_name: ClassVar[str] = "ros1"
    suffixes: ClassVar[tuple[str, ...]] = (".bag",)

    def sniff(self, path: Path) -> bool:
        """Any ``#ROSBAG``/``#ROSRECORD`` file, so that old versions reach :meth:`load` and its clear error."""
        if not path.is_file():
            return False
        with path.open("rb") as fh:
            head = fh.read(16)
        return head.startswith((b"#ROSBAG", b"#ROSRECORD", b"#ROSLOG"))

    def load(self, path: Path, **options: Any) -> Sequence:
        path = Path(path)
        if not path.is_file():
            raise DataError(f"{path}: no such ROS1 bag file")
        with path.open("rb") as fh:
            head = fh.readline(64).rstrip(b"\n")
        problem = version_problem(head)
        if problem is not None:
            raise ParseError(path, problem, line=1)
        return _load_bag(path, path, path.stem, self.format_name, options)


class Ros2BagLoader:
    """ROS2 bags (a folder with ``metadata.yaml`` and sqlite3 ``.db3`` or ``.mcap`` storage).

    ``format_name`` is ``"ros2"``; the loaded sequence's metadata says
    ``ros2-sqlite3`` or ``ros2-mcap`` from the storage file found.
    """

    format_name: ClassVar[str] = "ros2"
    suffixes: ClassVar[tuple[str, ...]] = (".db3", ".mcap")

    @staticmethod
    def bag_dir(path: Path) -> Path | None:
        """The bag folder for a folder or one of its storage files, or None."""
        folder = path if path.is_dir() else path.parent
        return folder if (folder / "metadata.yaml").is_file() else None

    @classmethod
    def storage_files(cls, folder: Path) -> list[Path]:
        """The ``.db3`` / ``.mcap`` files of a (would-be) bag folder."""
        return sorted(p for p in folder.iterdir() if p.suffix in cls.suffixes and p.is_file())

    def sniff(self, path: Path) -> bool:
        """A bag folder (or a storage file in one), also when its metadata.yaml is missing (see :meth:`load`)."""
        if path.is_dir():
            return self.bag_dir(path) is not None or bool(self.storage_files(path))
        return path.suffix in self.suffixes

    def load(self, path: Path, **options: Any) -> Sequence:
        """The bag as a Sequence.

        Options: ``scan_topic``, ``odom_topic`` (Odometry or ``/tf``),
        ``reference_topic`` (Odometry), ``odom_frame`` (default ``odom``) and
        ``base_frame`` (default: the only child of ``odom_frame``) for ``/tf``,
        ``outside_odometry`` (``error`` | ``drop``).
        """
        path = Path(path)
        if not path.exists():
            raise DataError(f"{path}: no such ROS2 bag folder")
        if not (path.is_dir() or path.suffix in self.suffixes or path.name == "metadata.yaml"):  # a ROS1 .bag
            raise DataError(
                f"{path}: not a ROS2 bag; expected its folder (metadata.yaml beside .db3/.mcap storage files) "
                "or one of its .db3/.mcap storage files"
            )
        folder = self.bag_dir(path)
        if folder is None:
            where = path if path.is_dir() else path.parent
            found = ", ".join(p.name for p in self.storage_files(where))
            if not found:
                raise DataError(
                    f"{where}: not a ROS2 bag folder; expected metadata.yaml beside .db3/.mcap storage files, "
                    f"found neither"
                )
            raise DataError(
                f"{where / 'metadata.yaml'}: missing; a ROS2 bag folder holds metadata.yaml beside its storage "
                f"files (found: {found}); ROS 2's `ros2 bag reindex FOLDER` can recreate it"
            )
        # ``run.mcap``, or ``run.mcap.zstd`` when rosbag2 compressed the whole file (which used to be called sqlite3)
        mcap = any(".mcap" in p.suffixes for p in folder.iterdir() if p.is_file())
        storage = "ros2-mcap" if mcap else "ros2-sqlite3"
        return _load_bag(folder, folder, folder.name, storage, options)
