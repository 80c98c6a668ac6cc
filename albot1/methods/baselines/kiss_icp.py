"""KISS-ICP odometry on planar scans, with the robot's odometry as the initial guess.

KISS-ICP (Vizzo et al., RA-L 2023; pip ``kiss-icp``, pinned ``==1.3.0``)
registers each scan against a local voxel map with point-to-point ICP, a
Geman-McClure kernel and an adaptive correspondence threshold. Here a 2D
scan is a 3D cloud with z = 0 in the robot (base) frame.

How the odometry prior is injected. ``KissICP.register_frame`` (1.3.0) has
no initial-guess argument: it predicts ``last_pose @ last_delta`` (a
constant-velocity model, which alone gives 11.8 m ATE on intel-corrected,
see docs/baselines.md), registers, then updates the threshold, the map and
``last_delta`` unconditionally. Overwriting ``last_delta`` before each call
would inject the prior too, but would leave no way to check a result before
it enters the map. This mapper therefore drives the public Python components
that ``register_frame`` is made of -- ``kiss_icp.voxelization.
voxel_down_sample``, ``kiss_icp.mapping.VoxelHashMap``, ``kiss_icp.registration.
Registration.align_points_to_map(initial_guess=...)`` and the thresholds of
``kiss_icp.threshold`` -- in the same order, with these changes:

1. the initial guess is ``last_pose`` composed with the *odometry* increment
   since the previous scan (``odometry_prior = false`` restores the
   constant-velocity model, for comparison);
2. the result is checked (finite, else :class:`BaselineError`; its
   correction of the guess within ``max_correction_m`` /
   ``max_correction_deg``, else rejected) *before* it touches the threshold
   model or the map: a rejected result never feeds the threshold, the scan's
   pose (and its place in the map) is the odometry prediction, and more than
   ``max_consecutive_failures`` rejections in a row is a
   :class:`BaselineError` (the method has lost track);
3. the pose is projected to SE(2) (x, y, yaw) at every scan, so z, roll and
   pitch cannot creep in through round-off; the largest out-of-plane
   component removed is reported in ``extras``;
4. a scan enters the voxel map only after ``map_update_distance_m`` or
   ``map_update_angle_deg`` of motion since the last insertion (both 0 =
   every scan, as KISS-ICP), and the two thinning resolutions are explicit
   settings instead of KISS-ICP's fixed 0.5 x and 1.5 x the voxel size.

These components and their signatures are those of kiss-icp 1.3.0 (hence
the exact pin). Deskewing is off: the preprocessor is not used, its only
remaining job (range cropping) is done here. Registration runs on one
thread: a fixed summation order makes runs bit-for-bit repeatable (TBB's
parallel reductions do not promise one), and ~50 source points per scan
leave little to parallelise.

The laser's mounting offset is applied by the runner for every method
(:func:`albot1.data.transforms.sensor_frame`): the mapper is given the
laser's trajectory, in which the scans are centred, and its poses are moved
back to the robot afterwards; so the scan is used as it comes.

Counters: ``views`` (scans processed), ``updates`` (scans inserted into
the voxel map; they play the role of keyframes), ``registrations`` (ICP
runs), ``registration_failures`` (results rejected by the correction
bounds), ``odometry_fallbacks`` (scans whose pose is the odometry
prediction: rejected results plus scans with fewer than ``min_points``
usable points) and ``map_points`` (points of the stored map).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from pydantic import BaseModel, Field

from albot1.config.method_model import MethodConfig
from albot1.config.presets import TomlPresets
from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame
from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.point_map import ThinnedPointMap

if TYPE_CHECKING:
    from kiss_icp.mapping import VoxelHashMap
    from kiss_icp.registration import Registration


#: How many scan indices of odometry fallbacks ``extras`` lists (the counter has the total).
_LISTED_FALLBACKS = 200


class KissIcpConfig(MethodConfig):
    """Types, bounds and meaning of the KISS-ICP baseline's settings.

    The values live in ``baselines/kiss-icp.toml`` (see :mod:`albot1.config.presets`).
    """

    voxel_size_m: float = Field(
        gt=0,
        description=(
            "KISS-ICP map voxel; correspondences are searched in the 3x3 neighbouring voxels, so it "
            "also bounds how far ICP can reach"
        ),
    )
    map_point_spacing_m: float = Field(
        gt=0,
        description=(
            "scans are thinned to one point per cell of this size before insertion into the map (KISS-ICP: 0.5 x voxel)"
        ),
    )
    source_point_spacing_m: float = Field(
        gt=0,
        description="scans are thinned to one point per cell of this size for registration (KISS-ICP: 1.5 x voxel)",
    )
    map_update_distance_m: float = Field(
        ge=0,
        description=(
            "insert a scan into the voxel map only after moving this far from the last insertion "
            "(or turning map_update_angle_deg); 0 and 0 = every scan, as KISS-ICP"
        ),
    )
    map_update_angle_deg: float = Field(ge=0, description="see map_update_distance_m")
    min_range_m: float = Field(ge=0, description="beams shorter than this are dropped")
    max_range_m: float = Field(
        gt=0,
        description=(
            "beams longer than this are dropped; also the local map radius and the threshold's rotation lever arm"
        ),
    )
    max_points_per_voxel: int = Field(ge=1, description="points kept per map voxel")
    initial_threshold_m: float = Field(gt=0, description="adaptive threshold before any motion sample exists")
    min_motion_th_m: float = Field(ge=0, description="model deviations below this do not update the adaptive threshold")
    fixed_threshold_m: float = Field(
        ge=0, description="fixed correspondence threshold sigma; 0 = adaptive (KISS-ICP's model)"
    )
    refine_threshold_m: float = Field(
        ge=0, description="second ICP pass from the first one's result with this fixed threshold sigma; 0 = single pass"
    )
    max_num_iterations: int = Field(ge=1, description="ICP iteration cap")
    convergence_criterion: float = Field(gt=0, description="ICP stops when the update's norm is below this")
    odometry_prior: bool = Field(
        description="initial guess from the odometry increment (true) or KISS-ICP's constant-velocity model (false)"
    )
    min_points: int = Field(ge=3, description="scans with fewer usable points keep the odometry prediction")
    max_correction_m: float = Field(gt=0, description="a registration moving the guess further than this is rejected")
    max_correction_deg: float = Field(gt=0, description="a registration rotating the guess more than this is rejected")
    max_consecutive_failures: int = Field(
        ge=0, description="more consecutive rejected registrations raise BaselineError"
    )
    map_voxel_m: float = Field(
        gt=0, description="grid cell thinning the stored map (every scan projected with its pose)"
    )


class KissIcpMapper:
    """KISS-ICP 1.3.0 components driven scan by scan with an odometry initial guess (module doc)."""

    name: ClassVar[str] = "kiss-icp"
    config_model: ClassVar[type[BaseModel]] = KissIcpConfig
    presets = TomlPresets()
    #: KISS-ICP's modules this mapper imports when built (below): the bench's forkserver imports them once for
    #: every cell (``Mapper``'s optional ``preload_modules``), ~14 ms of CPU a cell otherwise pays (issue 24).
    preload_modules: ClassVar[tuple[str, ...]] = (
        "kiss_icp.mapping",
        "kiss_icp.registration",
        "kiss_icp.threshold",
        "kiss_icp.voxelization",
        "kiss_icp.config.parser",
    )

    def __init__(self, config: KissIcpConfig, *, seed: int = 0) -> None:
        # KISS-ICP is deterministic; ``seed`` is accepted for the protocol.
        from kiss_icp.mapping import VoxelHashMap
        from kiss_icp.registration import Registration
        from kiss_icp.threshold import AdaptiveThreshold, FixedThreshold

        self.config = config
        self._local_map: VoxelHashMap = VoxelHashMap(
            voxel_size=config.voxel_size_m,
            max_distance=config.max_range_m,
            max_points_per_voxel=config.max_points_per_voxel,
        )
        self._registration: Registration = Registration(
            max_num_iterations=config.max_num_iterations,
            convergence_criterion=config.convergence_criterion,
            max_num_threads=1,
        )
        self._threshold: Any
        if config.fixed_threshold_m > 0:
            self._threshold = FixedThreshold(config.fixed_threshold_m)
        else:
            self._threshold = AdaptiveThreshold(_threshold_settings(config))
        self._max_correction_rad = math.radians(config.max_correction_deg)
        self._map_update_angle_rad = math.radians(config.map_update_angle_deg)
        self._last_inserted: FloatArray | None = None
        self._map = ThinnedPointMap(config.map_voxel_m)
        self._poses: list[FloatArray] = []
        self._last_odometry: FloatArray | None = None
        self._last_delta = np.zeros(3)
        self._consecutive_failures = 0
        self._counters = {
            "views": 0,
            "updates": 0,
            "registrations": 0,
            "registration_failures": 0,
            "odometry_fallbacks": 0,
        }
        self._fallback_scans: list[int] = []
        self._corrections: list[tuple[float, float]] = []
        self._out_of_plane = 0.0

    # -- per scan --------------------------------------------------------------------------------------------

    def process(self, frame: Frame) -> None:
        """Register one scan (see the module doc for the order of steps and the checks)."""
        from kiss_icp.voxelization import voxel_down_sample

        odometry = np.asarray(frame.odometry, dtype=float)
        if odometry.shape != (3,) or not np.isfinite(odometry).all():
            raise BaselineError(
                f"kiss-icp: scan {frame.index}: odometry {odometry.tolist()} is not a finite "
                f"(x, y, theta); expected finite odometry at every scan"
            )
        self._counters["views"] += 1
        cloud = self._base_cloud(frame)
        frame_down = voxel_down_sample(cloud, self.config.map_point_spacing_m)

        if self._last_odometry is None:
            pose = np.zeros(3)
        else:
            pose = self._register(frame, odometry, frame_down, voxel_down_sample)
            self._last_delta = np.array(se2.between_pose(self._poses[-1], pose))
        self._last_odometry = odometry
        self._poses.append(pose)
        if len(frame_down) and self._moved_since_insertion(pose):
            self._local_map.update(frame_down, se2.pose_to_se3(pose))
            self._last_inserted = pose
            self._counters["updates"] += 1
        self._map.add(cloud[:, :2] @ se2.rows_rotation(pose[2]) + pose[:2])

    def _moved_since_insertion(self, pose: FloatArray) -> bool:
        """Whether the pose is far enough from the last one inserted into the voxel map."""
        if self._last_inserted is None:
            return True
        step = se2.between_pose(self._last_inserted, pose)
        return (
            math.hypot(step[0], step[1]) >= self.config.map_update_distance_m
            or abs(float(step[2])) >= self._map_update_angle_rad
        )

    def _base_cloud(self, frame: Frame) -> FloatArray:
        """Beams with a return within the range limits as 3D points (z = 0) in the scan's frame, ``(k, 3)``."""
        points = frame.scan.points(self.config.min_range_m, self.config.max_range_m)
        cloud = np.zeros((len(points), 3))
        cloud[:, :2] = points
        return cloud

    def _register(self, frame: Frame, odometry: FloatArray, frame_down: FloatArray, down_sample: Any) -> FloatArray:
        """The pose of this scan: ICP from the predicted pose, or the prediction when ICP cannot be trusted."""
        assert self._last_odometry is not None
        step = se2.between_pose(self._last_odometry, odometry) if self.config.odometry_prior else self._last_delta
        guess = np.array(se2.compose_pose(self._poses[-1], step))
        source = down_sample(frame_down, self.config.source_point_spacing_m)
        if len(source) < self.config.min_points:
            return self._fallback(frame.index, guess)

        sigma = float(self._threshold.get_threshold())
        guess_matrix = se2.pose_to_se3(guess)
        result = self._align(source, guess_matrix, sigma)
        if self.config.refine_threshold_m > 0 and np.isfinite(result).all():
            result = self._align(source, result, self.config.refine_threshold_m)
        self._counters["registrations"] += 1
        if not np.isfinite(result).all():
            raise BaselineError(
                f"kiss-icp diverged at scan {frame.index}: registration of {len(source)} points returned a "
                f"non-finite pose from the initial guess {np.round(guess, 4).tolist()} (threshold {sigma:.3g} m)"
            )
        pose, out_of_plane = se2.pose_from_se3(result)
        self._out_of_plane = max(self._out_of_plane, out_of_plane)

        correction = se2.between_pose(guess, pose)
        shift, turn = math.hypot(correction[0], correction[1]), abs(float(correction[2]))
        if shift > self.config.max_correction_m or turn > self._max_correction_rad:
            self._counters["registration_failures"] += 1
            self._consecutive_failures += 1
            if self._consecutive_failures > self.config.max_consecutive_failures:
                raise BaselineError(
                    f"kiss-icp lost track at scan {frame.index}: {self._consecutive_failures} consecutive "
                    f"registrations moved the odometry prediction by more than {self.config.max_correction_m} m "
                    f"or {self.config.max_correction_deg} deg (last: {shift:.3f} m, {math.degrees(turn):.2f} deg); "
                    f"expected at most max_consecutive_failures = {self.config.max_consecutive_failures}"
                )
            return self._fallback(frame.index, guess)

        self._consecutive_failures = 0
        self._corrections.append((shift, turn))
        self._threshold.update_model_deviation(se2.pose_to_se3(correction))
        return pose

    def _align(self, source: FloatArray, initial: FloatArray, sigma: float) -> FloatArray:
        """One KISS-ICP registration: gate 3 sigma, kernel sigma, as ``KissICP.register_frame`` 1.3.0 calls it."""
        result = self._registration.align_points_to_map(
            points=source,
            voxel_map=self._local_map,
            initial_guess=initial,
            max_correspondance_distance=3.0 * sigma,
            kernel=sigma,
        )
        return np.asarray(result, dtype=float)

    def _fallback(self, index: int, guess: FloatArray) -> FloatArray:
        self._counters["odometry_fallbacks"] += 1
        if len(self._fallback_scans) < _LISTED_FALLBACKS:
            self._fallback_scans.append(index)
        return guess

    # -- end of run ------------------------------------------------------------------------------------------

    def finish(self) -> MapperOutput:
        """Poses, the thinned point map, counters and the registration statistics."""
        points = self._map.points()
        counters: dict[str, int | float] = {**self._counters, "map_points": int(len(points))}
        corrections = np.asarray(self._corrections, dtype=float).reshape(-1, 2)
        extras: dict[str, Any] = {
            "kiss_icp": {
                "final_threshold_m": float(self._threshold.get_threshold()) if self._poses else None,
                "local_map_points": int(len(self._local_map.point_cloud())),
                "max_out_of_plane_removed": self._out_of_plane,
                "fallback_scans": self._fallback_scans,
                "fallback_scans_truncated": self._counters["odometry_fallbacks"] > len(self._fallback_scans),
                "correction_m": _stats(corrections[:, 0]),
                "correction_deg": _stats(np.degrees(corrections[:, 1])),
            }
        }
        return MapperOutput(
            poses=np.asarray(self._poses, dtype=float).reshape(-1, 3),
            map=MapData(points=points),
            counters=counters,
            extras=extras,
        )


def _threshold_settings(config: KissIcpConfig) -> Any:
    """The KISS-ICP settings object its ``AdaptiveThreshold`` reads (only these three fields)."""
    from kiss_icp.config.config import AdaptiveThresholdConfig, DataConfig
    from kiss_icp.config.parser import KISSConfig

    # Explicit keyword values take precedence over KISS-ICP's own env vars (pydantic-settings' init source).
    return KISSConfig(
        data=DataConfig(max_range=config.max_range_m, min_range=config.min_range_m, deskew=False),
        adaptive_threshold=AdaptiveThresholdConfig(
            initial_threshold=config.initial_threshold_m, min_motion_th=config.min_motion_th_m
        ),
    )


def _stats(values: FloatArray) -> dict[str, float | int] | None:
    """Median, p95, max and count of a per-scan quantity (None when empty)."""
    if not len(values):
        return None
    return {
        "median": float(np.median(values)),
        "p95": float(np.percentile(values, 95)),
        "max": float(np.max(values)),
        "n": int(len(values)),
    }
