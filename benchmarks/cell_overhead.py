"""A bench cell's work outside its method, old code against new, alternating in one process (issue 24).

Runs the cells of a stored grid (their ``cell.json``: every Nth, or those
whose method is named) once each in this process, after the cell
forkserver's imports and warm-ups (:mod:`albot1.bench.preload`), keeps their
results, then times the phases a cell pays after its method, the old and the
new implementation of each alternating round by round on the same results::

    python benchmarks/cell_overhead.py results/default --every 12 --rounds 3
    python benchmarks/cell_overhead.py results/default --old-tree /path/to/base/checkout

``--old-tree``: a checkout of the code before the change; its
``albot1/runs/map_files.py`` and ``albot1/report/tight_png.py`` are loaded
under other names and are the "old" side (the preview's drawing code is the
same module; only its PNG writing is swapped). It prints each phase's
seconds summed over the cells for both sides, their ratio, and whether the
map files are byte-identical and the previews' decoded pixels equal. On a
shared machine only the ratios of one run are meaningful.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import tempfile
import time
from pathlib import Path
from types import ModuleType
from typing import Any


def _load(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("store", type=Path, help="a results folder of albot1 bench (its runs/*/cell.json)")
    parser.add_argument("--old-tree", type=Path, required=True, help="checkout of the code before the change")
    parser.add_argument("--every", type=int, default=10, help="take every Nth cell of the store, by key")
    parser.add_argument("--methods", default="", help="comma-separated: only these methods")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)

    import numpy as np
    from PIL import Image

    import albot1.bench.preload  # noqa: F401 -- the forkserver's state: imports, kernels, fonts
    from albot1.bench.grid import Cell
    from albot1.data.open import open_sequence
    from albot1.report import preview
    from albot1.runs import map_files
    from albot1.runs.evaluate import evaluate_run
    from albot1.runs.execute import run_method
    from albot1.runs.folder import write_run

    old_maps = _load(args.old_tree / "albot1/runs/map_files.py", "old_map_files")
    old_png = _load(args.old_tree / "albot1/report/tight_png.py", "old_tight_png")
    methods = {m for m in args.methods.split(",") if m}
    paths = sorted(args.store.glob("runs/*/cell.json"))[:: args.every]
    results: list[Any] = []
    for path in paths:
        cell = Cell.from_json(json.loads(path.read_text()))
        if cell.trajectory is not None or (methods and cell.method not in methods):
            continue
        try:
            sequence = open_sequence(cell.dataset_label)
            results.append(
                run_method(
                    cell.method,
                    sequence,
                    preset=cell.preset,
                    overrides=dict(cell.overrides),
                    degradation=cell.degradation,
                    seed=cell.seed,
                    dataset_name=cell.dataset_label,
                )
            )
        except Exception as exc:  # noqa: BLE001 -- a cell the grid records as failed has nothing after its method
            print(f"skipped {cell.describe()}: {type(exc).__name__}", file=sys.stderr)
    print(f"{len(results)} cells: " + ", ".join(sorted({r.method for r in results})))

    totals: dict[str, float] = {}
    same_maps = same_pixels = True
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        for rnd in range(args.rounds):
            for side in ("old", "new") if rnd % 2 == 0 else ("new", "old"):
                for i, result in enumerate(results):
                    folder = root / side / str(i)
                    folder.mkdir(parents=True, exist_ok=True)
                    writer = old_maps.write_map if side == "old" else map_files.write_map
                    start = time.perf_counter()
                    writer(folder, result.map)
                    totals[f"map {side}"] = totals.get(f"map {side}", 0.0) + time.perf_counter() - start
                    saver = old_png.save_tight_png if side == "old" else preview.save_tight_png
                    original = preview.save_tight_png
                    preview.save_tight_png = saver  # the same drawing, the PNG step of one side
                    try:
                        start = time.perf_counter()
                        preview.render_preview(result, folder / "preview.png")
                        totals[f"preview {side}"] = totals.get(f"preview {side}", 0.0) + time.perf_counter() - start
                    finally:
                        preview.save_tight_png = original
            for i in range(len(results)):
                old, new = root / "old" / str(i), root / "new" / str(i)
                same_maps &= (old / "map.geojson").read_bytes() == (new / "map.geojson").read_bytes()
                with Image.open(old / "preview.png") as a, Image.open(new / "preview.png") as b:
                    same_pixels &= np.array_equal(np.asarray(a), np.asarray(b))
        for result in results:  # the rest of a cell, for its share (same code on both sides)
            run_dir = write_run(result, root / "runs")
            start = time.perf_counter()
            evaluate_run(run_dir)
            totals["evaluate"] = totals.get("evaluate", 0.0) + time.perf_counter() - start
    for phase in ("map", "preview"):
        old, new = totals[f"{phase} old"], totals[f"{phase} new"]
        print(f"{phase:8s} old {old / args.rounds:7.2f} s  new {new / args.rounds:7.2f} s  new/old {new / old:.2f}")
    print(f"evaluate {totals.get('evaluate', 0.0):7.2f} s (once, unchanged)")
    print(f"map.geojson byte-identical: {same_maps}; preview pixels identical: {same_pixels}")
    return 0 if same_maps and same_pixels else 1


if __name__ == "__main__":
    sys.exit(main())
