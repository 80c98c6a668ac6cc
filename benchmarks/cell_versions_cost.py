"""CPU a forked bench cell spends on the versions its run records (issue 24, session 11).

``albot1.runs.execute.run_method`` records ``versions.git_commit()`` and
``versions.library_versions()`` in every run. This script imports
:mod:`albot1.bench.preload` as the bench's forkserver does (no method preloaded:
``ALBOT1_PRELOAD_METHODS`` empty), forks N cells one after the other, and in each
times those two calls: CPU of the cell and of its children (the ``git``
commands), and wall. Run it with each checkout on ``PYTHONPATH``, alternating::

    PYTHONPATH=<checkout> python benchmarks/cell_versions_cost.py 40 LABEL

A checkout outside git (``git archive``) asks no git: compare git checkouts.
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time


def _one_cell() -> tuple[float, float]:
    """In a fork: (CPU s of this process and its children, wall s) of the two lookups."""
    from albot1 import versions

    cpu0 = time.process_time()
    children0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall0 = time.perf_counter()
    versions.git_commit()
    versions.library_versions()
    children1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    children = (children1.ru_utime - children0.ru_utime) + (children1.ru_stime - children0.ru_stime)
    return time.process_time() - cpu0 + children, time.perf_counter() - wall0


def main(cells: int, label: str) -> None:
    os.environ["ALBOT1_PRELOAD_METHODS"] = ""
    import albot1.bench.preload  # noqa: F401 -- what the forkserver imports before it forks a cell

    cpu = wall = 0.0
    for _ in range(cells):
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(read)
            os.write(write, json.dumps(_one_cell()).encode())
            os._exit(0)
        os.close(write)
        data = b""
        while chunk := os.read(read, 4096):
            data += chunk
        os.close(read)
        os.waitpid(pid, 0)
        cell_cpu, cell_wall = json.loads(data)
        cpu += cell_cpu
        wall += cell_wall
    print(f"{label}: per cell {1000 * cpu / cells:.1f} ms CPU, {1000 * wall / cells:.1f} ms wall ({cells} cells)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 40, sys.argv[2] if len(sys.argv) > 2 else "this checkout")
