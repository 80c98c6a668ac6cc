"""Where gtsam-graph's CPU goes in a cell, and a cell's CPU and output digest under one checkout (issue 24).

Two commands, each in one process that imports the bench forkserver's preload and warms gtsam-graph's kernels
first, as a forked bench cell finds them::

    python benchmarks/gtsam_graph_cost.py profile 'intel|none|0' 'fhw-corrected?odometry=laser-pose|bias:0.02:0.5|0'
    python benchmarks/gtsam_graph_cost.py digest 'intel|none|0' ...      # run under each checkout's PYTHONPATH

A cell is ``DATASET|DEGRADATION|SEED``. ``profile`` runs each cell once unmeasured (imports, caches), then again
under a sampler: every millisecond of process CPU (``ITIMER_PROF``) the Python stack is read, and the sample
weighs the process CPU spent since the previous one (a long C call, ISAM2's update or a compiled kernel, holds
back the signal: its samples merge, their weight does not). Each sample goes to the innermost frame that names
a part (:data:`PARTS`); the shares are printed per cell and in all. ``digest`` prints per cell the CPU-s of
``run_method`` (``time.process_time`` around it) and a sha256 of its poses, map points, counters (less the
measured ones) and extras: alternate two checkouts' processes and compare (docs/baselines.md, "Cost (issue 24),
fifth round").
"""

from __future__ import annotations

import argparse
import collections
import hashlib
import json
import signal
import sys
import time
from types import FrameType

import numpy as np

#: a part of a run and the frames (``file.py:qualname`` prefixes) that make it, innermost match first
PARTS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("ICP compiled loop", ("registration.py:_iterate_compiled",)),
    ("ICP final terms (numpy path)", ("registration.py:_linearise",)),
    ("ICP grid, k-d tree", ("registration.py:Target.grid", "registration.py:Target.tree", "nearest.py:Matches")),
    ("ICP Python", ("registration.py:register", "registration.py:try_register")),
    ("ISAM2 update", ("graph.py:PoseGraph.update",)),
    ("ISAM2 estimates", ("graph.py:PoseGraph.estimate",)),
    ("graph nodes, edges", ("graph.py:PoseGraph.add", "graph.py:body_frame")),
    ("final LM", ("graph.py:PoseGraph.optimise",)),
    ("place search (B&B)", ("correlative.py:branch_and_bound_search",)),
    ("loop correlative search", ("correlative.py:correlative_search",)),
    ("line normals", ("registration.py:line_normals",)),
    ("targets", ("backend.py:BackEnd.target",)),
    ("graph distances", ("backend.py:BackEnd.graph_distances",)),
    ("odometry trust", ("odometry_trust.py", "earned_choice.py", "odometry_runs.py")),
    ("preprocess", ("frontend.py:preprocess",)),
    ("map, scan poses", ("backend.py:BackEnd.project_map", "backend.py:BackEnd.scan_poses")),
    ("other front, back, loop Python", ("frontend.py", "backend.py", "loop_", "place_recognition.py", "mapper.py")),
    ("run_method (log, degrade, checks)", ("execute.py:run_method",)),
)


def _part(frame: FrameType | None) -> str:
    while frame is not None:
        code = frame.f_code
        key = f"{code.co_filename.rsplit('/', 1)[-1]}:{code.co_qualname}"
        for name, prefixes in PARTS:
            if key.startswith(prefixes):
                return name
        frame = frame.f_back
    return "other"


def _cells(specs: list[str]) -> list[tuple[str, str, int]]:
    out = []
    for spec in specs:
        dataset, degradation, seed = spec.split("|")
        out.append((dataset, degradation, int(seed)))
    return out


def _warm() -> None:
    import albot1.bench.preload  # noqa: F401 -- the forkserver's state
    from albot1.methods.baselines.gtsam_graph import block_sums, icp_loop, nearest

    for module in (nearest, icp_loop, block_sums):
        module.warm_up()


def profile(specs: list[str]) -> None:
    """Per cell and in all: the CPU share of each part (:data:`PARTS`)."""
    from albot1.data import open_sequence
    from albot1.runs.execute import run_method

    _warm()
    everything: dict[str, float] = collections.defaultdict(float)
    for dataset, degradation, seed in _cells(specs):
        sequence = open_sequence(dataset)
        run_method("gtsam-graph", sequence, degradation=degradation, seed=seed)
        shares: dict[str, float] = collections.defaultdict(float)
        last = [time.process_time()]

        def sample(
            signum: int, frame: FrameType | None, shares: dict[str, float] = shares, last: list[float] = last
        ) -> None:
            now = time.process_time()
            shares[_part(frame)] += now - last[0]
            last[0] = now

        signal.signal(signal.SIGPROF, sample)
        last[0] = time.process_time()
        signal.setitimer(signal.ITIMER_PROF, 0.001, 0.001)
        run_method("gtsam-graph", sequence, degradation=degradation, seed=seed)
        signal.setitimer(signal.ITIMER_PROF, 0, 0)
        for name, cpu in shares.items():
            everything[name] += cpu
        _print(f"{dataset}|{degradation}|{seed}", shares)
    _print("all", everything)


def _print(title: str, shares: dict[str, float]) -> None:
    total = sum(shares.values())
    ranked = sorted(shares.items(), key=lambda item: -item[1])
    parts = ", ".join(f"{name} {100 * cpu / total:.1f} %" for name, cpu in ranked)
    print(f"{title}: {total:.2f} CPU-s; {parts}", flush=True)


def digest(specs: list[str]) -> None:
    """Per cell: ``run_method``'s CPU-s and the sha256 of what it returned (one JSON line each)."""
    from albot1.data import open_sequence
    from albot1.runs.execute import run_method

    _warm()
    run_method("gtsam-graph", open_sequence("aces[:150]"))  # the imports a first run makes
    for dataset, degradation, seed in _cells(specs):
        sequence = open_sequence(dataset)
        start = time.process_time()
        result = run_method("gtsam-graph", sequence, degradation=degradation, seed=seed)
        cpu = time.process_time() - start
        sha = hashlib.sha256()
        sha.update(np.ascontiguousarray(result.poses, dtype=np.float64).tobytes())
        sha.update(np.ascontiguousarray(result.map.points, dtype=np.float64).tobytes())
        counters = {k: v for k, v in result.counters.items() if not k.endswith(("_s", "_mb"))}
        sha.update(json.dumps(counters, sort_keys=True).encode())
        sha.update(json.dumps(result.extras, sort_keys=True, default=str).encode())
        line = {"cell": f"{dataset}|{degradation}|{seed}", "cpu_s": round(cpu, 3), "sha256": sha.hexdigest()[:16]}
        print(json.dumps(line), flush=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("command", choices=("profile", "digest"))
    parser.add_argument("cells", nargs="+", help="DATASET|DEGRADATION|SEED")
    args = parser.parse_args(argv)
    (profile if args.command == "profile" else digest)(args.cells)
    return 0


if __name__ == "__main__":
    sys.exit(main())
