"""Hand-written 2D point-to-line ICP against small_gicp on real consecutive scan pairs (a script).

Why this exists: issue 4 asks to prefer a maintained registration library
unless a hand-written 2D ICP measures better. Each scan of the Intel
corrected log is registered against a local map of the previous five scans
(placed with the SLAM-corrected poses), from the true relative pose
perturbed by N(0, 0.1 m) in x, y and N(0, 3 deg) in theta (seeded); the
error is measured against the corrected poses (which are themselves a SLAM
estimate, so ~1-2 cm is the floor). small_gicp works in 3D: the 2D points
are extruded to z = -0.5, 0, +0.5 so that their neighbourhoods are vertical
planes (flat z = 0 clouds give degenerate covariances).

Usage (small_gicp is not a project dependency: ``pip install small_gicp``)::

    ALBOT1_DATA_DIR=/path/to/datasets .venv/bin/python benchmarks/gtsam_graph_registration_compare.py
"""

from __future__ import annotations

import math
import time

import numpy as np

from albot1.data.open import open_sequence
from albot1.geometry import se2
from albot1.methods.baselines.gtsam_graph.registration import IcpParams, Target, register


def _lift(points: np.ndarray) -> np.ndarray:
    return np.concatenate([np.column_stack([points, np.full(len(points), z)]) for z in (-0.5, 0.0, 0.5)])


def _matrix(pose: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    m[:2, :2] = [[c, -s], [s, c]]
    m[:2, 3] = pose[:2]
    return m


def main(local_map: int = 5) -> None:
    import small_gicp

    seq = open_sequence("intel-corrected", odometry="laser-pose").materialize()
    ref = seq.reference
    scans = []
    for frame in seq.frames():
        pts = frame.scan.points()
        r = np.hypot(pts[:, 0], pts[:, 1])
        scans.append(pts[(r > 0.1) & (r < 30.0)])
    rng = np.random.default_rng(0)
    errors: dict[str, list[np.ndarray]] = {
        "point-to-line ICP (this package)": [],
        "small_gicp GICP": [],
        "small_gicp PLANE_ICP": [],
    }
    times: dict[str, list[float]] = {k: [] for k in errors}
    for i in range(local_map, len(scans)):
        target = np.concatenate(
            [se2.transform_points(se2.between(ref[i - 1], ref[j]), scans[j]) for j in range(i - local_map, i)]
        )
        truth = se2.between(ref[i - 1], ref[i])
        guess = truth + np.array([rng.normal(0, 0.1), rng.normal(0, 0.1), math.radians(rng.normal(0, 3.0))])
        start = time.perf_counter()
        result = register(Target.from_points(target), scans[i], guess, IcpParams(prior_sigma_xy_m=1.0))
        times["point-to-line ICP (this package)"].append(time.perf_counter() - start)
        errors["point-to-line ICP (this package)"].append(se2.between(truth, result.pose))
        for name, kind in (("small_gicp GICP", "GICP"), ("small_gicp PLANE_ICP", "PLANE_ICP")):
            start = time.perf_counter()
            out = small_gicp.align(
                _lift(target),
                _lift(scans[i]),
                _matrix(guess),
                registration_type=kind,
                downsampling_resolution=0.05,
                max_correspondence_distance=1.0,
                max_iterations=30,
            )
            times[name].append(time.perf_counter() - start)
            t = out.T_target_source
            errors[name].append(se2.between(truth, np.array([t[0, 3], t[1, 3], math.atan2(t[1, 0], t[0, 0])])))
    print(f"{len(scans) - local_map} scan pairs of intel-corrected, local map of {local_map} scans")
    print("| method | trans. error median / p90 (cm) | > 10 cm | rot. error median / p90 (deg) | time median (ms) |")
    print("|---|---|---|---|---|")
    for name, errs in errors.items():
        e = np.asarray(errs)
        trans = np.hypot(e[:, 0], e[:, 1]) * 100
        rot = np.degrees(np.abs(e[:, 2]))
        print(
            f"| {name} | {np.median(trans):.2f} / {np.percentile(trans, 90):.2f} | {np.mean(trans > 10):.1%} "
            f"| {np.median(rot):.3f} / {np.percentile(rot, 90):.3f} | {np.median(times[name]) * 1000:.2f} |"
        )


if __name__ == "__main__":
    main()
