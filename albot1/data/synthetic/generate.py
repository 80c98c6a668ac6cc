"""Generating a world: from a :class:`WorldSpec` to poses, odometry, scans and crossings.

Pure simulation, no I/O. :func:`generate` samples the route, checks it can be
driven, simulates the odometry and ray-casts the exact ranges of one lap;
:func:`stream_frames` turns that into frames, drawing the range noise while
streaming, in fixed blocks of scans each with its own seed, so every
iteration yields identical frames and a long multi-lap world costs no more
memory than one lap. The ray casting is done once per lap because a lap's
poses repeat exactly; only the noise differs.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass, field

import numpy as np
from numpy.typing import NDArray

from albot1.data.model import Frame, Scan, SequenceMetadata
from albot1.data.synthetic import lidar
from albot1.data.synthetic.errors import WorldOptionError
from albot1.data.synthetic.floorplan import DoorwayCrossing, FloorPlan, check_route
from albot1.data.synthetic.floorplan import doorway_crossings as find_crossings
from albot1.data.synthetic.lidar import LaserSpec
from albot1.data.synthetic.odometry import OdometryErrorModel, simulate
from albot1.data.synthetic.route import Route, Sampling, repeat_laps, sample, timestamps
from albot1.geometry import se2
from albot1.geometry.types import FloatArray

# Half the width of the thesis's Pioneer 3-DX (50 cm): every route must keep
# this far from the walls, so it could be driven (through a 0.9 m doorway too).
ROBOT_RADIUS = 0.25

# Scans per block of range noise: each block has its own seed, so streaming
# can draw noise for a block without drawing everything before it.
NOISE_BLOCK = 1024


@dataclass(frozen=True)
class WorldSpec:
    """Everything that defines a world; ``plan`` and ``route`` build their parts on first use."""

    name: str
    description: str
    plan: Callable[[], FloorPlan]
    route: Callable[[], Route]
    sampling: Sampling
    laser: LaserSpec = field(default_factory=LaserSpec)
    odometry: OdometryErrorModel = field(default_factory=OdometryErrorModel)
    seed: int = 0
    laps: int = 1
    #: Waypoints of the closed route the world may also be driven from: loader option ``start=K`` picks
    #: ``starts[K]`` (empty: the world takes no ``start`` option).
    starts: tuple[int, ...] = ()


@dataclass(frozen=True, eq=False)
class WorldData:
    """A generated world: the arrays frames are streamed from."""

    spec: WorldSpec
    plan: FloorPlan
    reference: FloatArray  # (N, 3) exact pose per scan
    odometry: FloatArray  # (N, 3)
    timestamps: FloatArray  # (N,)
    lap_ranges: FloatArray  # (L, beams) exact ranges of one lap's poses
    crossings: tuple[DoorwayCrossing, ...]
    route_length: float

    @property
    def scans(self) -> int:
        return int(self.reference.shape[0])

    def exact_row(self, index: NDArray[np.intp]) -> NDArray[np.intp]:
        """The row of ``lap_ranges`` that scan ``index`` sees (laps repeat the lap's poses)."""
        lap = len(self.lap_ranges)
        return index if self.spec.laps == 1 else index % (lap - 1)


#: The most scans a generated world may hold (its poses and times are built whole: ~0.25 KB a scan, so about
#: 0.5 GB here; synthetic-office-long, the largest embedded world, has 37,401).
MAX_WORLD_SCANS = 2_000_000


def generate(spec: WorldSpec) -> WorldData:
    """Build a world from its spec (uncached; ``worlds.load_world`` caches the embedded ones by name)."""
    plan = spec.plan()
    route = spec.route()
    check_route(plan, route.waypoints, clearance=ROBOT_RADIUS)
    lap = sample(route, spec.sampling)
    scans = (len(lap) - 1) * spec.laps + 1 if spec.laps > 1 else len(lap)
    if scans > MAX_WORLD_SCANS:
        # `?laps=999999999` asked numpy for 40.8 TiB and ended in an ArrayMemoryError traceback
        raise WorldOptionError(
            f"synthetic world {spec.name!r}: {spec.laps} laps of {len(lap) - 1} scans would be {scans:,} scans; "
            f"expected at most {MAX_WORLD_SCANS:,} (a world is generated whole, in memory): give fewer laps"
        )
    reference = repeat_laps(lap, spec.laps)
    odometry = simulate(reference, spec.odometry, seed=np.random.default_rng([spec.seed, 0]))
    lap_ranges = lidar.cast_many(plan.walls, lap, spec.laser.angles, spec.laser.max_range)
    for shared in (plan.walls, reference, odometry, lap_ranges):
        shared.setflags(write=False)  # a cached world is shared by every caller in the process
    times = timestamps(reference, spec.sampling)
    return WorldData(
        spec=spec,
        plan=plan,
        reference=reference,
        odometry=odometry,
        timestamps=times,
        lap_ranges=lap_ranges,
        crossings=tuple(find_crossings(plan, reference, times)),
        route_length=se2.path_length(reference),
    )


def stream_frames(data: WorldData) -> Iterator[Frame]:
    """The frames of a generated world, range noise drawn block by block (identical on every call)."""
    laser = data.spec.laser
    angles = laser.angles
    angles.setflags(write=False)  # shared by every scan
    for start in range(0, data.scans, NOISE_BLOCK):
        index = np.arange(start, min(start + NOISE_BLOCK, data.scans))
        rng = np.random.default_rng([data.spec.seed, 1, start // NOISE_BLOCK])
        ranges = lidar.add_noise(data.lap_ranges[data.exact_row(index)], laser.range_sigma, laser.max_range, rng)
        for k, i in enumerate(index):
            scan = Scan(ranges=ranges[k], angles=angles, timestamp=float(data.timestamps[i]), max_range=laser.max_range)
            yield Frame(index=int(i), scan=scan, odometry=data.odometry[i].copy(), reference=data.reference[i].copy())


def world_metadata(data: WorldData) -> SequenceMetadata:
    """Sequence metadata with the world's facts (crossings, wall count, models) in ``extra``, JSON-able."""
    spec = data.spec
    return SequenceMetadata(
        source=f"synthetic:{spec.name}",
        format="synthetic",
        license="generated by albot1-bench (MIT)",
        odometry_source=f"simulated odometry, seed {spec.seed}",
        reference_source="exact simulated pose",
        extra={
            "world": spec.name,
            "description": spec.description,
            "seed": spec.seed,
            "laps": spec.laps,
            "closed_loop": spec.route().closed,
            "route_length_m": data.route_length,
            "sampling": asdict(spec.sampling),
            "laser": {**asdict(spec.laser), "resolution_deg": spec.laser.resolution_deg},
            "odometry_model": spec.odometry.as_dict(),
            "wall_segments": int(len(data.plan.walls)),
            "doorways": [d.as_dict() for d in data.plan.doorways],
            "spaces": [{"name": space.name, "rect": list(space.rect)} for space in data.plan.spaces],
            "doorway_crossings": [c.as_dict() for c in data.crossings],
        },
    )
