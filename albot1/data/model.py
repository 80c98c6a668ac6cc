"""The one data model every loader produces and every mapper consumes.

Frames follow ROS REP-103: x forward, y left, angles counter-clockwise, beam
angle 0 = straight ahead. The thesis's own frame (robot facing +y, surfaces
ordered left to right) exists only inside the Albot1 mapper.

A :class:`Sequence` is *streamed*: iterating it yields :class:`Frame` objects
decoded on demand, so a mapper can start on a 100k-scan log before the rest
of the file is read. Whole-sequence arrays (timestamps, odometry, reference)
are computed by one full pass the first time they are asked for and cached.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from albot1.geometry import se2

FloatArray = NDArray[np.float64]


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

    def points(self) -> FloatArray:
        """Cartesian points ``(k, 2)`` of the valid beams, sensor frame, in beam order."""
        mask = self.valid()
        r, a = self.ranges[mask], self.angles[mask]
        return np.column_stack([r * np.cos(a), r * np.sin(a)])


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


@dataclass(frozen=True)
class SequenceArrays:
    """Per-scan summary arrays obtained by one full pass over a sequence."""

    timestamps: FloatArray
    odometry: FloatArray
    reference: FloatArray | None
    beams: NDArray[np.int64]


class Sequence:
    """A named, re-iterable stream of frames plus sequence-level data.

    ``frames_factory`` must return a *new* iterator each call, yielding frames
    with consecutive indices from 0; it is how streaming loaders, transforms
    (odometry degradation) and in-memory sequences share one type.
    """

    def __init__(
        self,
        name: str,
        frames_factory: Callable[[], Iterator[Frame]],
        metadata: SequenceMetadata | None = None,
        relations: Relations | None = None,
    ) -> None:
        self.name = name
        self._frames_factory = frames_factory
        self.metadata = metadata or SequenceMetadata()
        self.relations = relations
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
        return cls(name, lambda: iter(frame_list), metadata, relations)

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
    ) -> Sequence:
        """A new sequence whose frames are ``transform(self.frames())``, still streamed."""
        return Sequence(name or self.name, lambda: transform(self.frames()), metadata or self.metadata, self.relations)

    @property
    def arrays(self) -> SequenceArrays:
        """Timestamps, odometry, reference and beam counts (one full pass, cached)."""
        if self._arrays is None:
            stamps, odom, ref, beams = [], [], [], []
            has_ref = True
            for frame in self.frames():
                stamps.append(frame.scan.timestamp)
                odom.append(frame.odometry)
                beams.append(frame.scan.beams)
                if frame.reference is None:
                    has_ref = False
                elif has_ref:
                    ref.append(frame.reference)
            self._arrays = SequenceArrays(
                timestamps=np.asarray(stamps, dtype=float),
                odometry=np.asarray(odom, dtype=float).reshape(-1, 3),
                reference=np.asarray(ref, dtype=float).reshape(-1, 3) if has_ref and stamps else None,
                beams=np.asarray(beams, dtype=np.int64),
            )
        return self._arrays

    def __len__(self) -> int:
        return int(self.arrays.timestamps.shape[0])

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
        """The facts ``albot1 datasets info --json`` prints (DESIGN.md 4b)."""
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
        }
