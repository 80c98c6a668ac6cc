"""Where a cell's CPU goes, function by function, with no profiler: the work that grows with the log (issue 24).

``cProfile`` charges every call a fixed cost, which on an odometry cell (a few calls per scan, 7,000-14,000
scans) inflates the per-scan functions twofold. This wraps a chosen list of functions (:data:`TARGETS`: the
opening of the log, the runner's loop, the method's ``process``, the point map's thinning, the run folder's
files, the preview, the evaluation and each metric) with a CPU-clock timer that charges each call its own time
less that of the wrapped calls inside it, and runs each cell of a suite in a fork of a process that imported
:mod:`albot1.bench.preload`, as the bench's forkserver forks a cell::

    python benchmarks/cell_phases_by_function.py SUITE.toml --rounds 3 [--only fr-clinic]

Per cell it prints the cell's CPU (each round) and each function's median exclusive CPU-s and share of the
cell, with the clock reads taken off (a ``process_time`` read is a system call, ~9 us on the VM of session 26:
measured in each fork and subtracted per call). Used for docs/benchmarking.md, "Session 26".
The run folders go to a temporary folder that is removed.
"""

from __future__ import annotations

import argparse
import collections
import functools
import importlib
import json
import os
import resource
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

#: (module, function or Class.method, label): wrapped in every module that holds the same function object
TARGETS = (
    ("albot1.data.open", "open_sequence", "open"),
    ("albot1.data.relations", "read_relations", "read_relations"),
    ("albot1.data.finite", "frame_problem", "frames: finite check"),
    ("albot1.runs.execute", "withhold_ground_truth", "run_method: withhold"),
    ("albot1.runs.execute", "run_method", "run_method: loop, frames and rest"),
    ("albot1.methods.baselines.odometry", "OdometryMapper.process", "method: process"),
    ("albot1.methods.baselines.odometry", "OdometryMapper.finish", "method: finish"),
    ("albot1.methods.baselines.point_map", "ThinnedPointMap._flush", "method: map thinning"),
    ("albot1.data.model", "Scan.points", "method: scan points"),
    ("albot1.runs.folder", "write_run", "write_run: rest"),
    ("albot1.data.trajectory", "write_tum", "write_run: tum"),
    ("albot1.data.relations", "write_relations", "write_run: relations"),
    ("albot1.runs.map_files", "map_text", "write_run: map text"),
    ("albot1.runs.map_files", "_write_npz", "write_run: npz"),
    ("albot1.report.preview", "render_preview", "preview"),
    ("albot1.runs.evaluate", "evaluate_run", "evaluate: rest"),
    ("albot1.runs.folder", "read_run", "evaluate: read_run"),
    ("albot1.data.trajectory", "read_tum", "evaluate: read_tum"),
)


def _clock_cost() -> float:
    """CPU-s of one ``time.process_time()`` read here (a system call: ~9 us on the 2-core VM of session 26)."""
    reads = 2_000
    start = time.process_time()
    for _ in range(reads):
        time.process_time()
    return (time.process_time() - start) / reads


def _install(totals: collections.Counter[str]) -> None:
    """Wrap :data:`TARGETS` and every metric's ``compute`` with exclusive CPU timers adding into ``totals``.

    Each wrapped call reads the clock twice; about one read falls inside the call's own span and one in its
    caller's, so ``<label> calls`` and ``<label> inner calls`` are counted too and :func:`main` takes one read's
    cost off each (on a log of 13,631 scans, four wrapped calls a scan are ~1 CPU-s of clock reads here).
    """
    stack: list[tuple[str, float]] = []

    def wrap(function: Callable[..., Any], label: str) -> Callable[..., Any]:
        @functools.wraps(function)
        def timed(*args: Any, **kwargs: Any) -> Any:
            start = time.process_time()
            stack.append((label, 0.0))
            try:
                return function(*args, **kwargs)
            finally:
                spent = time.process_time() - start
                inner = stack.pop()[1]
                totals[label] += spent - inner
                totals[f"{label} calls"] += 1
                if stack:
                    caller, below = stack[-1]
                    stack[-1] = (caller, below + spent)
                    totals[f"{caller} inner calls"] += 1
                else:
                    totals["unwrapped inner calls"] += 1

        return timed

    for module_name, name, label in TARGETS:
        module = importlib.import_module(module_name)
        if "." in name:
            owner, method = name.split(".")
            cls = getattr(module, owner)
            setattr(cls, method, wrap(cls.__dict__[method], label))
            continue
        original = getattr(module, name)
        timed = wrap(original, label)
        for holder in list(sys.modules.values()):
            namespace = getattr(holder, "__dict__", None) or {}
            for key, value in list(namespace.items()):
                if value is original:
                    namespace[key] = timed
    from albot1.metrics.registry import metric_registry

    for metric in metric_registry():
        object.__setattr__(metric, "compute", wrap(metric.compute, f"evaluate: metric {metric.name}"))


def _cell_in_fork(cell: Any, out: Path) -> dict[str, float]:
    """One cell in a fork, as the forkserver runs it: exclusive CPU-s per label and the cell's whole CPU."""
    from albot1.bench.cell_main import freeze_inherited_heap
    from albot1.bench.cells import execute_cell

    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(read)
        freeze_inherited_heap()
        totals: collections.Counter[str] = collections.Counter()
        _install(totals)
        from albot1.report.preview import render_preview  # the wrapped function, as the bench passes it by name

        before = resource.getrusage(resource.RUSAGE_SELF)
        execute_cell(cell, out, preview=render_preview)
        after = resource.getrusage(resource.RUSAGE_SELF)
        totals["cell"] = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
        totals["clock"] = _clock_cost()
        os.write(write, json.dumps(totals).encode())
        os._exit(0)
    os.close(write)
    with os.fdopen(read, "rb") as pipe:
        data: dict[str, float] = json.loads(pipe.read())
    os.waitpid(pid, 0)
    return data


def _corrected(found: dict[str, float]) -> dict[str, float]:
    """Each label's CPU-s less a clock read per call of it and per wrapped call inside it; the cell two a call."""
    clock = found["clock"]
    labels = {k for k in found if not k.endswith(" calls") and k != "clock"} - {"cell"}
    out = {k: found[k] - clock * (found.get(f"{k} calls", 0.0) + found.get(f"{k} inner calls", 0.0)) for k in labels}
    calls = sum(v for k, v in found.items() if k.endswith(" calls") and not k.endswith(" inner calls"))
    out["cell"] = found["cell"] - 2 * clock * calls
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("suite", help="a suite .toml")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--only", default="", help="only cells whose method|dataset|degradation contains this")
    args = parser.parse_args(argv)

    import albot1.bench.preload  # noqa: F401 -- the forkserver's state: imports, kernels, fonts
    from albot1.bench.plan import plan_suite
    from albot1.bench.suite import load_suite
    from albot1.settings import get_settings

    cells = [
        c
        for c in plan_suite(load_suite(args.suite), get_settings()).cells
        if args.only in f"{c.method}|{c.dataset_label}|{c.degradation}"
    ]
    runs: dict[str, list[dict[str, float]]] = collections.defaultdict(list)
    with tempfile.TemporaryDirectory(prefix="albot1-cell-functions-") as tmp:
        for _ in range(args.rounds):
            for cell in cells:
                shutil.rmtree(Path(tmp) / cell.key, ignore_errors=True)  # the whole cell each round
                runs[f"{cell.method}|{cell.dataset_label}|{cell.degradation}"].append(_cell_in_fork(cell, Path(tmp)))
    for name, found in runs.items():
        corrected = [_corrected(r) for r in found]
        labels = sorted(
            {k for r in corrected for k in r} - {"cell"}, key=lambda k: -sum(r.get(k, 0.0) for r in corrected)
        )
        whole = sorted(r["cell"] for r in corrected)[len(corrected) // 2]
        each = " ".join(f"{r['cell']:.3f}" for r in corrected)
        reads = sorted(r["clock"] for r in found)[len(found) // 2]
        print(f"{name}: cell CPU-s {each} (median {whole:.3f}; clock reads taken off, {1e6 * reads:.1f} us each)")
        for label in labels:
            median = sorted(r.get(label, 0.0) for r in corrected)[len(corrected) // 2]
            if median >= 0.0005:
                print(f"    {label:34s} {median:7.3f}  {100 * median / whole:5.1f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
