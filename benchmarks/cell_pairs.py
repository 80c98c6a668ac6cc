"""A cell's CPU under two checkouts, cell by cell, alternated: what a change to a cell's fixed costs is worth.

On a shared machine whole grids run one after the other differ by more than
a few milliseconds a cell (the load moves between them), so each cell of a
suite is run here by both checkouts back to back, their order swapped from
one cell to the next. Each checkout has a worker process that imports
:mod:`albot1.bench.preload` as the bench's forkserver does and plans the
suite with its own code (the run keys name the code), then forks one cell
per request, freezes the inherited heap as a forked cell does, and runs
``execute_cell`` with the run preview: open, degrade, run, write the run
folder, draw the preview, evaluate. It reports the fork's CPU (user +
system, from the fork to the end of the cell) and the method's own CPU
(``result.json``)::

    python benchmarks/cell_pairs.py SUITE.toml --old <checkout> --new <checkout> --rounds 3 \\
        --out <folder> --preload odometry,kiss-icp

Each round runs every cell of the suite once with each checkout (the run
folder removed first, so the whole cell runs each time); the run folders are
kept under ``--out/old`` and ``--out/new``; ``--compare`` then compares them file by file, byte for byte
(only the fields that name the code or time the run masked: ``result.json``'s key, timing and code version,
``metrics.json``'s ``run`` and ``cost``, ``cell.json``'s key and code version; ``attempt.json``,
``cell.log``, ``DONE`` and ``per_scan_ns.npy`` left out); a ``.npz`` or ``.png`` whose bytes differ is
compared by what it decodes to (arrays; RGBA pixels) and counted apart. Used for
docs/benchmarking.md, "Session 22", "Session 24" and "Session 26" (``--by-dataset``: a line per dataset and
degradation too).
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import resource
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any


def _plan(suite: str) -> list[dict[str, Any]]:
    """The suite's cells as JSON, planned by this checkout's code."""
    from albot1.bench.plan import plan_suite
    from albot1.bench.suite import load_suite
    from albot1.settings import get_settings

    return [cell.to_json() for cell in plan_suite(load_suite(suite), get_settings()).cells]


def _in_fork(task: Any) -> Any:
    """``task()``'s JSON result, computed in a fork: planning imports what a cell would, and the worker must not
    hold it (a cell of the old code would then find imported what the new code moved into the preload)."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(read)
        os.write(write, json.dumps(task()).encode())
        os._exit(0)
    os.close(write)
    with os.fdopen(read, "rb") as pipe:
        data = pipe.read()
    os.waitpid(pid, 0)
    return json.loads(data)


def worker(suite: str, out: Path) -> int:
    """One checkout's cells on request (stdin: a cell name per line; stdout: its CPU-s as JSON)."""
    import albot1.bench.preload  # noqa: F401 -- the forkserver's state: imports, kernels, fonts
    from albot1.bench.cell_main import freeze_inherited_heap
    from albot1.bench.cells import execute_cell
    from albot1.bench.grid import Cell
    from albot1.report.preview import render_preview

    planned = [Cell.from_json(c) for c in _in_fork(lambda: _plan(suite))]
    cells = {f"{c.method}|{c.preset}|{c.dataset_label}|{c.degradation}|{c.seed}": c for c in planned}
    out.mkdir(parents=True, exist_ok=True)
    print(json.dumps(sorted(cells)), flush=True)
    for line in sys.stdin:
        cell = cells[line.strip()]
        shutil.rmtree(out / cell.key, ignore_errors=True)  # the whole cell each time, not only its evaluation
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:  # the cell, as a forkserver child runs it; its numbers down the pipe
            os.close(read)
            freeze_inherited_heap()
            execute_cell(cell, out, preview=render_preview)
            usage = resource.getrusage(resource.RUSAGE_SELF)
            timing = json.loads((out / cell.key / "result.json").read_text())["timing"]
            payload = {"cpu": usage.ru_utime + usage.ru_stime, "method": timing["cpu_s"] or 0.0}
            os.write(write, json.dumps(payload).encode())
            os._exit(0)
        os.close(write)
        with os.fdopen(read, "rb") as pipe:
            data = pipe.read()
        os.waitpid(pid, 0)
        print(data.decode() or '{"error": true}', flush=True)
    return 0


#: Left out of the byte comparison: stamps and timing only (DONE holds the run key, which names the code).
_STAMPS = frozenset({"attempt.json", "cell.log", "per_scan_ns.npy", "DONE"})


def _masked(name: str, data: dict[str, Any]) -> dict[str, Any]:
    """``data`` (a JSON file of a run) without the fields that name the code or time the run."""
    if name == "result.json":
        versions = {k: v for k, v in data["versions"].items() if k != "code"}
        return {**{k: v for k, v in data.items() if k not in ("key", "timing")}, "versions": versions}
    if name == "metrics.json":
        return {k: v for k, v in data.items() if k not in ("run", "cost")}
    if name == "cell.json":
        return {k: v for k, v in data.items() if k not in ("key", "code_version")}
    return data


def _decoded(data: bytes) -> Any:
    """What a ``.npz`` (each array's name, dtype, shape and bytes) or a ``.png`` (its RGBA pixels) holds."""
    import io

    import numpy as np

    if data.startswith(b"\x89PNG"):
        from PIL import Image

        with Image.open(io.BytesIO(data)) as image:
            return image.size, image.convert("RGBA").tobytes()
    with np.load(io.BytesIO(data), allow_pickle=False) as npz:
        return [(k, str(npz[k].dtype), npz[k].shape, npz[k].tobytes()) for k in sorted(npz.files)]


def compare(old: Path, new: Path) -> int:
    """Every file of the two sides' run folders (matched by cell) the same bytes, stamps and timing masked."""

    def folders(root: Path) -> dict[str, Path]:
        runs = ((p.parent, json.loads(p.read_text())) for p in root.glob("*/result.json"))
        return {f"{r['method']}|{r['preset']}|{r['dataset']}|{r['degradation']}|{r['seed']}": d for d, r in runs}

    sides = folders(old), folders(new)
    same, decoded = 0, 0
    differing = [f"{name}: a cell of one side only" for name in sides[0].keys() ^ sides[1].keys()]
    for cell in sorted(sides[0].keys() & sides[1].keys()):
        files = [{p.name for p in side[cell].iterdir()} for side in sides]
        differing += [f"{cell}: {name} in one folder only" for name in files[0] ^ files[1]]
        for name in sorted(files[0] & files[1] - _STAMPS):
            a, b = ((side[cell] / name).read_bytes() for side in sides)
            if name in ("result.json", "metrics.json", "cell.json"):
                a, b = (_masked(name, json.loads(x)) for x in (a, b))  # type: ignore[assignment]
            if a == b:
                same += 1
            elif name.endswith((".npz", ".png")) and _decoded(a) == _decoded(b):
                decoded += 1  # a container written another way (deflate level, colour channels): the same content
            else:
                differing.append(f"{cell}: {name}")
    counts = f"{same} files identical, {decoded} of the same decoded content (.npz arrays, .png pixels)"
    print("\n".join(differing + [f"{len(sides[0])} cells: {counts}, {len(differing)} differing"]))
    return 1 if differing else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("suite", help="a suite .toml (keep it to cheap cells: each runs 2 x rounds times)")
    parser.add_argument("--old", type=Path, required=True, help="the checkout to compare against")
    parser.add_argument("--new", type=Path, required=True, help="the checkout with the change")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--out", type=Path, required=True, help="the run folders: OUT/old, OUT/new")
    parser.add_argument("--preload", default="", help="ALBOT1_PRELOAD_METHODS for the workers (the suite's methods)")
    parser.add_argument("--compare", action="store_true", help="only compare OUT/old and OUT/new, byte for byte")
    parser.add_argument("--by-dataset", action="store_true", help="also sum by dataset and degradation")
    parser.add_argument("--worker", nargs=2, metavar=("SUITE", "OUT"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        return worker(args.worker[0], Path(args.worker[1]))
    if args.compare:
        return compare(args.out / "old", args.out / "new")

    env = dict(os.environ, ALBOT1_PRELOAD_METHODS=args.preload)
    procs = {
        tag: subprocess.Popen(
            [
                sys.executable,
                __file__,
                args.suite,
                "--old",
                ".",
                "--new",
                ".",
                "--out",
                ".",
                "--worker",
                args.suite,
                str(args.out / tag),
            ],
            env=dict(env, PYTHONPATH=str(tree.resolve())),
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        for tag, tree in (("old", args.old), ("new", args.new))
    }
    names = {tag: json.loads(proc.stdout.readline()) for tag, proc in procs.items()}  # type: ignore[union-attr]
    if names["old"] != names["new"]:
        raise SystemExit("the two checkouts plan different cells for this suite")
    sums: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
    for done in range(args.rounds):
        for index, name in enumerate(names["old"]):
            for tag in ("old", "new") if (index + done) % 2 == 0 else ("new", "old"):
                procs[tag].stdin.write(name + "\n")  # type: ignore[union-attr]
                procs[tag].stdin.flush()  # type: ignore[union-attr]
                data = json.loads(procs[tag].stdout.readline())  # type: ignore[union-attr]
                keys = ["all", name.split("|")[0]] + (["|".join(name.split("|")[2:4])] if args.by_dataset else [])
                for key in keys:
                    sums[key][f"{tag} cpu"] += data["cpu"]
                    sums[key][f"{tag} method"] += data["method"]
                    sums[key][f"{tag} cells"] += 1
        for key, s in sorted(sums.items()):
            n = s["old cells"]
            old_out, new_out = (s["old cpu"] - s["old method"]) / n, (s["new cpu"] - s["new method"]) / n
            print(
                f"after round {done + 1}: {key:13s} {n:4d} cells: CPU-s a cell old {s['old cpu'] / n:.4f} "
                f"new {s['new cpu'] / n:.4f} ({s['new cpu'] / s['old cpu']:.3f}); outside the method old "
                f"{old_out:.4f} new {new_out:.4f} ({1000 * (new_out - old_out):+.1f} ms, {new_out / old_out:.3f})",
                flush=True,
            )
    for proc in procs.values():
        proc.stdin.close()  # type: ignore[union-attr]
        proc.wait()
    return 0


if __name__ == "__main__":
    sys.exit(main())
