"""The back end of :class:`~albot1.methods.baselines.gtsam_graph.mapper.GtsamGraphMapper`: graph, nodes and map.

It owns everything the other parts read about the map so far: the GTSAM
pose graph (ISAM2 after every node, :mod:`.graph`), the current node
estimates, what each node keeps of its scan (points and line normals, in the
node's frame), the loop edges added, and per scan the node it belongs to and
its offset from that node. The front end (:mod:`.frontend`), the loop closer
(:mod:`.loop_closer`) and place recognition (:mod:`.place_recognition`) build
their ICP targets from it (:meth:`BackEnd.target`) and hand it edges.

At the end it runs the final batch Levenberg-Marquardt, gives every scan a
pose (node scans take their node's; the others are seeded from the tracked
offsets and refined, :mod:`.refine`) and projects the map.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np

from albot1.geometry import se2
from albot1.geometry.grid import first_per_cell
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.errors import GraphError
from albot1.methods.baselines.gtsam_graph.graph import PoseGraph
from albot1.methods.baselines.gtsam_graph.loop_closure import LoopMatch
from albot1.methods.baselines.gtsam_graph.odometry_trust import OdometryFactor
from albot1.methods.baselines.gtsam_graph.refine import RefineTests, accept, seed_poses
from albot1.methods.baselines.gtsam_graph.registration import Target, line_normals, rotate_runs, try_register
from albot1.methods.baselines.gtsam_graph.span_edges import SpanEdge


def transform_batch(points: FloatArray, moves: FloatArray, counts: Sequence[int]) -> FloatArray:
    """Consecutive runs of ``points`` (``counts`` rows each) moved by one pose each: ``se2.transform_points``'s bits.

    ``moves`` holds per run the pose's ``x``, ``y`` and the ``np.cos`` and
    ``np.sin`` of its heading, each computed as :func:`.se2.transform_points`
    computes them for one pose (the same ufunc on one value); the
    per-point arithmetic ``x + c * px - s * py`` and ``y + s * px + c * py``
    is then one elementwise pass over every run at once, the same IEEE
    operations in the same order. One call instead of one per node: a local
    map's ten nodes cost ten times numpy's per-call overhead before
    (docs/baselines.md, "Cost (issue 24), fifth round").
    """
    per_point = np.repeat(moves, counts, axis=0)
    x, y, c, s = per_point[:, 0], per_point[:, 1], per_point[:, 2], per_point[:, 3]
    out = np.empty_like(points)
    out[:, 0] = x + c * points[:, 0] - s * points[:, 1]
    out[:, 1] = y + s * points[:, 0] + c * points[:, 1]
    return out


class BackEnd:
    """Pose graph, node estimates and scans, and the final optimisation and map projection."""

    def __init__(self, config: GtsamGraphConfig, counters: dict[str, int]) -> None:
        self.config = config
        self.counters = counters  # shared with the mapper's other parts: one set of counters per run
        self.graph = PoseGraph(config.isam_relinearize_threshold)
        self.estimates: FloatArray = np.empty((0, 3))
        # Per node.
        self.odometry: list[FloatArray] = []
        self.steps: list[FloatArray] = []  # measured pose of node k in node k-1's frame (node 0: zeros)
        self._step_rows: FloatArray = np.empty((0, 3))  # the steps as rows (the first len(steps)): graph_distances
        self.scans: list[FloatArray] = []
        self.lines: list[tuple[FloatArray, FloatArray]] = []  # line-like points and normals, node frame
        self.frames: list[int] = []  # the frame index of each node's scan
        self.loop_edges: list[tuple[int, int]] = []
        # Per scan.
        self.scan_node: list[int] = []
        self.scan_offset: list[FloatArray] = []
        self.scan_points: list[FloatArray] = []
        self._local: Target | None = None
        self._refine_icp = config.refine_icp()
        self._refine_tests = RefineTests(
            min_fitness=config.refine_min_fitness,
            max_rmse_m=config.refine_max_rmse_m,
            max_correction_m=config.refine_max_correction_m,
            max_correction_rad=math.radians(config.refine_max_correction_deg),
        )

    @property
    def newest(self) -> int:
        """The key of the newest node (-1 before the first)."""
        return len(self.odometry) - 1

    # ------------------------------------------------------------------ nodes and edges
    def start(self, odometry: FloatArray, points: FloatArray, index: int) -> None:
        """The first node, at the origin."""
        self.graph.add_node(np.zeros(3))
        self.graph.update()
        self._remember_node(odometry, np.zeros(3), points, index)
        self.estimates = np.zeros((1, 3))

    def add_node(
        self,
        odometry: FloatArray,
        step: FloatArray,
        relative: FloatArray,
        covariance: FloatArray,
        points: FloatArray,
        index: int,
        odometry_factors: Sequence[OdometryFactor] = (),
        spans: Sequence[SpanEdge] = (),
    ) -> int:
        """A node at ``step`` from the newest, joined to it by the sequential edge ``relative``; its key.

        ``odometry_factors`` (each from node ``key - 1`` to ``key``, this new
        node's included) and the edges ``spans`` spanning runs of steps to it (:mod:`.span_edges`) go into the
        same update. ISAM2 updates the graph,
        and the estimates of the nodes a local map can reach are refreshed
        from it; all of them when an odometry factor reached further back.
        """
        prev = self.newest
        key = self.graph.add_node(se2.compose(self.estimates[prev], step))
        self.graph.add_edge(prev, key, relative, covariance)
        for factor in odometry_factors:
            self.graph.add_edge(factor.key - 1, factor.key, factor.step, factor.covariance)
        for span in spans:
            self.graph.add_edge(span.first, span.key, span.relative, span.covariance, kernel=span.kernel)
        self.graph.update()
        self._remember_node(odometry, relative, points, index)
        self.estimates = np.vstack([self.estimates, se2.compose(self.estimates[prev], relative)])
        first = max(0, key - self.config.local_map_nodes)
        if any(factor.key - 1 < first for factor in odometry_factors) or any(span.first < first for span in spans):
            self.estimates = self.graph.estimates()
        else:
            self.estimates[first : key + 1] = self.graph.estimate_rows(range(first, key + 1))
        return key

    def _remember_node(self, odometry: FloatArray, step: FloatArray, points: FloatArray, index: int) -> None:
        """Keep what later scan matching needs of a new node: its odometry, measured step, scan, lines, frame."""
        self.odometry.append(odometry)
        self.steps.append(np.asarray(step, dtype=float))
        if len(self.steps) > len(self._step_rows):  # the same rows as the list, kept as one array (doubling)
            grown = np.empty((max(16, 2 * len(self._step_rows)), 3))
            grown[: len(self.steps) - 1] = self._step_rows[: len(self.steps) - 1]
            self._step_rows = grown
        self._step_rows[len(self.steps) - 1] = self.steps[-1]
        self._local = None
        self.scans.append(points)
        self.lines.append(
            line_normals(points, self.config.normal_neighbours, self.config.normal_radius_m, self.config.max_planarity)
        )
        self.frames.append(index)

    def add_loops(self, accepted: list[LoopMatch]) -> None:
        """Add confirmed loop matches as robust edges and bring the estimates up to date."""
        cfg = self.config
        for match in accepted:
            self.graph.add_edge(
                match.candidate,
                match.current,
                match.relative,
                match.covariance,
                kernel=cfg.loop_kernel,
                kernel_scale=cfg.loop_kernel_scale,
            )
            self.loop_edges.append((match.candidate, match.current))
        self.graph.update(cfg.isam_extra_updates_on_loop)
        self.estimates = self.graph.estimates()
        self._local = None

    def add_scan(self, offset: FloatArray, points: FloatArray) -> None:
        """A scan of the newest node, at ``offset`` in that node's frame."""
        self.scan_node.append(self.newest)
        self.scan_offset.append(offset.copy())
        self.scan_points.append(points)

    # ------------------------------------------------------------------ what the other parts match against
    def target(self, nodes: Iterable[int], frame_node: int, poses: FloatArray | None = None) -> Target:
        """The line-like points of ``nodes``' scans, expressed in ``frame_node``'s frame.

        Nodes are placed with ``poses`` (default: the current estimates).
        """
        at = self.estimates if poses is None else poses
        origin = at[frame_node]
        parts, nrm, moves, counts, turns = [], [], [], [], []
        for n in nodes:
            rel = se2.between(origin, at[n])
            points, normals = self.lines[n]
            parts.append(points)
            nrm.append(normals)
            turns.append(rel[2])
            moves.append((rel[0], rel[1], np.cos(rel[2]), np.sin(rel[2])))
            counts.append(len(points))
        return Target(transform_batch(np.concatenate(parts), np.array(moves), counts), rotate_runs(nrm, turns))

    def local_map(self) -> Target:
        """The last ``local_map_nodes`` node scans in the newest node's frame (built once per node and estimate)."""
        if self._local is None:
            last = self.newest
            self._local = self.target(range(max(0, last - self.config.local_map_nodes + 1), last + 1), last)
        return self._local

    def graph_distances(self, key: int) -> FloatArray:
        """Shortest path length (m) from node ``key`` to every node ``0..key`` along sequential and loop edges."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import dijkstra

        n = key + 1
        # The same values as lists of Python numbers gave (sequential edges, then loop edges in their order), built
        # as arrays: the rows kept by _remember_node, the loop edges' differences elementwise, math.hypot of each.
        steps = self._step_rows[1:n]
        ends = np.array(self.loop_edges, dtype=np.int64).reshape(-1, 2)
        gaps = (self.estimates[ends[:, 0], :2] - self.estimates[ends[:, 1], :2]).tolist()
        rows = np.concatenate([np.arange(n - 1), ends[:, 0]])
        cols = np.concatenate([np.arange(1, n), ends[:, 1]])
        lengths = np.concatenate([np.hypot(steps[:, 0], steps[:, 1]), [math.hypot(dx, dy) for dx, dy in gaps]])
        # csgraph treats a zero weight as a missing edge; a node step can be a pure rotation.
        graph = coo_matrix((np.maximum(lengths, 1e-6), (rows, cols)), shape=(n, n)).tocsr()
        return np.asarray(dijkstra(graph, directed=False, indices=key), dtype=np.float64)

    # ------------------------------------------------------------------ output
    def optimise(self) -> FloatArray:
        """The node poses after the final batch LM (or the ISAM2 estimates when ``final_lm`` is off)."""
        try:
            nodes = (
                self.graph.optimise(self.config.lm_max_iterations) if self.config.final_lm else self.graph.estimates()
            )
        except GraphError as exc:
            raise BaselineError(f"gtsam-graph: final optimisation: {exc}") from exc
        if not np.isfinite(nodes).all():
            raise BaselineError(
                f"gtsam-graph: the optimised graph of {len(nodes)} nodes has non-finite poses (diverged)"
            )
        return nodes

    def scan_poses(self, nodes: FloatArray) -> FloatArray:
        """Every scan's pose: node scans take their node's, the others are seeded and refined (:mod:`.refine`)."""
        scan_node = np.asarray(self.scan_node, dtype=np.int64)
        offsets = np.asarray(self.scan_offset, dtype=float)
        poses = seed_poses(nodes, np.asarray(self.steps), scan_node, offsets)
        is_node = np.zeros(len(scan_node), dtype=bool)
        is_node[np.asarray(self.frames, dtype=np.int64)] = True
        poses[is_node] = nodes[scan_node[is_node]]
        if not self.config.refine_scans:
            return poses
        width = self.config.refine_nodes_either_side
        target: Target | None = None
        target_node = -1
        for i in np.flatnonzero(~is_node):
            k = int(scan_node[i])
            if k != target_node:
                around = range(max(0, k - width), min(len(nodes), k + width + 2))
                target, target_node = self.target(around, k, nodes), k
            assert target is not None
            seed = se2.between(nodes[k], poses[i])
            reg = try_register(target, self.scan_points[i], seed, self._refine_icp)
            if reg is not None and accept(self._refine_tests, seed, reg.pose, reg.converged, reg.fitness, reg.rmse_m):
                poses[i] = se2.compose(nodes[k], reg.pose)
                self.counters["scans_refined"] += 1
        return poses

    def project_map(self, poses: FloatArray) -> FloatArray:
        """Every ``map_every``-th scan projected with its pose; the first point in each grid cell wins."""
        every = self.config.map_every
        parts = [
            se2.transform_points(poses[i], pts) for i, pts in enumerate(self.scan_points) if i % every == 0 and len(pts)
        ]
        if not parts:
            return np.empty((0, 2))
        return first_per_cell(np.concatenate(parts), self.config.map_voxel_m)
