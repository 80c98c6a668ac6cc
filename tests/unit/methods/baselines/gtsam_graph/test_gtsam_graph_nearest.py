"""ICP's compiled grid search gives the k-d tree's answers, bit for bit: ties, the gate, far away, compiled or not."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from pydantic import ValidationError
from scipy.spatial import cKDTree

from albot1.data import open_sequence
from albot1.methods.albot1.compiled import as_written
from albot1.methods.baselines.gtsam_graph import nearest
from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.errors import RegistrationError
from albot1.methods.baselines.gtsam_graph.nearest import Grid, Matches, build_grid, linearise_terms, terms
from albot1.methods.baselines.gtsam_graph.registration import rotate
from albot1.methods.registry import resolve_config
from albot1.runs.execute import run_method


class CountingTree:
    """A target's ``cKDTree`` that counts the query points it was asked about."""

    def __init__(self, points: np.ndarray) -> None:
        self.tree = cKDTree(points)
        self.asked = 0

    def query(self, x: np.ndarray, **kwargs: Any) -> tuple[np.ndarray, np.ndarray]:
        self.asked += len(x)
        dist, idx = self.tree.query(x, **kwargs)
        return np.asarray(dist), np.asarray(idx)


def expected_terms(
    points: np.ndarray,
    normals: np.ndarray,
    rot: np.ndarray,
    pose: np.ndarray,
    gate: float,
    cauchy: float,
    inv_var: float,
) -> tuple[np.ndarray, ...]:
    """The numpy formulation every recorded gtsam-graph result was computed with."""
    dist, idx = cKDTree(points).query(rot + pose[:2], k=1, distance_upper_bound=gate)
    ok = dist < gate
    rot, idx = rot[ok], idx[ok]
    n = normals[idx]
    diff = rot + pose[:2] - points[idx]
    res = n[:, 0] * diff[:, 0] + n[:, 1] * diff[:, 1]
    jac = np.empty((len(res), 3))
    jac[:, :2] = n
    jac[:, 2] = n[:, 1] * rot[:, 0] - n[:, 0] * rot[:, 1]
    w = 1.0 / (1.0 + (res / cauchy) ** 2)
    return jac, res, w, jac * (w * inv_var)[:, None]


def found(
    points: np.ndarray, normals: np.ndarray, rot: np.ndarray, pose: np.ndarray, gate: float
) -> tuple[tuple[np.ndarray, ...], CountingTree]:
    tree = CountingTree(points)
    lines = np.hstack([points, normals])
    out = Matches(len(rot)).find(Grid(points), lambda: tree, lines, rot, pose, gate, 0.1, 400.0)
    return out, tree


def unit_normals(rng: np.random.Generator, n: int) -> np.ndarray:
    angle = rng.uniform(-np.pi, np.pi, n)
    return np.column_stack([np.cos(angle), np.sin(angle)])


def assert_same_bits(got: tuple[np.ndarray, ...], want: tuple[np.ndarray, ...]) -> None:
    for a, b in zip(got, want, strict=True):
        assert a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("gate", [0.2, 0.5, 1.5])
def test_on_a_lattice_full_of_exact_ties_the_answers_are_the_k_d_tree_s(seed: int, gate: float) -> None:
    """Integer and half-integer coordinates (0.1 m lattice): many queries are equidistant from two or four points."""
    rng = np.random.default_rng(seed)
    points = rng.integers(0, 60, size=(400, 2)) * 0.1
    points = np.vstack([points, points[:20]])  # exact duplicates with other normals
    normals = unit_normals(rng, len(points))
    rot = rng.integers(-10, 130, size=(300, 2)) * 0.05
    pose = np.array([0.0, 0.0, 0.0])
    got, tree = found(points, normals, rot, pose, gate)
    assert_same_bits(got, expected_terms(points, normals, rot, pose, gate, 0.1, 400.0))
    assert tree.asked > 0  # the ties went to the k-d tree


@pytest.mark.parametrize("seed", range(6))
def test_on_generic_points_no_query_needs_the_k_d_tree(seed: int) -> None:
    """Random walls and a moved, rotated scan: the grid answers every query itself, with the same bits."""
    rng = np.random.default_rng(100 + seed)
    t = rng.uniform(0, 1, 600)
    starts, ends = rng.uniform(-8, 8, (600, 2)), rng.uniform(-8, 8, (600, 2))
    points = starts + (ends - starts) * t[:, None] * 0.1
    normals = unit_normals(rng, len(points))
    src = rng.uniform(-9, 9, (250, 2))
    pose = np.array([rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-np.pi, np.pi)])
    rot = rotate(src, pose[2])
    for gate in (0.2, 0.7, 1.0):
        got, tree = found(points, normals, rot, pose, gate)
        assert_same_bits(got, expected_terms(points, normals, rot, pose, gate, 0.1, 400.0))
        assert tree.asked == 0


def test_a_query_exactly_at_the_gate_and_far_outside_the_grid() -> None:
    """Distance == gate is outside (the k-d tree's strict bound); a query 1 km away finds nothing and costs nothing."""
    points = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0], [3.0, 3.0]])
    normals = np.tile([0.0, 1.0], (4, 1))
    rot = np.array([[0.25, 0.0], [0.0, 0.2499], [1000.0, -1000.0], [-1e9, 5.0], [3.0, 2.75]])
    got, _ = found(points, normals, rot, np.zeros(3), 0.25)
    assert_same_bits(got, expected_terms(points, normals, rot, np.zeros(3), 0.25, 0.1, 400.0))
    assert len(got[1]) == 1  # only (0, 0.2499) is within the gate


@pytest.mark.parametrize("offset", [5e5, 4e6])
def test_far_from_the_origin_the_ties_still_reach_the_k_d_tree(offset: float) -> None:
    """UTM-sized coordinates: the k-d tree's rounding grows with them, and so does the tolerance."""
    rng = np.random.default_rng(3)
    points = rng.integers(0, 60, size=(400, 2)) * 0.1 + offset
    normals = unit_normals(rng, len(points))
    rot = rng.integers(-10, 130, size=(300, 2)) * 0.05
    pose = np.array([offset, offset, 0.0])
    got, tree = found(points, normals, rot, pose, 0.5)
    assert_same_bits(got, expected_terms(points, normals, rot, pose, 0.5, 0.1, 400.0))
    assert tree.asked > 0


def test_a_query_that_is_not_finite_is_refused_by_the_k_d_tree_as_before() -> None:
    """The grid leaves it to the tree (no endless ring search), which raises as the numpy formulation did."""
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    normals = np.tile([0.0, 1.0], (3, 1))
    for bad in (np.nan, np.inf):
        rot = np.array([[bad, 0.0], [0.05, 0.0]])
        with pytest.raises(ValueError) as want:
            expected_terms(points, normals, rot, np.zeros(3), 0.5, 0.1, 400.0)
        with pytest.raises(ValueError) as got:
            found(points, normals, rot, np.zeros(3), 0.5)
        assert str(got.value) == str(want.value)


def test_an_infinite_gate_or_an_empty_target_is_refused_in_one_line() -> None:
    points = np.array([[0.0, 0.0], [1.0, 0.0]])
    lines = np.hstack([points, np.tile([0.0, 1.0], (2, 1))])
    with pytest.raises(RegistrationError, match="finite positive correspondence gate, got inf"):
        Matches(1).find(Grid(points), lambda: cKDTree(points), lines, np.zeros((1, 2)), np.zeros(3), np.inf, 0.1, 1.0)
    with pytest.raises(RegistrationError, match=r"non-empty \(n, 2\) array of finite points"):
        Grid(np.empty((0, 2)))
    with pytest.raises(ValidationError, match="finite number"):
        cfg = resolve_config("gtsam-graph", "default", {})
        GtsamGraphConfig.model_validate({**cfg.model_dump(), "icp_max_correspondence_m": np.inf})


def test_a_wide_sparse_target_gets_coarser_cells_and_every_point_is_in_its_own_cell() -> None:
    points = np.array([[0.0, 0.0], [500.0, 300.0], [0.1, 0.05], [250.0, 0.3]])
    origin, dims, cell, starts, order = build_grid(points, 0.2, 4)
    nx, ny = int(dims[0]), int(dims[1])
    assert nx * ny <= 4 * len(points) + 64 and cell > 0.2
    assert sorted(order.tolist()) == [0, 1, 2, 3] and starts[-1] == 4
    for c in range(nx * ny):
        for k in order[starts[c] : starts[c + 1]]:
            cx, cy = divmod(c, ny)
            assert min(int((points[k, 0] - origin[0]) / cell), nx - 1) == cx
            assert min(int((points[k, 1] - origin[1]) / cell), ny - 1) == cy


def test_compiled_and_as_written_kernels_give_the_same_bits() -> None:
    rng = np.random.default_rng(7)
    points = rng.integers(0, 30, size=(120, 2)) * 0.1
    lines = np.hstack([points, unit_normals(rng, len(points))])
    rot = rng.integers(0, 60, size=(40, 2)) * 0.05
    grid = Grid(points)
    outs = []
    for fn, fill in ((linearise_terms, terms), (as_written(linearise_terms), as_written(terms))):
        idx, jac, res, w, wj = (
            np.zeros(40, dtype=np.int64),
            np.zeros((40, 3)),
            np.zeros(40),
            np.zeros(40),
            np.zeros((40, 3)),
        )
        args = (grid.origin, grid.dims, grid.cell, grid.starts, grid.xy, grid.order, lines, rot, 0.01, -0.02, 0.3, 0.1)
        m = fn(*args, 400.0, idx, jac, res, w, wj)
        assert m == -1  # the lattice has ties: the ambiguous ones are marked, no terms yet
        idx[idx == nearest.AMBIGUOUS] = nearest.NONE
        m = fill(lines, rot, 0.01, -0.02, 0.1, 400.0, idx, jac, res, w, wj)
        outs.append((idx.copy(), jac[:m].copy(), res[:m].copy(), w[:m].copy(), wj[:m].copy()))
    assert_same_bits(outs[0], outs[1])


def test_after_the_warm_up_a_run_compiles_nothing_and_a_cached_warm_up_says_nothing() -> None:
    said: list[str] = []
    nearest.warm_up()
    nearest.warm_up(said.append)
    assert said == []  # compiled (or loaded) by the first call: nothing to announce
    kernels = (build_grid, linearise_terms, terms)
    before = [len(k.signatures) for k in kernels]  # type: ignore[attr-defined]
    run_method("gtsam-graph", open_sequence("synthetic-office-loop[:200]"))
    assert [len(k.signatures) for k in kernels] == before  # type: ignore[attr-defined]
