"""Writes frames as an MRPT rawlog, the input of MRPT's SLAM applications.

Why the project writes rawlogs itself: MRPT's own ``carmen2rawlog`` scales
CARMEN timestamps wrongly (every observation gets one time) and assumes
0.5 deg per beam, and ``rosbag2rawlog`` ignores laser scans and odometry
(``docs/baselines.md``, section MRPT). Writing from the data model keeps
every loader's checks and the exact beam geometry.

Two layouts, because MRPT's applications disagree on what they read:

* ``actions`` ("actions / sensory frames"): per scan a ``CActionCollection``
  holding one ``CActionRobotMovement2D`` with the odometry increment since
  the previous scan (zero for the first), then a ``CSensoryFrame`` holding
  the scan. ``rbpf-slam`` needs it (it crashes on the other layout); it is
  also what ``albot1 convert x.clf x.rawlog`` writes.
* ``observations``: per scan a ``CObservationOdometry`` (the absolute
  odometry) then the ``CObservation2DRangeScan``. ``icp-slam`` works best
  with it.

Beam geometry: MRPT describes a scan by its aperture and spreads the beams
evenly and symmetrically about the sensor's x axis; a scan whose beams are
not centred (the 180-beam logs span -90..+89 deg) is described by rotating
the sensor pose by the centre angle. Beams must be evenly spaced. The laser's
mounting pose on the robot is ``SequenceMetadata.sensor_offset``. A beam with
no return (NaN) or beyond the scan's max range is written as invalid.

Stamps: each scan's own. With ``fill_stamps`` (what the mrpt-icp and
mrpt-rbpf methods use) a scan whose stamp MRPT cannot use (not finite, not
representable, tick 0, or not strictly later than the stamp written for the
previous scan) gets the previous written stamp plus 1 us instead (the step of
``albot1 convert --retime``, :mod:`albot1.data.retime`) and is counted in
:class:`RawlogStats`; ``stamps`` says why icp-slam needs strictly increasing
stamps and gives the rule exactly. A log whose stamps are all usable is
written byte for byte as without it. ``albot1 convert`` does not fill (it
changes no data unless asked: its ``--retime`` makes repeated or backward
stamps strictly increasing by the same rule, which is what icp-slam needs).
"""

from __future__ import annotations

import gzip
import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from albot1.atomic import atomic_write
from albot1.data.errors import DataError
from albot1.data.loaders.rawlog import serialize
from albot1.data.loaders.rawlog.stamps import StampClock
from albot1.data.model import Frame, Sequence
from albot1.geometry import se2

RawlogLayout = Literal["actions", "observations"]
LAYOUTS: tuple[RawlogLayout, ...] = ("actions", "observations")

#: Relative tolerance on beam spacing (as the CARMEN writer): MRPT can only describe evenly spaced beams.
_SPACING_TOLERANCE = 1e-6


@dataclass(frozen=True)
class BeamGeometry:
    """How MRPT sees a scan's beams: the aperture and the rotation of the sensor to centre them."""

    aperture_rad: float
    centre_rad: float


def beam_geometry(angles: NDArray[np.float64], where: str) -> BeamGeometry:
    """The aperture and centre angle of evenly spaced, ascending beam angles (DataError otherwise)."""
    n = len(angles)
    if n < 2:
        raise DataError(f"{where}: a scan of {n} beam(s); an MRPT range scan needs at least 2")
    steps = np.diff(angles)
    step = float(angles[-1] - angles[0]) / (n - 1)
    if step <= 0 or not np.allclose(steps, step, rtol=_SPACING_TOLERANCE, atol=1e-9):
        raise DataError(
            f"{where}: beam angles are not evenly spaced and ascending (steps {float(steps.min()):.6g} .. "
            f"{float(steps.max()):.6g} rad); an MRPT range scan needs one angular step"
        )
    return BeamGeometry(aperture_rad=float(angles[-1] - angles[0]), centre_rad=float(angles[-1] + angles[0]) / 2.0)


@dataclass
class RawlogStats:
    """What :func:`write_frames` wrote."""

    scans: int = 0
    invalid_beams: int = 0
    bytes_written: int = 0
    #: Scans written with a filled-in stamp instead of their own (see ``stamps``), and the first such scan and why.
    replaced_stamps: int = 0
    first_replaced_stamp: str | None = None


def encode_frame(
    frame: Frame,
    previous_odometry: NDArray[np.float64] | None,
    *,
    layout: RawlogLayout,
    sensor_offset: tuple[float, float, float],
    motion_model: serialize.GaussianMotionModel,
    label: str = "LASER",
    stamp: int | None = None,
) -> tuple[bytes, int]:
    """The serialized objects of one frame, and how many of its beams are invalid.

    ``stamp`` (``mrpt::Clock`` ticks) is the one :func:`write_frames` chose; None: the scan's own.
    """
    scan = frame.scan
    where = f"frame {frame.index}"
    geometry = beam_geometry(scan.angles, where)
    max_range = float(scan.max_range)
    if not (math.isfinite(max_range) and max_range > 0):
        raise DataError(f"{where}: max_range {max_range!r}; expected a positive number of metres")
    odometry = np.asarray(frame.odometry, dtype=float)
    if odometry.shape != (3,) or not np.isfinite(odometry).all():
        raise DataError(f"{where}: odometry {odometry.tolist()} is not a finite (x, y, theta)")
    if stamp is None:
        try:
            stamp = serialize.mrpt_timestamp(float(scan.timestamp))
        except ValueError as exc:
            raise DataError(f"{where}: {exc}") from None
    ranges = np.asarray(scan.ranges, dtype=float)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(ranges) & (ranges > 0) & (ranges <= max_range)
    written = np.where(valid, ranges, max_range)
    sensor = (sensor_offset[0], sensor_offset[1], sensor_offset[2] + geometry.centre_rad)
    observation = serialize.range_scan(
        written,
        valid,
        aperture_rad=geometry.aperture_rad,
        max_range_m=max_range,
        sensor_pose=sensor,
        stamp=stamp,
        label=label,
    )
    invalid = int(len(valid) - np.count_nonzero(valid))
    if layout == "observations":
        return serialize.odometry(odometry, stamp) + observation, invalid
    increment = np.zeros(3) if previous_odometry is None else se2.between(previous_odometry, odometry)
    action = serialize.action_collection([serialize.robot_movement_2d(increment, stamp, motion_model)])
    return action + serialize.sensory_frame([observation]), invalid


def write_frames(
    frames: Iterable[Frame],
    out: BinaryIO,
    *,
    layout: RawlogLayout = "actions",
    sensor_offset: tuple[float, float, float] = (0.0, 0.0, 0.0),
    motion_model: serialize.GaussianMotionModel | None = None,
    fill_stamps: bool = False,
) -> RawlogStats:
    """Serialize ``frames`` to the open binary stream ``out`` (see the module doc for the layouts and stamps)."""
    if layout not in LAYOUTS:
        raise DataError(f"rawlog layout {layout!r}; expected one of: {', '.join(LAYOUTS)}")
    model = motion_model or serialize.GaussianMotionModel()
    stats = RawlogStats()
    clock = StampClock()
    previous: NDArray[np.float64] | None = None
    for frame in frames:
        stamp: int | None = None
        if fill_stamps:
            try:
                stamp = clock.stamp(frame.index, float(frame.scan.timestamp))
            except DataError as exc:
                raise DataError(f"frame {frame.index}: {exc}") from None
        data, invalid = encode_frame(
            frame, previous, layout=layout, sensor_offset=sensor_offset, motion_model=model, stamp=stamp
        )
        out.write(data)
        previous = np.asarray(frame.odometry, dtype=float)
        stats.scans += 1
        stats.invalid_beams += invalid
        stats.bytes_written += len(data)
    stats.replaced_stamps = clock.replaced
    stats.first_replaced_stamp = clock.first_replacement
    return stats


def _open(path: Path) -> BinaryIO:
    if path.name.endswith(".gz"):
        return gzip.open(path, "wb", compresslevel=6)  # type: ignore[return-value]
    return path.open("wb")


class RawlogWriter:
    """``albot1 convert IN OUT.rawlog[.gz]``: an MRPT rawlog in the actions / sensory-frames layout.

    ``layout`` chooses the layout (see the module doc); the output is
    gzip-compressed when the name ends in ``.gz`` (MRPT reads both) and is
    written to a temporary file renamed into place.
    """

    format_name: ClassVar[str] = "rawlog"

    def __init__(
        self, layout: RawlogLayout = "actions", motion_model: serialize.GaussianMotionModel | None = None
    ) -> None:
        if layout not in LAYOUTS:
            raise DataError(f"rawlog layout {layout!r}; expected one of: {', '.join(LAYOUTS)}")
        self.layout: RawlogLayout = layout
        self.motion_model = motion_model
        self.stats = RawlogStats()

    def write(self, sequence: Sequence, path: Path) -> None:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        offset = tuple(float(v) for v in sequence.metadata.sensor_offset)

        def write_file(tmp: Path) -> None:
            with _open(tmp) as out:
                self.stats = write_frames(
                    sequence.frames(),
                    out,
                    layout=self.layout,
                    sensor_offset=(offset[0], offset[1], offset[2]),
                    motion_model=self.motion_model,
                )
            if self.stats.scans == 0:
                raise DataError(f"{sequence.name}: no scans to write; a rawlog needs at least one")

        atomic_write(path, write_file)
