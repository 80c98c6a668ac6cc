"""The one data model every loader produces and every mapper consumes.

Frames follow ROS REP-103: x forward, y left, angles counter-clockwise, beam
angle 0 = straight ahead. The thesis's own frame (robot facing +y, surfaces
ordered left to right) exists only inside the Albot1 mapper.

A :class:`Sequence` is *streamed*: iterating it yields :class:`Frame` objects
decoded on demand, so a mapper can start on a 100k-scan log before the rest
of the file is read. Whole-sequence arrays (timestamps, odometry, reference)
are computed by one full pass the first time they are asked for and cached.

The number of scans is known up front only for some sequences (in memory,
synthetic worlds, prefixes and strides of those); for a streamed log it
takes decoding the whole file. So ``len(sequence)`` answers only when the
count is known without decoding (:attr:`Sequence.known_scan_count`) and is
a ``TypeError`` otherwise, while :meth:`Sequence.count_scans` always answers
and says in its name that it may cost a full pass.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.geometry import se2
from albot1.geometry.types import FloatArray

#: Largest accepted |x|, |y| (m) of a pose and largest accepted laser reading (m): 1e8 m (100 000 km) is no
#: planar map, and larger values overflow to infinity once squared in a metric or cast to a grid cell. Trajectory
#: files (:mod:`albot1.data.trajectory`), every loaded frame (:mod:`albot1.data.finite`), the bag reader's ranges
#: and a method's map (:mod:`albot1.runs.execute`) are held to it.
MAX_COORDINATE_M = 1e8
#: Largest accepted |timestamp| (s): year 5138 in Unix time; nanosecond stamps (1.7e18) are refused, not misread.
#: Trajectory and relations files and every loaded frame (:mod:`albot1.data.finite`) are held to it, so a log
#: whose stamps a run's own ``trajectory.tum`` could not be read back with is refused when it is loaded.
MAX_TIMESTAMP_S = 1e11
#: Largest accepted distance (m) of the laser from the robot's base (``SequenceMetadata.sensor_offset``): the longest
#: road vehicles are about 20 m long. A mount written in millimetres (``200`` for 0.2 m) or a corrupt ``/tf_static``
#: used to place every scan that far off the robot without a word; a mount of 1e300 m made each run fail as
#: "diverged". Every loaded sequence (:mod:`albot1.data.finite`), the albot log's ``MOUNT`` line and CARMEN's
#: ``robot_*laser_offset`` PARAMs are held to it (:func:`mount_problem`).
MAX_MOUNT_M = 20.0


def mount_problem(offset: tuple[float, float, float]) -> str | None:
    """Why ``offset`` (x, y, yaw of the laser on the robot) cannot be a laser mount, or None."""
    x, y, yaw = (float(v) for v in offset)
    if not all(map(math.isfinite, (x, y, yaw))):
        return f"laser mount (x, y, yaw) = ({x!r}, {y!r}, {yaw!r}) is not finite; expected metres and radians"
    distance = math.hypot(x, y)
    if distance <= MAX_MOUNT_M:
        return None
    return (
        f"laser mount (x, y, yaw) = ({x:.6g} m, {y:.6g} m, {yaw:.6g} rad) puts the laser {distance:.6g} m from the "
        f"robot's base; expected at most {MAX_MOUNT_M:g} m (metres on a robot: a mount in millimetres?)"
    )


class _BeamDirections:
    """cos and sin of the last read-only beam-angle array seen.

    Loaders share one read-only angle array across all scans of a log, so
    :meth:`Scan.points` computes its trigonometry once per log instead of
    once per scan (half the cost of the conversion). A writeable array is
    never cached: its values could change under the same identity.
    """

    def __init__(self) -> None:
        self._last: tuple[FloatArray, FloatArray, FloatArray] | None = None

    def __call__(self, angles: FloatArray) -> tuple[FloatArray, FloatArray]:
        last = self._last
        if last is not None and last[0] is angles:
            return last[1], last[2]
        cos, sin = np.cos(angles), np.sin(angles)
        if not angles.flags.writeable:
            self._last = (angles, cos, sin)
        return cos, sin


_beam_directions = _BeamDirections()


@dataclass(frozen=True, slots=True, eq=False)
class Scan:
    """One planar laser scan in the sensor frame.

    ``ranges`` are metres with NaN for "no return" (max-range readings are
    converted to NaN by the loaders); ``angles`` are radians, counter-clockwise,
    0 = forward, one per range, ascending.
    """

    ranges: FloatArray
    angles: FloatArray
    timestamp: float
    max_range: float

    def __post_init__(self) -> None:
        if self.ranges.shape != self.angles.shape or self.ranges.ndim != 1:
            raise ValueError(f"ranges {self.ranges.shape} and angles {self.angles.shape} must be equal 1-D shapes")

    @property
    def beams(self) -> int:
        return int(self.ranges.shape[0])

    def valid(self) -> NDArray[np.bool_]:
        """Mask of beams with a return."""
        return np.isfinite(self.ranges)

    def points(
        self, min_range_m: float | None = None, max_range_m: float | None = None, *, keep_missing: bool = False
    ) -> FloatArray:
        """Cartesian points ``(k, 2)`` of the beams with a return, in the sensor frame, in beam order.

        The one scan-to-points conversion of the package. Beams without a
        return (NaN) are dropped, unless ``keep_missing`` (one point per beam,
        NaN where there is no return: what a format that stores every beam
        as a point writes; no range limits then). ``min_range_m`` / ``max_range_m``
        also drop beams shorter / longer than the limit (a beam exactly at a
        limit is kept). Moving the points into the robot or map frame (the
        laser's mounting offset, a pose) is the caller's, with
        :func:`albot1.geometry.se2.transform_points`.
        """
        if keep_missing and (min_range_m is not None or max_range_m is not None):
            raise ValueError("keep_missing keeps every beam: it takes no range limits")
        mask = np.ones(self.beams, dtype=np.bool_) if keep_missing else self.valid()
        if min_range_m is not None:
            mask &= self.ranges >= min_range_m
        if max_range_m is not None:
            mask &= self.ranges <= max_range_m
        cos, sin = _beam_directions(self.angles)
        r = self.ranges[mask]
        out = np.empty((len(r), 2))
        np.multiply(r, cos[mask], out=out[:, 0])
        np.multiply(r, sin[mask], out=out[:, 1])
        return out


@dataclass(frozen=True, slots=True, eq=False)
class Frame:
    """One step of a sequence: the scan and the poses that belong to it.

    ``odometry`` is the robot (base) pose in the odometry frame at the scan's
    time; ``reference`` is the ground-truth/corrected pose when the dataset has
    one (else None).
    """

    index: int
    scan: Scan
    odometry: FloatArray
    reference: FloatArray | None = None


@dataclass(frozen=True)
class Relations:
    """Ground-truth relative poses (Kuemmerle et al. 2009): ``inv(T(t1)) * T(t2)``."""

    t1: FloatArray
    t2: FloatArray
    poses: FloatArray  # (M, 3): x, y, yaw of the relation
    #: How many lines of the file this was read from repeat an earlier line (identically, or in the other
    #: direction as its inverse): left out (each relation counted once) unless ``repeats_counted`` (read with
    #: ``repeats="keep"``, as the published evaluator counts lines); see :mod:`albot1.data.relations`.
    repeats: int = 0
    repeats_counted: bool = False

    def __len__(self) -> int:
        return int(self.t1.shape[0])


@dataclass(frozen=True)
class SequenceMetadata:
    """Where a sequence came from and how its fields were derived."""

    source: str = ""
    format: str = ""
    license: str = ""
    citation: str = ""
    sensor_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    odometry_source: str = ""
    reference_source: str = ""
    extra: dict[str, Any] = field(default_factory=dict)
    #: sha256 of every file the sequence was read from, by file name (:mod:`albot1.data.identity`); empty for a
    #: sequence made in memory (a synthetic world is named by the code version)
    checksums: dict[str, str] = field(default_factory=dict)
    #: the ``[loader]`` table of a registered dataset's manifest, as written (``datasets/<name>.toml``): options that
    #: shape what the loader reads (``max_range``, the odometry source) without appearing in the dataset's name, so
    #: a run key and ``result.json`` carry them (an edited or replaced manifest must not reuse an older result)
    manifest_loader: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class SequenceArrays:
    """Per-scan summary arrays obtained by one full pass over a sequence."""

    timestamps: FloatArray
    odometry: FloatArray
    reference: FloatArray | None
    beams: NDArray[np.int64]
    #: ``(N, 2)``: each scan's first and last beam angle (radians); with ``beams`` it gives the field of view
    #: and the beam spacing (``albot1 datasets info``), which differ between recordings of one log.
    angle_span: FloatArray | None = None


class Sequence:
    """A named, re-iterable stream of frames plus sequence-level data.

    ``frames_factory`` must return a *new* iterator each call, yielding frames
    with consecutive indices from 0; it is how streaming loaders, transforms
    (odometry degradation) and in-memory sequences share one type.
    ``scan_count`` is the number of frames when the creator knows it without
    decoding (a list in memory, an index, a generated world); None = unknown.
    """

    def __init__(
        self,
        name: str,
        frames_factory: Callable[[], Iterator[Frame]],
        metadata: SequenceMetadata | None = None,
        relations: Relations | None = None,
        *,
        scan_count: int | None = None,
    ) -> None:
        if scan_count is not None and scan_count < 0:
            raise ValueError(f"scan_count must be >= 0 or None (unknown), got {scan_count}")
        self.name = name
        self._frames_factory = frames_factory
        self.metadata = metadata or SequenceMetadata()
        self.relations = relations
        self._scan_count = scan_count
        self._arrays: SequenceArrays | None = None

    @classmethod
    def from_frames(
        cls,
        name: str,
        frames: Iterable[Frame],
        metadata: SequenceMetadata | None = None,
        relations: Relations | None = None,
    ) -> Sequence:
        """An in-memory sequence (frames are kept in a list)."""
        frame_list = list(frames)
        for i, frame in enumerate(frame_list):
            if frame.index != i:
                raise ValueError(f"frame {i} has index {frame.index}; frames must be numbered 0..N-1")
        return cls(name, lambda: iter(frame_list), metadata, relations, scan_count=len(frame_list))

    def __iter__(self) -> Iterator[Frame]:
        return self._frames_factory()

    def frames(self) -> Iterator[Frame]:
        """A fresh streaming iterator over the frames."""
        return self._frames_factory()

    def materialize(self) -> Sequence:
        """The same sequence held in memory (decodes everything once)."""
        seq = Sequence.from_frames(self.name, self.frames(), self.metadata, self.relations)
        seq._arrays = self._arrays
        return seq

    def with_frames(
        self,
        transform: Callable[[Iterator[Frame]], Iterator[Frame]],
        name: str | None = None,
        metadata: SequenceMetadata | None = None,
        *,
        scan_count: int | None = None,
    ) -> Sequence:
        """A new sequence whose frames are ``transform(self.frames())``, still streamed.

        ``scan_count``: how many frames the transform yields, when that is
        known without decoding (e.g. a count-preserving transform of a
        sequence whose count is known); None leaves it unknown.
        """
        return Sequence(
            name or self.name,
            lambda: transform(self.frames()),
            metadata or self.metadata,
            self.relations,
            scan_count=scan_count,
        )

    def with_metadata(self, metadata: SequenceMetadata) -> Sequence:
        """The same frames (still streamed) under new metadata."""
        return Sequence(self.name, self._frames_factory, metadata, self.relations, scan_count=self._scan_count)

    @property
    def arrays(self) -> SequenceArrays:
        """Timestamps, odometry, reference and beam counts (one full pass, cached)."""
        if self._arrays is None:
            stamps, odom, ref, beams, span = [], [], [], [], []
            has_ref = True
            for frame in self.frames():
                stamps.append(frame.scan.timestamp)
                odom.append(frame.odometry)
                beams.append(frame.scan.beams)
                angles = frame.scan.angles
                span.append((angles[0], angles[-1]) if len(angles) else (np.nan, np.nan))
                if frame.reference is None:
                    has_ref = False
                elif has_ref:
                    ref.append(frame.reference)
            self._arrays = SequenceArrays(
                timestamps=np.asarray(stamps, dtype=float),
                odometry=np.asarray(odom, dtype=float).reshape(-1, 3),
                reference=np.asarray(ref, dtype=float).reshape(-1, 3) if has_ref and stamps else None,
                beams=np.asarray(beams, dtype=np.int64),
                angle_span=np.asarray(span, dtype=float).reshape(-1, 2),
            )
        return self._arrays

    @property
    def known_scan_count(self) -> int | None:
        """The number of frames if known without decoding (given at creation, or counted already), else None."""
        if self._scan_count is not None:
            return self._scan_count
        return int(self._arrays.timestamps.shape[0]) if self._arrays is not None else None

    def count_scans(self) -> int:
        """The number of frames: free when :attr:`known_scan_count` knows it, else one full decoding pass.

        The pass fills :attr:`arrays` (cached), so later counts are free.
        """
        known = self.known_scan_count
        return known if known is not None else int(self.arrays.timestamps.shape[0])

    def __len__(self) -> int:
        """The number of frames when known without decoding; TypeError otherwise (see :meth:`count_scans`).

        ``len()`` must be cheap: a streamed log's length takes decoding the
        whole file, which ``len()`` must not do silently. (``list(sequence)``
        still works: Python's size hint treats the TypeError as "unknown".)
        """
        known = self.known_scan_count
        if known is None:
            raise TypeError(
                f"len() of sequence {self.name!r} is unknown without decoding it; "
                "use sequence.count_scans() (one full pass) instead"
            )
        return known

    def __bool__(self) -> bool:
        """Always true, like any object: emptiness needs :meth:`count_scans` (``len()`` may be unknown)."""
        return True

    @property
    def timestamps(self) -> FloatArray:
        return self.arrays.timestamps

    @property
    def odometry(self) -> FloatArray:
        return self.arrays.odometry

    @property
    def reference(self) -> FloatArray | None:
        return self.arrays.reference

    def summary(self) -> dict[str, Any]:
        """The facts ``albot1 datasets info --json`` prints (one full pass, cached; see ``docs/datasets.md``)."""
        arr = self.arrays
        beams = np.unique(arr.beams).tolist() if len(arr.beams) else []
        return {
            "name": self.name,
            "source": self.metadata.source,
            "format": self.metadata.format,
            "scans": int(len(arr.timestamps)),
            "beams": beams[0] if len(beams) == 1 else beams,
            "duration_s": float(arr.timestamps[-1] - arr.timestamps[0]) if len(arr.timestamps) > 1 else 0.0,
            "odometry_path_m": se2.path_length(arr.odometry),
            "has_reference": arr.reference is not None,
            "relations": len(self.relations) if self.relations is not None else 0,
            "odometry_source": self.metadata.odometry_source,
            "reference_source": self.metadata.reference_source,
            "license": self.metadata.license,
            "scan_geometry": scan_geometry(arr.beams, arr.angle_span),
            "sensor_offset": [float(v) for v in self.metadata.sensor_offset],
            "sensor_offset_source": str(self.metadata.extra.get("sensor_offset_source", "")),
            "skipped_messages": str(self.metadata.extra.get("skipped_messages", "")),
        }


def scan_geometry(beams: NDArray[np.int64], span: FloatArray | None) -> list[dict[str, Any]]:
    """The distinct beam layouts of a sequence, most frequent first, in degrees.

    Each: ``first_deg``, ``last_deg`` (beam angles, so the field of view is
    ``last - first``), ``beams``, ``spacing_deg`` (``(last - first) / (beams - 1)``,
    NaN for one beam) and ``scans`` using it. Angles are rounded to 1e-6 deg
    so float noise does not split one layout in two.
    """
    if span is None or not len(beams):
        return []
    rows = np.column_stack([np.round(np.degrees(span), 6), beams.astype(float)])
    layouts, counts = np.unique(rows, axis=0, return_counts=True)
    order = np.lexsort((layouts[:, 0], -counts))
    out = []
    for i in order:
        first, last, n = (float(v) for v in layouts[i])
        spacing = (last - first) / (n - 1) if n > 1 else float("nan")
        out.append(
            {"first_deg": first, "last_deg": last, "beams": int(n), "spacing_deg": spacing, "scans": int(counts[i])}
        )
    return out
