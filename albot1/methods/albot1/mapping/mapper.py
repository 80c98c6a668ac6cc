"""Albot1's perceptual mapping (thesis Algorithm 4) behind the Mapper protocol.

Each scan becomes a view; its landmarks are recognised against the
landmarks tracked since the last update. While at least three are
recognised the robot only localises on them. With fewer, the map is
updated: with the current view if the previous step was the update, else
with the previous view (its landmarks are then tracked afresh and
recognition re-runs on the current view, which can trigger a second update
in the same step). When no landmark can place the robot, the odometry step
is composed instead (the thesis's path integration in featureless
corridors).

Everything runs in the thesis frame; poses and map are handed out in a
REP-103 map frame (the first view at the origin, heading 0).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel

from albot1.config.presets import TomlPresets
from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame
from albot1.geometry.se2 import Pose, between_pose, compose_pose
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.errors import MappingError
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.perceptual_map import PerceptualMap
from albot1.methods.albot1.mapping.plus import PlusLocaliser
from albot1.methods.albot1.mapping.start_poses import ODOMETRY_TURNS
from albot1.methods.albot1.mapping.step_kernels import perceive_scan
from albot1.methods.albot1.mapping.update import UpdateOutcome, UpdateParams, update_map
from albot1.methods.albot1.perception.frames import thesis_to_rep_pose, thesis_to_rep_segments
from albot1.methods.albot1.perception.kernels import PerceptionKernels
from albot1.methods.albot1.perception.landmarks import Landmarks, find_landmarks
from albot1.methods.albot1.perception.recognition import Tracked, motion_step, recognise
from albot1.methods.albot1.perception.view import View, construct_view
from albot1.methods.albot1.warm_up import together, warm_up

#: The thesis presets' localisation asks ``robust_starts`` for no odometry turns (Albot1+'s start poses only).
_NO_TURNS = np.empty(0)


@dataclass(slots=True)
class _Step:
    """What Algorithm 4 keeps of the previous step."""

    index: int
    view: View
    landmarks: Landmarks
    tracked: Tracked
    odometry: tuple[float, float, float]
    pose: Pose


@dataclass(frozen=True, slots=True)
class UpdateEvent:
    """One map update as an observer (:attr:`Albot1Mapper.on_update`) sees it.

    Chapter 4's places layer marks the surfaces entering the map with the
    current place and counts the map surfaces the view co-locates with
    (deleted, extended or trimmed) before they go. ``view`` is ``initial``,
    ``current``, ``previous`` or ``forced`` (:meth:`Albot1Mapper.force_update`);
    ``view_map`` is that view's surfaces placed in the map (thesis frame).
    """

    scan: int
    view: str
    view_scan: int
    pose: Pose
    outcome: UpdateOutcome
    view_map: NDArray[np.float64]


@dataclass(slots=True)
class _Counts:
    views: int = 0
    updates: int = 0
    updates_current_view: int = 0
    updates_previous_view: int = 0
    double_updates: int = 0
    path_integration: int = 0
    odometry_pose_steps: int = 0
    empty_views: int = 0
    single_surface_views: int = 0
    odometry_jumps: int = 0
    stationary_steps: int = 0
    surfaces_added: int = 0
    surfaces_deleted: int = 0
    surfaces_extended: int = 0
    surfaces_trimmed: int = 0
    recognised: list[int] = field(default_factory=list)


class Albot1Mapper:
    """The Albot1 perceptual mapper (thesis chapter 3, section 3.1)."""

    name: ClassVar[str] = "albot1"
    config_model: ClassVar[type[BaseModel]] = Albot1Config
    presets = TomlPresets()

    def __init__(self, config: Albot1Config, *, seed: int = 0) -> None:
        # The method is deterministic; ``seed`` is accepted for the protocol.
        self.config = config
        self._pk = PerceptionKernels(config.accelerate)
        self._mk = MappingKernels(config.accelerate)
        self._view_params = config.view_params()
        self._update_params = UpdateParams(
            delete_margin=config.delete_margin_m,
            correspond_angle=math.radians(config.correspond_angle_deg),
            correspond_distance=config.correspond_distance_m,
            partial_without_match=config.partial_without_match,
            polygon=config.update_polygon,
            margin_from=config.delete_margin_from,
        )
        self._rec_angle = math.radians(config.recognition_angle_deg)
        self._angle_floor = math.radians(config.goodness_angle_floor_deg)
        self._stationary_rad = math.radians(config.stationary_deg)
        self.map = PerceptualMap()
        #: The landmark map: ids ``(m,)``, surfaces as placed ``(m, 4)``, endpoint labels ``(m, 2)`` (the last row
        #: of an id is its record), read by the compiled localisation (:func:`~.localise_kernels.robust_starts`)
        self._landmark_rows: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.int64]] = (
            np.empty(0, dtype=np.int64),
            np.empty((0, 4)),
            np.empty((0, 2), dtype=np.int64),
        )
        self._poses: list[Pose] = []
        self._prev: _Step | None = None
        self._u_step = -1
        self._n = 0
        self._counts = _Counts()
        self._trace: list[dict[str, Any]] = []
        # Albot1+ (pose_estimate="robust"): the localiser, this scan's points and odometry, the last update view's.
        self._plus = (
            PlusLocaliser(config.plus_params(), self._mk, config.max_range_m)
            if config.pose_estimate == "robust"
            else None
        )
        self._points = np.empty((0, 2))
        #: Albot1+'s :func:`perceive_scan` arguments: landmark length, the points' range and stride (0: no points)
        self._perceive_args = (
            config.landmark_min_length_m,
            config.max_range_m,
            config.scan_beam_stride if config.scan_refinement else 0,
        )
        self._odometry: Pose = (0.0, 0.0, 0.0)
        self._update_odometry: Pose = (0.0, 0.0, 0.0)
        #: Called after every map update (chapter 4's places observe the map through it); None: nobody listens.
        self.on_update: Callable[[UpdateEvent], None] | None = None

    @property
    def last_view(self) -> View | None:
        """The view of the last processed scan (thesis frame; None before the first)."""
        return None if self._prev is None else self._prev.view

    @property
    def last_pose(self) -> Pose | None:
        """The pose of the last processed scan in the map (thesis frame; None before the first)."""
        return None if self._prev is None else self._prev.pose

    def force_update(self) -> None:
        """Update the map with the last scan's view at its pose now, as if Algorithm 4 had decided to.

        Chapter 4's Algorithm 5 (line 16) forces this after an exit is
        crossed, so the surfaces in view re-enter the map marked with the new
        place. Landmark tracking restarts from that view, as after any update.
        Counted in ``updates`` (not in the current/previous-view counts).
        """
        prev = self._prev
        if prev is None:
            raise MappingError("force_update before the first scan")
        prev.tracked = self._update(
            prev.view,
            prev.landmarks,
            prev.pose,
            prev.index,
            trigger=prev.index,
            which="forced",
            source="current",
            reference=-1,
            odometry=prev.odometry,
        )

    # -- Algorithm 4 -------------------------------------------------------
    @property
    def kernels(self) -> tuple[PerceptionKernels, MappingKernels]:
        """The kernel sets this mapper calls (compiled unless ``accelerate`` is false)."""
        return self._pk, self._mk

    #: warm-ups made inside it are compiled as one (the bench's forkserver warms every preset so)
    warm_up_together = staticmethod(together)

    def warm_up(self, announce: Callable[[str], None] | None = None) -> None:
        """Compile every kernel now (or load numba's cache), before the runner's timed loop (``Mapper.warm_up``)."""
        if self.config.accelerate:
            warm_up(self.kernels, announce, skip=MappingKernels.not_called(self.config.pose_estimate))

    def process(self, frame: Frame) -> None:
        n = self._n
        scan = frame.scan
        try:
            if self._plus is None:
                view = construct_view(scan.ranges, scan.angles, self._view_params, self._pk)
                lms = find_landmarks(view, self.config.landmark_min_length_m, self._pk)
            else:  # the view, its landmarks and the scan's points in one kernel call (issue 24: .step_kernels)
                view, lms, self._points = perceive_scan(
                    scan.ranges, scan.angles, self._view_params, *self._perceive_args, self._mk.perceive
                )
        except (ValueError, TypeError) as exc:
            raise MappingError(f"scan {frame.index}: cannot build a view: {exc}") from exc
        odo = (float(frame.odometry[0]), float(frame.odometry[1]), float(frame.odometry[2]))
        if not all(map(math.isfinite, odo)):
            raise MappingError(f"scan {frame.index}: odometry {odo} is not finite")
        self._odometry = odo
        c = self._counts
        c.views += 1
        if len(view) == 0:
            c.empty_views += 1
        elif len(view) == 1:
            c.single_surface_views += 1
        prev = self._prev
        if prev is None:
            pose: Pose = (0.0, 0.0, 0.0)
            tracked = self._update(
                view, lms, pose, n, trigger=n, which="initial", source="initial", reference=-1, odometry=odo
            )
            c.recognised.append(0)
        else:
            tracked, pose = self._step(n, view, lms, odo, prev)
        self._poses.append(pose)
        self._prev = _Step(n, view, lms, tracked, odo, pose)
        self._n += 1

    def _step(
        self, n: int, view: View, lms: Landmarks, odo: tuple[float, float, float], prev: _Step
    ) -> tuple[Tracked, Pose]:
        c, cfg = self._counts, self.config
        rel = between_pose(prev.odometry, odo)
        dist = math.hypot(rel[0], rel[1])
        if dist > cfg.odometry_jump_m:
            c.odometry_jumps += 1
        if dist <= cfg.stationary_m and abs(rel[2]) <= self._stationary_rad:
            c.stationary_steps += 1
        step = motion_step(rel, cfg.motion_model)
        rl = self._recognise(prev.tracked, lms, step)
        c.recognised.append(len(rl))
        if len(rl) >= cfg.min_landmarks:
            return rl, self._pose_between_updates(rl, prev.pose, step)
        if n - self._u_step != 1:
            # Lines 18-23: update with the previous view at its own pose, track its landmarks afresh
            # and recognise again (line 23, "go back to step 11").
            prev.tracked = self._update(
                prev.view,
                prev.landmarks,
                prev.pose,
                prev.index,
                trigger=n,
                which="previous",
                source="stored",
                reference=-1,
                odometry=prev.odometry,
            )
            rl = self._recognise(prev.tracked, lms, step)
            if len(rl) >= cfg.min_landmarks:
                return rl, self._pose_between_updates(rl, prev.pose, step)
            c.double_updates += 1
        # Lines 13-17: update with the current view.
        reference: int | None
        if self._plus is not None:
            pose, reference = self._robust_pose(rl, prev.pose, step)
        else:
            loc = self._localise(rl)
            pose = compose_pose(prev.pose, step) if loc is None else loc[0]
            reference = None if loc is None else loc[1]
        if reference is None:
            c.path_integration += 1
            source, ref = "odometry", -1
        else:
            source, ref = ("landmark" if self._plus is None else "robust"), reference
        tracked = self._update(
            view,
            lms,
            pose,
            n,
            trigger=n,
            which="current",
            source=source,
            reference=ref,
            recognised=len(rl),
            odometry=odo,
        )
        return tracked, pose

    # -- stages ------------------------------------------------------------
    def _recognise(self, previous: Tracked, lms: Landmarks, step: Pose) -> Tracked:
        return recognise(
            previous,
            lms.surfaces,
            lms.kinds,
            step,
            max_angle=self._rec_angle,
            max_distance=self.config.recognition_distance_m,
            matching=self.config.recognition_matching,
            kernels=self._pk,
        )

    def _localise(self, rl: Tracked) -> tuple[Pose, int] | None:
        """The thesis's ``localize``: the pose from the best recognised landmark and that landmark's id, or None.

        :func:`~.localisation.localise` is the thesis's steps in Python; this is the same steps compiled, in
        the kernel Albot1+ starts from (:func:`~.localise_kernels.robust_starts`: the same operations in the
        same order, held to the same bits by the tests), without Albot1+'s start poses (no turns; the
        odometry it would add is not read). One kernel call a scan instead of a Python loop over the landmarks.
        """
        starts, _, _, _, best = self._starts(rl, (0.0, 0.0, 0.0), _NO_TURNS)
        if best < 0:
            return None
        x, y, phi = starts[0].tolist()  # the chosen candidate's pose, as the Python floats localise returns
        return (x, y, phi), int(rl.ids[best])

    def _starts(
        self, rl: Tracked, odometry: Pose, turns: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_], int]:
        """:func:`~.localise_kernels.robust_starts` on the tracked list ``rl`` and the landmark map."""
        cfg = self.config
        return self._mk.robust_starts(
            rl.surfaces,
            rl.kinds,
            rl.ids,
            rl.side,
            rl.prev_distance if cfg.goodness_distance_view == "previous" else rl.prev_distance_current,
            rl.gap,
            rl.angle_diff,
            *self._landmark_rows,
            odometry[0],
            odometry[1],
            odometry[2],
            turns,
            cfg.outlier_min_candidates,
            cfg.goodness_gap_floor_m,
            self._angle_floor,
        )

    def _robust_pose(self, rl: Tracked, prev_pose: Pose, step: Pose) -> tuple[Pose, int | None]:
        """Albot1+: from the thesis's pose (or the odometry step), robust least squares over every landmark.

        Returns the pose and the landmark id of the thesis's localisation it
        started from (None: no landmark could place the robot; the start was
        the odometry). The landmark rows, the thesis's localisation and the
        start poses are one kernel (:func:`~.localise_kernels.robust_starts`:
        ``localise`` then ``start_poses``, with the same bits).
        """
        assert self._plus is not None
        cfg = self.config
        odometry = compose_pose(prev_pose, step)
        starts, lm_view, lm_map, ok, best = self._starts(rl, odometry, ODOMETRY_TURNS)
        reference = None if best < 0 else int(rl.ids[best])
        since = motion_step(between_pose(self._update_odometry, self._odometry), cfg.motion_model)
        return self._plus.pose_stable(
            starts, lm_view, lm_map, ok, self._points, since, self._odometry, reference is not None
        ), reference

    def _pose_between_updates(self, rl: Tracked, prev_pose: Pose, step: Pose) -> Pose:
        """Localise on the tracked landmarks, else compose the odometry step (note 13, docs/albot1-mapper.md).

        Albot1+ refines the same start (:meth:`_robust_pose`); a step whose
        start was the odometry still counts in ``odometry_pose_steps``.
        """
        if self._plus is not None:
            pose, reference = self._robust_pose(rl, prev_pose, step)
            if reference is None:
                self._counts.odometry_pose_steps += 1
            return pose
        if self.config.pose_between_updates == "localise":
            loc = self._localise(rl)
            if loc is not None:
                return loc[0]
        self._counts.odometry_pose_steps += 1
        return compose_pose(prev_pose, step)

    def _update(
        self,
        view: View,
        lms: Landmarks,
        pose: Pose,
        view_scan: int,
        *,
        trigger: int,
        which: str,
        source: str,
        reference: int,
        odometry: Pose,
        recognised: int | None = None,
    ) -> Tracked:
        """``updatePM`` with ``view`` placed at ``pose``; returns the landmark list reset to its landmarks.

        ``odometry`` is the view's own odometry: Albot1+ measures the motion
        since the update from it.
        """
        c = self._counts
        view_map = self._mk.place_segments(view.surfaces, pose[0], pose[1], math.cos(pose[2]), math.sin(pose[2]))
        self._update_odometry = odometry
        if self._plus is not None:
            self._plus.reset(view_map, pose, odometry)
        out = update_map(self.map, view_map, (pose[0], pose[1]), view_scan, self._update_params, self._mk)
        if self.on_update is not None:
            self.on_update(UpdateEvent(trigger, which, view_scan, pose, out, view_map))
        ids = out.view_ids[lms.index]
        # Landmark positions are kept as placed now: later updates may edit the map surfaces (note 12).
        lm_map = view_map.take(lms.index, axis=0)  # (``take``: the rows of ``[lms.index]``, cheaper)
        self._landmark_rows = (ids, lm_map, lms.kinds)  # the compiled localisation reads them (robust_starts)
        self._u_step = view_scan
        c.surfaces_added += len(out.added)
        c.surfaces_deleted += len(out.deleted)
        c.surfaces_extended += len(out.extended)
        c.surfaces_trimmed += len(out.trimmed)
        if which != "initial":
            c.updates += 1
            if which == "current":
                c.updates_current_view += 1
            elif which == "previous":
                c.updates_previous_view += 1
        self._trace.append(
            {
                "scan": trigger,
                "view": which,
                "view_scan": view_scan,
                "pose_source": source,
                "reference_id": reference,
                "recognised": recognised,
                "surfaces": len(view),
                "landmarks": len(lms),
                "added": len(out.added),
                "deleted": len(out.deleted),
                "extended": len(out.extended),
                "trimmed": len(out.trimmed),
            }
        )
        return Tracked.fresh(lms.surfaces, lms.kinds, ids)

    # -- output ------------------------------------------------------------
    def finish(self) -> MapperOutput:
        c = self._counts
        ids = self.map.ids()
        segments = thesis_to_rep_segments(self.map.segments(ids))
        poses = np.asarray([thesis_to_rep_pose(p) for p in self._poses], dtype=float).reshape(-1, 3)
        rec = np.asarray(c.recognised, dtype=float)
        counters: dict[str, int | float] = {
            name: getattr(c, name)
            for name in (
                "views",
                "updates",
                "updates_current_view",
                "updates_previous_view",
                "double_updates",
                "path_integration",
                "odometry_pose_steps",
                "empty_views",
                "single_surface_views",
                "odometry_jumps",
                "stationary_steps",
                "surfaces_added",
                "surfaces_deleted",
                "surfaces_extended",
                "surfaces_trimmed",
            )
        }
        counters["map_surfaces"] = len(self.map)
        if self._plus is not None and (self.config.degenerate_sd_m > 0.0 or self.config.gate_probability > 0.0):
            # Albot1+'s degeneracy screen (docs/albot1-mapper.md, "Albot1+"): only when it is on, so the other
            # presets' counters stay as they were.
            counters["plus_degenerate_views"] = self._plus.degenerate_views
            counters["plus_gate_rejections"] = self._plus.gate_rejections
        if self._plus is not None and self.config.ambiguity_probability > 0.0:
            counters["plus_ambiguous_views"] = self._plus.ambiguous_views
        if self._plus is not None and self.config.turn_bound_floor_deg > 0.0:
            counters["plus_turn_bounded_views"] = self._plus.turn_bounded_views
        if self._plus is not None and self._plus.window is not None:
            counters["plus_window_views"] = self._plus.window_views
        counters["updates_per_view"] = c.updates / c.views if c.views else 0.0
        counters["landmarks_recognised_mean"] = float(rec[1:].mean()) if len(rec) > 1 else 0.0
        return MapperOutput(
            poses=poses,
            map=MapData(segments=segments, segment_properties=self.map.properties(ids)),
            counters=counters,
            extras={
                "update_trace": self._trace,
                "landmarks_recognised": c.recognised,
                "frame": "REP-103 map frame: first view at the origin, heading 0 (x forward)",
            },
        )
