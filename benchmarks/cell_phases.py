"""Where a bench cell's CPU goes, phase by phase, and how much of it is the cycle collector (issue 24).

Runs cells of a stored grid (their ``cell.json``: every Nth, of the methods
named), each in its own fork of this process after it imported
:mod:`albot1.bench.preload`, as the bench's forkserver forks a cell, and
after what a forked cell does first in the code under test
(``cell_main.freeze_inherited_heap`` where it exists). In each fork it
times, in CPU seconds of that process, opening the dataset, ``run_method``
(and the method's own CPU inside it), writing the run folder, drawing the
preview, ``evaluate_run``, and the time spent in the cycle collector (gc
callbacks) with the number of full collections::

    python benchmarks/cell_phases.py results/default --every 10 --methods odometry,albot1,albot1-places,kiss-icp

To compare two checkouts, run it once with each on ``PYTHONPATH`` (alternating,
in one session: on a shared machine only ratios of one session mean
anything). The run folders go to a temporary folder that is removed; the
store is only read. The script imports only functions both sides have.
"""

from __future__ import annotations

import argparse
import collections
import gc
import json
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

PHASES = ("open", "method", "run_method other", "files", "preview", "evaluate")


def _cell_phases(cell_json: dict[str, Any], out: Path) -> dict[str, float]:
    """The phases of one cell, run here (in the fork): CPU seconds each, the collector's time and full collections."""
    from albot1.bench import cell_main
    from albot1.bench.grid import Cell
    from albot1.data.open import open_sequence
    from albot1.report.preview import render_preview
    from albot1.runs.evaluate import evaluate_run
    from albot1.runs.execute import run_method
    from albot1.runs.folder import write_run

    getattr(cell_main, "freeze_inherited_heap", lambda: None)()
    spent: dict[str, float] = collections.defaultdict(float)
    started = [0.0]

    def collector(phase: str, info: dict[str, int]) -> None:
        if phase == "start":
            started[0] = time.process_time()
            return
        spent["collector"] += time.process_time() - started[0]
        spent["full collections"] += info["generation"] == 2

    gc.callbacks.append(collector)
    cell = Cell.from_json(cell_json)
    last = time.process_time()

    def mark(name: str) -> None:
        nonlocal last
        now = time.process_time()
        spent[name] += now - last
        last = now

    sequence = open_sequence(cell.dataset_label)
    mark("open")
    result = run_method(
        cell.method,
        sequence,
        preset=cell.preset,
        overrides=dict(cell.overrides),
        degradation=cell.degradation,
        seed=cell.seed,
        dataset_name=cell.dataset_label,
    )
    mark("run_method other")
    method_cpu = result.cpu_s or 0.0  # None where the platform cannot measure it
    spent["run_method other"] -= method_cpu
    spent["method"] = method_cpu
    run_dir = write_run(result, out)
    mark("files")
    render_preview(result, run_dir / "preview.png")
    mark("preview")
    evaluate_run(run_dir)
    mark("evaluate")
    spent["cell"] = time.process_time()
    return dict(spent)


def _in_fork(cell_json: dict[str, Any], out: Path) -> dict[str, float]:
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: one cell, its numbers down the pipe, then out without the parent's exit handlers
        os.close(read)
        code = 0
        try:
            payload = json.dumps(_cell_phases(cell_json, out)).encode()
        except Exception as exc:  # noqa: BLE001 -- reported by the parent under the cell's name
            payload, code = json.dumps({"error": f"{type(exc).__name__}: {exc}"}).encode(), 1
        with os.fdopen(write, "wb") as pipe:
            pipe.write(payload)
        os._exit(code)
    os.close(write)
    with os.fdopen(read, "rb") as pipe:
        data: dict[str, Any] = json.loads(pipe.read() or b"{}")
    os.waitpid(pid, 0)
    return data


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("store", type=Path, help="a results folder of albot1 bench (its runs/*/cell.json)")
    parser.add_argument("--every", type=int, default=10, help="take every Nth cell of those left, by key")
    parser.add_argument("--methods", default="", help="comma-separated: only these methods")
    args = parser.parse_args(argv)

    import albot1.bench.preload  # noqa: F401 -- the forkserver's state: imports, kernels, fonts

    methods = {m for m in args.methods.split(",") if m}
    cells = [json.loads(p.read_text()) for p in sorted(args.store.glob("runs/*/cell.json"))]
    cells = [c for c in cells if c.get("trajectory") is None and (not methods or c["method"] in methods)]
    totals: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
    with tempfile.TemporaryDirectory(prefix="albot1-cell-phases-") as tmp:
        for cell in cells[:: args.every]:
            data = _in_fork(cell, Path(tmp))
            if "error" in data:
                print(f"skipped {cell['method']} on {cell['dataset']}: {data['error']}", file=sys.stderr)
                continue
            for key in ("all", cell["method"]):
                totals[key].update(data)
                totals[key]["cells"] += 1
    for key, sums in sorted(totals.items(), key=lambda item: item[0] != "all"):
        outside = sum(sums[p] for p in PHASES if p != "method")
        shares = ", ".join(f"{p} {100 * sums[p] / outside:.0f} %" for p in PHASES if p != "method" and outside > 0)
        print(
            f"{key}: {sums['cells']:.0f} cells, CPU-s {sums['cell']:.2f} (method {sums['method']:.2f}, outside it "
            f"{outside:.2f}: {shares}); collector {sums['collector']:.2f} CPU-s, "
            f"{sums['full collections']:.0f} full collections"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
