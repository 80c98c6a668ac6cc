"""Where gtsam-graph's error with perfect odometry comes from (a script, not a test: issue 21, analysis only).

Usage (from the checkout, with the dataset copies)::

    ALBOT1_DATA_DIR=/path/to/datasets .venv/bin/python benchmarks/gtsam_graph_diagnose.py \\
        [--set KEY=VALUE ...] [--parts 8] [--worst 10] CELL [CELL ...]

Runs gtsam-graph on each cell (a log with reference poses), records every factor the graph received (sequential
edge, odometry-fallback edge, odometry factor, loop closure, place-recognition closure) and, after the run, compares
them with the reference. The reference is read only here, after the run. Prints one JSON object per cell with:

* ``route``: per part of the route (``--parts`` equal runs of nodes) the final node error after the ATE alignment
  (RMS, m), its mean heading error less the run's median (deg), and the *online* error of each node when it was
  created (its ISAM2 estimate then, against the reference relative to node 0: the drift the front end made before
  any later closure could correct it);
* ``kinds``: per factor kind, how many, the RMS of their measurement error at the reference (m, deg), the sum of
  their squared whitened error at the reference (``chi2_at_truth``: how much the measurements disagree with the
  truth, in their own stated units), and **the share of the final node error they cause** (``ate_m``: ATE of the
  reference displaced by that kind's contribution alone). The contribution is linear: at the optimum ``x*`` the
  gradient vanishes, so ``x* - x_true ~= H^-1 sum_i J_i' r_i`` with ``J, H`` at ``x*`` (robust weights included)
  and ``r_i`` factor ``i``'s whitened error at the truth; the kinds' contributions add up to the total;
* ``worst_factors``: the factors whose contribution alone gives the largest ATE, with kind, nodes, error, stated
  sigma;
* ``closures``: every accepted closure with its error against the reference and its stated sigma;
* ``offline``: the node ATE when the recorded graph is re-solved (batch LM) as is, with every loop/place closure
  removed, with the closures off the reference by more than 0.2 m or 1 deg removed, and with the sequential edges'
  headings replaced by the reference's (what a perfect match heading would give with everything else kept).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any
from unittest.mock import patch

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from albot1.data.open import open_sequence
from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph import backend, graph, place_recognition
from albot1.metrics.ate import ate
from albot1.runs.execute import run_method

# the held-out script's `--set` reading and its fallback threshold: one definition of each (run from benchmarks/)
sys.path.insert(0, str(Path(__file__).resolve().parent))
from gtsam_graph_held_out import FALLBACK_SIGMA_DEG, _value, parse_cell  # noqa: E402

#: A closure this far off the reference (m, deg) counts as wrong in the ``offline`` re-solve.
WRONG_M, WRONG_DEG = 0.2, 1.0


@contextmanager
def recorded_factors() -> Iterator[dict[str, Any]]:
    """Every between factor the pose graph receives, with its kind, and each node's estimate when it was created."""
    seen: dict[str, Any] = {"factors": [], "online": []}
    kinds: list[str] = []
    place = [False]
    add_edge, add_node, add_loops = graph.PoseGraph.add_edge, backend.BackEnd.add_node, backend.BackEnd.add_loops
    recognise = place_recognition.PlaceRecognition.recognise

    def edge(self: Any, i: int, j: int, relative: Any, covariance: Any, *rest: Any, **named: Any) -> None:
        kind = kinds.pop(0) if kinds else "other"
        if kind == "sequential" and math.degrees(math.sqrt(covariance[2][2])) >= FALLBACK_SIGMA_DEG:
            kind = "fallback"
        seen["factors"].append((kind, int(i), int(j), np.array(relative, float), np.array(covariance, float)))
        add_edge(self, i, j, relative, covariance, *rest, **named)

    def node(self: Any, odometry: Any, step: Any, relative: Any, covariance: Any, *rest: Any) -> int:
        factors = rest[2] if len(rest) > 2 else ()
        spans = rest[3] if len(rest) > 3 else ()
        kinds[:] = ["sequential", *(["odometry"] * len(factors)), *(["span"] * len(spans))]
        key = add_node(self, odometry, step, relative, covariance, *rest)
        seen["online"].append(np.array(self.estimates[key], float))
        return key

    def loops(self: Any, accepted: Any) -> None:
        kinds[:] = ["place" if place[0] else "loop"] * len(accepted)
        add_loops(self, accepted)

    def recognising(self: Any, key: int) -> None:
        place[0] = True
        try:
            recognise(self, key)
        finally:
            place[0] = False

    with (
        patch.object(graph.PoseGraph, "add_edge", edge),
        patch.object(backend.BackEnd, "add_node", node),
        patch.object(backend.BackEnd, "add_loops", loops),
        patch.object(place_recognition.PlaceRecognition, "recognise", recognising),
    ):
        yield seen


def _factor_graph(
    factors: list[tuple[Any, ...]],
    config: dict[str, Any],
    keep: Any = None,
    truth: Any = None,
    parts: tuple[int, ...] = (2,),
) -> Any:
    """The recorded factors as a GTSAM graph (node 0 anchored as in the run); ``keep(f)`` filters them.

    With ``truth`` (the reference anchored at node 0) the sequential edges' components ``parts`` (0, 1: x, y; 2:
    heading) are replaced by the reference's: what a match perfect in those components would give.
    """
    import gtsam

    g = gtsam.NonlinearFactorGraph()
    g.add(
        gtsam.PriorFactorPose2(0, gtsam.Pose2(0, 0, 0), gtsam.noiseModel.Diagonal.Sigmas(np.array([1e-3, 1e-3, 1e-4])))
    )
    for f in factors:
        if keep is not None and not keep(f):
            continue
        kind, i, j, rel, cov = f
        if truth is not None and kind == "sequential":
            rel = np.array(rel, dtype=float)
            true = se2.between(truth[i], truth[j])
            rel[list(parts)] = true[list(parts)]
        noise: Any = gtsam.noiseModel.Gaussian.Covariance(graph.body_frame_covariance(rel, cov))
        if kind in ("loop", "place") and config["loop_kernel"] == "cauchy":
            cauchy = gtsam.noiseModel.mEstimator.Cauchy.Create(config["loop_kernel_scale"])
            noise = gtsam.noiseModel.Robust.Create(cauchy, noise)
        g.add(gtsam.BetweenFactorPose2(i, j, gtsam.Pose2(*map(float, rel)), noise))
    return g


def _values(poses: np.ndarray) -> Any:
    import gtsam

    v = gtsam.Values()
    for k, p in enumerate(poses):
        v.insert(k, gtsam.Pose2(*map(float, p)))
    return v


def _solve(g: Any, start: np.ndarray) -> np.ndarray:
    import gtsam

    params = gtsam.LevenbergMarquardtParams()
    params.setMaxIterations(100)
    params.setLinearSolverType("MULTIFRONTAL_QR")
    out = gtsam.LevenbergMarquardtOptimizer(g, _values(start), params).optimize()
    return np.asarray(gtsam.utilities.extractPose2(out), float).reshape(-1, 3)


def _node_ate(poses: np.ndarray, truth: np.ndarray) -> float:
    return float(ate(poses, truth)["rmse_m"])


def contributions(g: Any, plain: Any, optimum: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per factor of ``g`` (graph order), its linear share of ``optimum - truth``: an array (factors, N, 3).

    Linearised at the truth, ``d = H^-1 sum_i A_i' b_i`` with ``b_i`` factor ``i``'s whitened error at the truth
    (sign as GTSAM's ``JacobianFactor``); a robust factor keeps the weight it had at the optimum (the weight the
    solver used), taken as the ratio of its whitened error with and without the kernel there (``plain``: the same
    graph without kernels). The displacements are in each node's tangent (x, y in the node frame, theta).
    """
    n = len(optimum)
    at_opt, at_truth = _values(optimum), _values(truth)
    rows: list[int] = []
    cols: list[int] = []
    vals: list[float] = []
    blocks = []
    r = 0
    for idx in range(g.size()):
        robust, bare = g.at(idx), plain.at(idx)
        _, b_robust = robust.linearize(at_opt).jacobian()
        _, b_bare = bare.linearize(at_opt).jacobian()
        norm = float(np.linalg.norm(b_bare))
        weight = float(np.linalg.norm(b_robust)) / norm if norm > 1e-12 else 1.0
        lin = bare.linearize(at_truth)
        a, b = lin.jacobian()
        a, b = a * weight, b * weight
        for c, key in enumerate(lin.keys()):
            for i in range(a.shape[0]):
                for jj in range(3):
                    rows.append(r + i)
                    cols.append(3 * int(key) + jj)
                    vals.append(float(a[i, 3 * c + jj]))
        blocks.append((r, a.shape[0], b))
        r += a.shape[0]
    jac = sp.csr_matrix((vals, (rows, cols)), shape=(r, 3 * n))
    lu = splu((jac.T @ jac).tocsc())
    out = np.zeros((len(blocks), n, 3))
    for start in range(0, len(blocks), 256):
        chunk = blocks[start : start + 256]
        rhs = np.zeros((3 * n, len(chunk)))
        for c, (row, m, res) in enumerate(chunk):
            rhs[:, c] = jac[row : row + m].T @ res
        sol = lu.solve(rhs)
        out[start : start + len(chunk)] = sol.T.reshape(len(chunk), n, 3)
    return out


def _displaced(truth: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """The reference (anchored at node 0) moved by ``delta`` in each node's tangent (x, y in the node frame)."""
    c, s = np.cos(truth[:, 2]), np.sin(truth[:, 2])
    moved = truth.copy()
    moved[:, 0] += c * delta[:, 0] - s * delta[:, 1]
    moved[:, 1] += s * delta[:, 0] + c * delta[:, 1]
    moved[:, 2] += delta[:, 2]
    return moved


def diagnose(cell: str, overrides: dict[str, Any], parts: int, worst: int) -> dict[str, Any]:
    """Run one cell with every factor recorded and compare them with the reference (module docstring)."""
    dataset, degradation, seed = parse_cell(cell)
    seq = open_sequence(dataset).materialize()
    with recorded_factors() as seen:
        result = run_method(
            "gtsam-graph", seq, overrides=overrides, degradation=degradation, seed=seed, dataset_name=dataset
        )
    config = {
        "loop_kernel": overrides.get("loop_kernel", "cauchy"),
        "loop_kernel_scale": overrides.get("loop_kernel_scale", 1.0),
    }
    scans = np.asarray(result.extras["node_scans"], dtype=np.int64)
    ref = np.asarray(result.reference, float)[scans]
    truth = np.array([se2.between(ref[0], p) for p in ref])  # the reference anchored at node 0, as the graph is
    final = np.asarray(result.poses, float)[scans]
    final = np.array([se2.between(final[0], p) for p in final])
    factors = seen["factors"]
    n = len(truth)
    online = np.asarray(seen["online"], float).reshape(-1, 3)
    online = np.vstack([np.zeros((1, 3)), online])[:n]
    heading = np.degrees(np.angle(np.exp(1j * (final[:, 2] - truth[:, 2]))))
    heading -= np.median(heading)
    aligned_err = _position_errors(final, truth)
    online_err = np.hypot(*(online[:, :2] - truth[:, :2]).T)
    online_head = np.degrees(np.angle(np.exp(1j * (online[:, 2] - truth[:, 2]))))
    bounds = np.linspace(0, n, parts + 1).astype(int)
    route = [
        {
            "nodes": [int(a), int(b - 1)],
            "final_rms_m": round(float(np.sqrt(np.mean(aligned_err[a:b] ** 2))), 3),
            "final_heading_deg": round(float(np.mean(heading[a:b])), 2),
            "online_rms_m": round(float(np.sqrt(np.mean(online_err[a:b] ** 2))), 3),
            "online_heading_deg": round(float(np.mean(online_head[a:b])), 2),
        }
        for a, b in zip(bounds[:-1], bounds[1:], strict=True)
    ]
    g = _factor_graph(factors, config)
    solved = _solve(g, final)
    delta = contributions(g, _factor_graph(factors, {**config, "loop_kernel": "none"}), solved, truth)[1:]  # no prior
    errors = []  # per factor: error m, deg, stated deg, stated m, the error pose (the measurement seen from the truth)
    for _kind, i, j, rel, cov in factors:
        e = se2.between(se2.between(truth[i], truth[j]), rel)
        errors.append(
            (
                math.hypot(e[0], e[1]),
                math.degrees(e[2]),
                math.degrees(math.sqrt(cov[2, 2])),
                math.sqrt(max(cov[0, 0], cov[1, 1])),
                e,
            )
        )
    kinds: dict[str, Any] = {}
    total = delta.sum(axis=0)
    for name in sorted({f[0] for f in factors}):
        idx = [k for k, f in enumerate(factors) if f[0] == name]
        chi2 = chi2_xy = chi2_theta = 0.0
        for k in idx:
            cov = graph.body_frame_covariance(factors[k][3], factors[k][4])
            e = errors[k][4]
            chi2 += float(e @ np.linalg.solve(cov, e))
            chi2_xy += float(e[:2] @ np.linalg.solve(cov[:2, :2], e[:2]))
            chi2_theta += float(e[2] ** 2 / cov[2, 2])
        kinds[name] = {
            "count": len(idx),
            "error_rms_m": round(float(np.sqrt(np.mean([errors[k][0] ** 2 for k in idx]))), 4),
            "error_rms_deg": round(float(np.sqrt(np.mean([errors[k][1] ** 2 for k in idx]))), 3),
            "chi2_at_truth": round(chi2, 1),
            "chi2_per_dof_xy_theta": [round(chi2_xy / (2 * len(idx)), 2), round(chi2_theta / len(idx), 2)],
            "ate_m": round(_node_ate(_displaced(truth, delta[idx].sum(axis=0)), truth), 4),
        }
    single = np.array([_node_ate(_displaced(truth, d), truth) for d in delta])
    order = np.argsort(-single)[:worst]
    wrong = [
        k
        for k, f in enumerate(factors)
        if f[0] in ("loop", "place") and (errors[k][0] > WRONG_M or abs(errors[k][1]) > WRONG_DEG)
    ]
    offline = {
        "as_run": round(_node_ate(final, truth), 4),
        "re_solved": round(_node_ate(solved, truth), 4),
        "linear_total": round(_node_ate(_displaced(truth, total), truth), 4),
        "no_closures": round(
            _node_ate(_solve(_factor_graph(factors, config, lambda f: f[0] not in ("loop", "place")), final), truth), 4
        ),
        "wrong_closures_removed": round(
            _node_ate(
                _solve(_factor_graph(factors, config, lambda f: not any(f is factors[k] for k in wrong)), final), truth
            ),
            4,
        ),
        "true_match_headings": round(_node_ate(_solve(_factor_graph(factors, config, truth=truth), final), truth), 4),
        "true_match_translations": round(
            _node_ate(_solve(_factor_graph(factors, config, truth=truth, parts=(0, 1)), final), truth), 4
        ),
        "true_matches": round(
            _node_ate(_solve(_factor_graph(factors, config, truth=truth, parts=(0, 1, 2)), final), truth), 4
        ),
    }
    return {
        "cell": cell,
        "ate_m": round(float(ate(result.poses, result.reference)["rmse_m"]), 4),
        "nodes": n,
        "route": route,
        "kinds": kinds,
        "worst_factors": [
            {
                "kind": factors[k][0],
                "nodes": [factors[k][1], factors[k][2]],
                "ate_alone_m": round(float(single[k]), 4),
                "error_m": round(errors[k][0], 3),
                "error_deg": round(errors[k][1], 2),
                "stated_m": round(errors[k][3], 3),
                "stated_deg": round(errors[k][2], 2),
                "truth_turn_deg": round(math.degrees(se2.between(truth[factors[k][1]], truth[factors[k][2]])[2]), 1),
            }
            for k in order
        ],
        "closures": [
            {
                "kind": f[0],
                "nodes": [f[2], f[1]],
                "error_m": round(errors[k][0], 3),
                "error_deg": round(errors[k][1], 2),
                "stated_m": round(errors[k][3], 3),
                "ate_alone_m": round(float(single[k]), 4),
            }
            for k, f in enumerate(factors)
            if f[0] in ("loop", "place")
        ],
        "offline": offline,
    }


def _position_errors(est: np.ndarray, truth: np.ndarray) -> np.ndarray:
    from albot1.metrics.ate import position_errors

    return np.asarray(position_errors(est, truth), float)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--parts", type=int, default=8)
    parser.add_argument("--worst", type=int, default=10)
    parser.add_argument("cells", nargs="+")
    args = parser.parse_args()
    overrides = {key: _value(value) for key, _, value in (s.partition("=") for s in args.settings)}
    for cell in args.cells:
        print(json.dumps(diagnose(cell, overrides, args.parts, args.worst)), flush=True)


if __name__ == "__main__":
    main()
