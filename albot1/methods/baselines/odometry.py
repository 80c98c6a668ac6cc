"""Dead reckoning: the thesis's "simple mathematical transformation".

The pose at each scan is the odometry the method is given (after any
degradation), re-expressed relative to the first scan so every method's map
frame starts at the origin; the map is every scan projected with it,
thinned on a voxel grid so large logs stay storable.

Its settings' values live in ``baselines/odometry.toml`` (see
:mod:`albot1.config.presets`); the field defaults below exist only so the
config can be built directly in code and tests, and equal that file's
``[presets.default]`` (a unit test checks it).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from pydantic import BaseModel, Field

from albot1.config.method_model import MethodConfig
from albot1.config.presets import TomlPresets
from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame
from albot1.geometry import se2
from albot1.methods.baselines.point_map import ThinnedPointMap


class OdometryConfig(MethodConfig):
    """Config of the odometry baseline."""

    map_voxel_m: float = Field(0.05, gt=0, description="grid cell for thinning the projected map points")
    map_every: int = Field(1, ge=1, description="project every n-th scan into the map")


class OdometryMapper:
    name: ClassVar[str] = "odometry"
    config_model: ClassVar[type[BaseModel]] = OdometryConfig
    presets = TomlPresets()

    def __init__(self, config: OdometryConfig, *, seed: int = 0) -> None:
        self.config = config
        self._origin: np.ndarray | None = None
        self._poses: list[np.ndarray] = []
        self._map = ThinnedPointMap(config.map_voxel_m)

    def process(self, frame: Frame) -> None:
        if self._origin is None:
            self._origin = frame.odometry
        pose = se2.between(self._origin, frame.odometry)
        self._poses.append(pose)
        if frame.index % self.config.map_every:
            return
        self._map.add(se2.transform_points(pose, frame.scan.points()))

    def finish(self) -> MapperOutput:
        points = self._map.points()
        n = len(self._poses)
        return MapperOutput(
            poses=np.asarray(self._poses, dtype=float).reshape(-1, 3),
            map=MapData(points=points),
            counters={"views": n, "updates": n, "map_points": int(len(points))},
        )
