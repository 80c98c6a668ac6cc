"""``GtsamGraphMapper``: graph-based SLAM behind the mapper protocol.

The method of Grisetti et al. (2010), the thesis's section 2.2.3:

* a **node** whenever odometry says the robot moved 0.5 m or turned 0.5 rad
  since the last node; its scan is stored in the node's frame;
* a **sequential edge** from point-to-line ICP of the node's scan against a
  local map (the last ``local_map_nodes`` node scans), the odometry
  increment being the initial guess and a weak prior; when the match is poor
  (not converged, low inlier fraction, large residual or an implausible
  correction) the edge is the odometry increment with a larger covariance;
  with ``odometry_trust`` (off by default) the odometry's heading joins it as its own
  factor where the odometry has shown itself the better of the two
  (:mod:`.odometry_trust`);
* **loop-closure edges** from ICP against the submaps of earlier nodes near
  the current estimate (:mod:`.loop_closure`), added only after strict tests
  and with a robust kernel;
* **place recognition** for loops whose drift is beyond that search: a
  branch-and-bound match of the local map over the region the drift allows
  (:mod:`.place_recognition`), verified the same way
  (``place_closures_accepted`` counts these among ``loop_closures_accepted``);
* GTSAM **ISAM2** after every node, a final batch **Levenberg-Marquardt** in
  :meth:`GtsamGraphMapper.finish`.

The pose of a scan is the optimised pose of the node it belongs to composed
with the odometry from that node to the scan; the map is every scan
projected with those poses, thinned on a grid.

The class is the composition of four parts, one module each: the front end
(:mod:`.frontend`: scan tracking, the sequential edges), the loop closer
(:mod:`.loop_closer`), place recognition (:mod:`.place_recognition`) and the
back end (:mod:`.backend`: graph, ISAM2, final optimisation, scan poses and
map projection). They share one set of counters.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import ClassVar

import numpy as np
from pydantic import BaseModel

from albot1.config.presets import TomlPresets
from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame
from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.gtsam_graph import block_sums, icp_loop, nearest
from albot1.methods.baselines.gtsam_graph.backend import BackEnd
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.errors import GraphError, RegistrationError
from albot1.methods.baselines.gtsam_graph.frontend import FrontEnd, preprocess
from albot1.methods.baselines.gtsam_graph.loop_closer import LoopCloser
from albot1.methods.baselines.gtsam_graph.place_recognition import PlaceRecognition
from albot1.methods.baselines.gtsam_graph.registration import Registration


class GtsamGraphMapper:
    """Pose-graph SLAM with scan-matching edges, verified loop closures, ISAM2 and a final LM."""

    name: ClassVar[str] = "gtsam-graph"
    config_model: ClassVar[type[BaseModel]] = GtsamGraphConfig
    presets = TomlPresets()

    def __init__(self, config: GtsamGraphConfig, *, seed: int = 0) -> None:
        # Nothing here is random; the seed is kept for the protocol and the record.
        self.config = config
        self.seed = seed
        self.counters: dict[str, int] = {
            "views": 0,
            "nodes": 0,
            "sequential_matches": 0,
            "sequential_retries_recovered": 0,
            "scans_tracked": 0,
            "tracking_failures": 0,
            "tracking_velocity_guess": 0,
            "tracking_velocity_rejected": 0,
            "tracking_outliers_rejected": 0,
            "odometry_fallbacks": 0,
            "odometry_fused": 0,
            "loop_candidates": 0,
            "loop_coarse_searches": 0,
            "loop_closures_accepted": 0,
            "loop_closures_rejected": 0,
            "place_searches": 0,
            "place_closures_accepted": 0,
            "scans_refined": 0,
        }
        self.back = BackEnd(config, self.counters)
        self.front = FrontEnd(config, self.back, self.counters)
        self.loops = LoopCloser(config, self.back, self.counters)
        self.places = PlaceRecognition(config, self.back, self.loops, self.counters)

    def warm_up(self, announce: Callable[[str], None] | None = None) -> None:
        """Compile ICP's grid search and loop and place recognition's block sums (or load numba's cache) first.

        ``Mapper.warm_up``: the bench's forkserver and ``albot1 warm-up`` call it once.
        """
        nearest.warm_up(announce)
        icp_loop.warm_up(announce)
        block_sums.warm_up(announce)

    # ------------------------------------------------------------------ input
    def process(self, frame: Frame) -> None:
        """Add the frame's scan to its node, creating a node when the robot moved enough."""
        odometry = np.asarray(frame.odometry, dtype=float)
        if odometry.shape != (3,) or not np.isfinite(odometry).all():
            raise BaselineError(
                f"gtsam-graph: scan {frame.index}: expected a finite odometry pose (x, y, theta), "
                f"got {odometry.tolist()}"
            )
        points = preprocess(self.config, frame.scan, frame.index)
        self.counters["views"] += 1
        front = self.front
        try:
            if front.last_odometry is None:
                self.back.start(odometry, points, frame.index)
                front.new_node()
            else:
                pose, reg = front.step(odometry, points, frame.scan.timestamp)
                if front.moved_enough(pose):
                    self._add_node(odometry, pose, points, frame.index, reg)
                else:
                    front.track = pose
        except (
            GraphError,
            RegistrationError,
        ) as exc:  # re-raised as the method's error so the runner names the dataset
            raise BaselineError(f"gtsam-graph: scan {frame.index}: {exc}") from exc
        front.last_odometry = odometry
        front.last_stamp = frame.scan.timestamp
        self.back.add_scan(front.track, points)

    def _add_node(
        self, odometry: FloatArray, step: FloatArray, points: FloatArray, index: int, tracked: Registration | None
    ) -> None:
        """A new node at ``step`` from the newest; then loop closure and place recognition when they are due."""
        cfg = self.config
        odometry_step = se2.between(self.back.odometry[-1], odometry)
        relative, covariance = self.front.sequential_edge(step, points, index, tracked, odometry_step)
        spans = [*self.front.run_factors, *(self.front.span_edges(relative, points) if cfg.span_nodes else [])]
        key = self.back.add_node(
            odometry, step, relative, covariance, points, index, self.front.odometry_factors, spans
        )
        self.front.new_node()
        self.loops.travelled(math.hypot(relative[0], relative[1]))
        if key % cfg.loop_every_nodes == 0:
            self.loops.close_loops(key)
        if cfg.place_recognition and key % cfg.place_every_nodes == 0:
            self.places.recognise(key)

    # ------------------------------------------------------------------ output
    def finish(self) -> MapperOutput:
        """Final LM, per-scan poses (node pose composed with odometry since the node) and the map."""
        back = self.back
        if not back.scan_node:
            return MapperOutput(
                poses=np.empty((0, 3)),
                map=MapData(points=np.empty((0, 2))),
                counters={**self.counters, "updates": 0, "optimisations": 0, "map_points": 0},
            )
        self.loops.flush()
        nodes = back.optimise()
        poses = back.scan_poses(nodes)
        points = back.project_map(poses)
        n_nodes = len(back.odometry)
        counters: dict[str, int | float] = {
            **self.counters,
            "nodes": n_nodes,
            "updates": n_nodes,
            "optimisations": back.graph.optimisations,
            "map_points": int(len(points)),
        }
        extras = {
            "node_scans": [int(i) for i in back.frames],
            "loop_edges": [[int(a), int(b)] for a, b in back.loop_edges],
            "loop_rejections": dict(sorted(self.loops.rejections.items())),
        }
        return MapperOutput(poses=poses, map=MapData(points=points), counters=counters, extras=extras)
