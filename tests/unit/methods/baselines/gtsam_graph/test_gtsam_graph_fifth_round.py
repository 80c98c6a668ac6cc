"""Issue 24's fifth round: each cheaper path gives the bits of the numpy formulation it replaced.

Each test keeps the old formulation here, word for word, and compares bytes on inputs where a naive rewrite
would not give them: ties and signed zeros for the medians, NaN payloads for the copies, long rows for the
sums (a plain left-to-right sum differs from numpy's pairwise one), points on every side of a field and on
its cell edges for the correlative scores (a truncating cast without the range test reads cells that numpy's
floor leaves outside), a final gate that leaves one or no inliers for ICP.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph import icp_loop
from albot1.methods.baselines.gtsam_graph.backend import BackEnd, transform_batch
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.correlative import _pose_scores
from albot1.methods.baselines.gtsam_graph.loop_closure import LoopMatch
from albot1.methods.baselines.gtsam_graph.odometry_trust import column_medians
from albot1.methods.baselines.gtsam_graph.registration import (
    IcpParams,
    Registration,
    Target,
    line_normals,
    register,
    rotate,
    rotate_runs,
    side_by_side,
)
from albot1.methods.registry import resolve_config


def _same(a: object, b: object) -> bool:
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return x.shape == y.shape and x.tobytes() == y.tobytes()


def test_column_medians_are_np_median_s_bits_with_ties_signed_zeros_and_nans() -> None:
    rng = np.random.default_rng(4)
    for trial in range(3000):
        n = int(rng.integers(1, 70))
        h = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-6, 2)
        if trial % 4 == 1:
            h = np.round(h, 1)  # ties
        elif trial % 4 == 2:
            h[rng.random((n, 3)) < 0.4] = -0.0
            h[rng.random((n, 3)) < 0.4] = 0.0
        elif trial % 4 == 3:
            h[rng.integers(0, n), rng.integers(0, 3)] = np.nan
        assert _same(column_medians(h), np.median(h, axis=0)), trial
    # an even count: the mean of the two middle values, rounded as numpy's mean rounds it
    h = np.array([[1.0, 0.1, -0.0], [2.0 + 2.0**-51, 0.2, 0.0]])
    assert _same(column_medians(h), np.median(h, axis=0))
    with pytest.warns(RuntimeWarning):  # numpy's own: the mean of an empty slice (left to np.median)
        assert _same(column_medians(np.empty((0, 3))), np.median(np.empty((0, 3)), axis=0))


def test_side_by_side_is_hstack_s_bytes() -> None:
    rng = np.random.default_rng(5)
    for n in (0, 1, 2, 7, 1500):
        left, right = rng.normal(size=(n, 2)), rng.normal(size=(n, 2))
        if n > 2:
            left[0, 1], right[1, 0] = -0.0, np.frombuffer(np.uint64(0x7FF8_0000_0000_1234).tobytes(), dtype=float)[0]
        assert side_by_side(left, right).tobytes() == np.hstack([left, right]).tobytes()
    strided = rng.normal(size=(10, 4))[:, ::2]  # not C-ordered: copied first
    assert side_by_side(strided, strided).tobytes() == np.hstack([strided, strided]).tobytes()


def _config() -> GtsamGraphConfig:
    cfg = resolve_config("gtsam-graph", "default", {})
    assert isinstance(cfg, GtsamGraphConfig)
    return cfg


def _old_target(back: BackEnd, nodes: range, frame_node: int) -> Target:
    """:meth:`BackEnd.target` as it was: one ``transform_points`` and one ``rotate`` per node."""
    origin = back.estimates[frame_node]
    pts, nrm = [], []
    for n in nodes:
        rel = se2.between(origin, back.estimates[n])
        pts.append(se2.transform_points(rel, back.lines[n][0]))
        nrm.append(rotate(back.lines[n][1], rel[2]))
    return Target(np.concatenate(pts), np.concatenate(nrm))


def _back_end(seed: int) -> BackEnd:
    """A back end of 40 nodes with random scans (some without line-like points) and a few loop edges."""
    rng = np.random.default_rng(seed)
    back = BackEnd(_config(), {})
    for k in range(40):
        t = rng.uniform(0.0, 4.0, int(rng.integers(0, 3)) * 60)
        scan = np.column_stack([t, 0.01 * rng.normal(size=len(t))]) @ se2.rows_rotation(rng.uniform(0, 3))
        step = np.array([rng.normal() * 0.5, rng.normal() * 0.5, rng.normal() * 0.3]) if k else np.zeros(3)
        if k == 0:
            back.start(np.zeros(3), scan, k)
        else:
            back.add_node(np.zeros(3), step, step, np.diag([0.01, 0.01, 0.001]), scan, k)
    back.add_loops([LoopMatch(39, 3, np.array([0.1, 0.2, 0.3]), np.diag([0.01, 0.01, 0.001]), np.zeros(3))])
    back.add_loops([LoopMatch(25, 7, np.array([-0.1, 0.0, 0.1]), np.diag([0.01, 0.01, 0.001]), np.zeros(3))])
    return back


@pytest.mark.parametrize("seed", [0, 1])
def test_targets_are_moved_with_transform_points_bits(seed: int) -> None:
    back = _back_end(seed)
    assert any(len(back.lines[n][0]) == 0 for n in range(40)) and any(len(back.lines[n][0]) for n in range(40))
    for nodes, frame in ((range(30, 40), 39), (range(0, 40), 17), (range(5, 6), 5)):
        new, old = back.target(nodes, frame), _old_target(back, nodes, frame)
        assert new.points.tobytes() == old.points.tobytes() and new.lines.tobytes() == old.lines.tobytes()
    run = np.random.default_rng(seed).normal(size=(50, 2))
    pose = np.array([1.5, -2.0, 2.9])
    c, s = np.cos(pose[2]), np.sin(pose[2])
    assert _same(transform_batch(run, np.array([[pose[0], pose[1], c, s]]), [50]), se2.transform_points(pose, run))


def test_rotate_runs_are_numpy_s_products_for_runs_of_every_length() -> None:
    rng = np.random.default_rng(9)
    parts = [rng.normal(size=(n, 2)) * 10.0 ** rng.uniform(-3, 3) for n in (0, 1, 2, 5, 1, 300, 3, 0, 64)]
    angles = [float(a) for a in rng.uniform(-4.0, 4.0, len(parts))]
    want = np.concatenate([rotate(v, a) for v, a in zip(parts, angles, strict=True)])
    assert rotate_runs(parts, angles).tobytes() == want.tobytes()
    real = icp_loop.available
    try:
        icp_loop.available = lambda: False  # type: ignore[assignment]
        assert rotate_runs(parts, angles).tobytes() == want.tobytes()
    finally:
        icp_loop.available = real  # type: ignore[assignment]


def _old_graph_distances(back: BackEnd, key: int) -> np.ndarray:
    """:meth:`BackEnd.graph_distances` as it was: lists of Python numbers."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    n = key + 1
    steps = np.asarray(back.steps[1:n], dtype=float).reshape(-1, 3)
    rows = [*range(n - 1), *(a for a, _ in back.loop_edges)]
    cols = [*range(1, n), *(b for _, b in back.loop_edges)]
    lengths = [
        *np.hypot(steps[:, 0], steps[:, 1]),
        *(math.hypot(*(back.estimates[a, :2] - back.estimates[b, :2])) for a, b in back.loop_edges),
    ]
    graph = coo_matrix((np.maximum(lengths, 1e-6), (rows, cols)), shape=(n, n)).tocsr()
    return np.asarray(dijkstra(graph, directed=False, indices=key), dtype=np.float64)


def test_graph_distances_are_the_list_built_graph_s_bits() -> None:
    back = _back_end(2)
    assert back.loop_edges
    assert _same(back.graph_distances(39), _old_graph_distances(back, 39))


def _old_pose_scores(field, lo, src, guess, grid, thetas, cell_m, floor=np.floor):  # type: ignore[no-untyped-def]
    """``correlative._pose_scores`` as numpy computed it before the fifth round (``floor``: to try another)."""
    n0, n1 = field.shape
    flat = np.append(field.ravel(), 0.0)
    scores = np.empty((len(thetas), len(grid)))
    for r, theta in enumerate(thetas):
        c, s = math.cos(theta), math.sin(theta)
        moved = src @ np.array([[c, s], [-s, c]]) + guess[:2]
        with np.errstate(invalid="ignore"):
            i = floor((moved[None, :, 0] + grid[:, None, 0] - lo[0]) / cell_m).astype(np.int64)
            j = floor((moved[None, :, 1] + grid[:, None, 1] - lo[1]) / cell_m).astype(np.int64)
        inside = i.view(np.uint64) < n0
        inside &= j.view(np.uint64) < n1
        i *= n1
        i += j
        scores[r] = flat.take(np.where(inside, i, n0 * n1)).sum(axis=1)
    return scores


def test_correlative_scores_are_the_numpy_lookups_bits_on_edges_and_outside() -> None:
    rng = np.random.default_rng(6)
    field = rng.uniform(0.0, 1.0, size=(12, 9))
    lo = np.array([0.0, 0.0])
    # exact cell edges at 0.5 m cells, seen unturned (theta 0: the rotation leaves them exact)
    edges = np.array([
        [-0.0, 1.0], [-0.25, 1.0], [-0.5, 1.0], [0.0, -0.0], [1.0, -0.25], [5.999999, 1.0], [6.0, 1.0],
        [1.0, 4.5], [1.0, 4.4999999], [1e300, 1.0], [-1e300, 1.0], [np.inf, 1.0], [np.nan, 1.0], [2.0, -np.inf],
    ])  # fmt: skip
    long_row = rng.uniform(-1.0, 7.0, size=(300, 2))  # longer than numpy's 128-value blocks
    src = np.concatenate([edges, long_row])
    grid = np.array([[0.0, 0.0], [0.5, -0.5], [-3.0, 2.0], [40.0, 0.0]])
    for thetas in (np.array([0.0]), np.array([0.0, 0.3, -2.0])):
        with np.errstate(invalid="ignore"):
            new = _pose_scores(field, lo, src, np.zeros(3), grid, thetas, 0.5)
            old = _old_pose_scores(field, lo, src, np.zeros(3), grid, thetas, 0.5)
            # a truncation in place of the floor reads cell 0 for -1 < v < 0 (the floor, -1, is outside)
            truncated = _old_pose_scores(field, lo, src, np.zeros(3), grid, thetas, 0.5, floor=np.trunc)
        assert new.tobytes() == old.tobytes()
        assert truncated.tobytes() != old.tobytes()
    # and a plain left-to-right row sum is not numpy's pairwise one on these rows
    vals = field[np.clip((long_row[:, 0] / 0.5).astype(int), 0, 11), np.clip((long_row[:, 1] / 0.5).astype(int), 0, 8)]
    plain = 0.0
    for v in vals.tolist():
        plain += v
    assert plain != float(vals.sum())


@pytest.mark.skipif(not icp_loop.available(), reason="numpy's BLAS is not scipy-openblas64 here")
@pytest.mark.parametrize("min_gate", [1e-4, 0.02, 0.2])
def test_register_s_final_terms_are_numpy_s_with_none_one_or_many_inliers(min_gate: float) -> None:
    """The final terms (now in the compiled call) against numpy's loop and ``_linearise``, ``wj.T @ jac``, ``mean``."""
    rng = np.random.default_rng(7)
    t = rng.uniform(0.0, 8.0, 600)
    walls = np.concatenate([
        np.column_stack([t[:300], 0.01 * rng.normal(size=300)]),
        np.column_stack([0.01 * rng.normal(size=300), t[300:]]),
    ])  # fmt: skip
    target = Target.from_points(walls)
    scan = walls[rng.choice(len(walls), 250, replace=False)] + rng.normal(size=(250, 2)) * 0.01
    guess = np.array([0.05, -0.03, 0.01])
    params = IcpParams(min_correspondence_m=min_gate, max_correspondence_m=max(min_gate, 0.5), min_points=2)
    fast = register(target, scan, guess, params)
    real = icp_loop.available
    try:
        icp_loop.available = lambda: False  # type: ignore[assignment]
        slow: Registration = register(Target(target.points, target.normals), scan, guess, params)
    finally:
        icp_loop.available = real  # type: ignore[assignment]
    assert _same(fast.pose, slow.pose) and _same(fast.information, slow.information)
    assert (fast.inliers, fast.iterations, fast.converged) == (slow.inliers, slow.iterations, slow.converged)
    assert _same([fast.rmse_m, fast.fitness], [slow.rmse_m, slow.fitness])
    if min_gate == 0.2:
        assert fast.inliers > 128  # numpy's pairwise sum splits the row: the recursion is exercised


def _old_line_normals(pts: np.ndarray, neighbours: int, radius_m: float = 0.5, max_planarity: float = 0.2):  # type: ignore[no-untyped-def]
    """``line_normals`` as numpy computed it before the fifth round (points already checked, three or more)."""
    from scipy.spatial import cKDTree

    k = min(neighbours, len(pts))
    dist, idx = cKDTree(pts).query(pts, k=k, distance_upper_bound=radius_m)
    ok = np.isfinite(dist)
    counts = ok.sum(axis=1)
    idx = np.where(ok, idx, np.arange(len(pts))[:, None])
    w = ok[..., None].astype(float)
    nb = pts[idx]
    mean = (nb * w).sum(axis=1) / np.maximum(counts, 1)[:, None]
    d = (nb - mean[:, None, :]) * w
    cxx = (d[..., 0] ** 2).sum(axis=1)
    cyy = (d[..., 1] ** 2).sum(axis=1)
    cxy = (d[..., 0] * d[..., 1]).sum(axis=1)
    root = np.sqrt((0.5 * (cxx - cyy)) ** 2 + cxy**2)
    lam_max = 0.5 * (cxx + cyy) + root
    lam_min = 0.5 * (cxx + cyy) - root
    axis = 0.5 * np.arctan2(2.0 * cxy, cxx - cyy)
    keep = (counts >= 3) & (lam_max > 1e-12) & (lam_min <= max_planarity * np.maximum(lam_max, 1e-12))
    return pts[keep], np.column_stack([-np.sin(axis[keep]), np.cos(axis[keep])])


def test_line_normals_are_the_numpy_moments_bits_on_lattices_signed_zeros_and_sparse_points() -> None:
    rng = np.random.default_rng(8)
    plain_differs = 0
    for trial in range(600):
        n = int(rng.integers(3, 300))
        if trial % 3 == 0:
            pts = rng.normal(size=(n, 2)) * rng.uniform(0.1, 5.0)  # sparse: many points with fewer neighbours
        elif trial % 3 == 1:
            pts = rng.integers(-5, 5, size=(n, 2)) * 0.1  # a lattice: equidistant neighbours, exact zeros
            pts[rng.random((n, 2)) < 0.3] *= -1.0
        else:
            th, r = rng.uniform(0.0, 6.3, n), rng.uniform(0.5, 8.0, n)
            pts = np.column_stack([r * np.cos(th), r * np.sin(th)])
            pts[: n // 3, 1] = -0.0
        for neighbours in (3, 6, 7, 9):  # 9: past the kernel's in-order sums, numpy's own path
            new, old = line_normals(pts, neighbours), _old_line_normals(pts, neighbours)
            assert new[0].tobytes() == old[0].tobytes() and new[1].tobytes() == old[1].tobytes(), (trial, neighbours)
        # the mean's sum in another order (last neighbour first) is not always numpy's
        from scipy.spatial import cKDTree

        dist, idx = cKDTree(pts).query(pts, k=6, distance_upper_bound=0.5)
        vals = np.where(np.isfinite(dist), pts[np.minimum(idx, n - 1), 0], 0.0)
        plain_differs += not np.array_equal(vals.sum(axis=1), vals[:, ::-1].sum(axis=1))
    assert plain_differs > 50


def test_the_warm_up_compiles_the_new_kernels_with_a_run_s_types() -> None:
    """A run after the warm-ups adds no signature to the three kernels of this round (no compile in a timed scan)."""
    from albot1.data import open_sequence
    from albot1.methods.baselines.gtsam_graph import block_sums, nearest
    from albot1.runs.execute import run_method

    for module in (nearest, icp_loop, block_sums):
        module.warm_up()
    kernels = [block_sums.line_moments, block_sums.pose_sums]
    if icp_loop.available():
        kernels.append(icp_loop.rotate_runs)
    before = [len(k.signatures) for k in kernels]
    run_method("gtsam-graph", open_sequence("synthetic-office-loop[:200]"))
    rng = np.random.default_rng(10)
    field, src = rng.uniform(size=(20, 30)), rng.normal(size=(40, 2))
    _pose_scores(field, np.zeros(2), src, np.zeros(3), np.zeros((3, 2)), np.array([0.0, 0.1]), 0.1)
    assert [len(k.signatures) for k in kernels] == before
