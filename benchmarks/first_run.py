"""What the first run after an install costs more than a warm one: `albot1 run` cold, then warm (issue 24).

Each *pair* is two runs of one command in fresh processes, sharing a private,
empty user cache folder (``XDG_CACHE_HOME``, so the numba kernel cache of
``albot1.methods.albot1.compiled.cache_dir()`` starts empty): the first
compiles every kernel its preset calls, the second loads them. The
matplotlib configuration folder is shared by every run and warmed before the
first pair, so only numba's cache is cold. Reported per run: wall seconds and
the CPU seconds of the process tree (the run and its compile helpers), and
per pair *adds*, cold minus warm. ``--trees`` names source trees (checkouts)
to alternate, pair by pair, so that old and new code meet the same load::

    python benchmarks/first_run.py --presets thesis plus places --rounds 2
    python benchmarks/first_run.py --trees /tmp/old . --presets thesis --rounds 3
    python benchmarks/first_run.py --install-warm-up --presets thesis plus places --rounds 2

``--install-warm-up`` first runs ``albot1 warm-up`` on the empty cache, as
``make venv`` does after installing, and reports its time apart (it is the
install's cost); the first run then follows it.

Presets: ``albot1`` presets on ``synthetic-office-loop``, and ``places``
(``albot1-places`` default on ``synthetic-places-loop``), the commands of
``docs/albot1-mapper.md``, "Compile time". Wall seconds are only meaningful
on an idle machine (the load average is printed with every pair); the CPU
seconds are inflated less by a loaded one.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: how `albot1 run` is started in a fresh interpreter (the console script's own entry point)
ENTRY = "from albot1.cli.app import main; main()"


def command(preset: str, out: Path) -> list[str]:
    """The `albot1 run` arguments of ``preset`` (``places``: the places layer's default)."""
    if preset == "places":
        run = ["albot1-places", "synthetic-places-loop"]
    else:
        run = ["albot1", "synthetic-office-loop", "--preset", preset]
    return [sys.executable, "-c", ENTRY, "run", *run, "--out", str(out)]


def timed(argv: list[str], env: dict[str, str], cwd: Path) -> tuple[float, float]:
    """Wall and CPU seconds (user + system of the child and its children) of one command, which must succeed.

    Run in ``cwd``, a folder without code: ``python -c`` puts its working
    folder first on ``sys.path``, before ``PYTHONPATH``'s tree.
    """
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(
        argv, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=False
    )
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(argv[3:])}: exit {done.returncode}: {done.stderr.strip().splitlines()[-1:]}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def pair(tree: Path, preset: str, mpl: Path, install_warm_up: bool = False) -> str:
    """One cold and one warm run of ``preset`` from source tree ``tree`` on a fresh cache: a line of numbers.

    ``install_warm_up``: ``albot1 warm-up`` first, as ``make venv`` runs it after installing (timed apart).
    """
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="albot1-first-run-") as folder:
        env = {**os.environ, "PYTHONPATH": str(tree), "XDG_CACHE_HOME": str(Path(folder) / "cache")}
        env["MPLCONFIGDIR"] = str(mpl)
        install = timed([sys.executable, "-c", ENTRY, "warm-up"], env, Path(folder)) if install_warm_up else None
        cold = timed(command(preset, Path(folder) / "cold"), env, Path(folder))
        warm = timed(command(preset, Path(folder) / "warm"), env, Path(folder))
    installed = f"install warm-up {install[0]:6.2f} s ({install[1]:5.2f} CPU-s)  " if install else ""
    return (
        f"{tree.name or tree}  {preset:8s} {installed}{'first' if install else 'cold'} "
        f"{cold[0]:6.2f} s ({cold[1]:5.2f} CPU-s)  "
        f"warm {warm[0]:5.2f} s ({warm[1]:4.2f} CPU-s)  "
        f"adds {cold[0] - warm[0]:5.2f} s ({cold[1] - warm[1]:5.2f} CPU-s)  "
        f"load {load:.1f} -> {os.getloadavg()[0]:.1f}"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presets", nargs="+", default=["thesis", "plus"], help="albot1 presets, or places")
    parser.add_argument("--trees", nargs="+", type=Path, default=[Path.cwd()], help="source trees to alternate")
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument(
        "--install-warm-up", action="store_true", help="run `albot1 warm-up` first, as `make venv` does (timed apart)"
    )
    args = parser.parse_args(argv)
    trees = [tree.resolve() for tree in args.trees]
    with tempfile.TemporaryDirectory(prefix="albot1-first-run-mpl-") as mpl:
        env = {**os.environ, "MPLCONFIGDIR": mpl, "PYTHONPATH": str(trees[0])}
        subprocess.run([sys.executable, "-c", "import matplotlib.pyplot"], env=env, cwd=mpl, check=True)  # font cache
        for _ in range(args.rounds):
            for preset in args.presets:
                for tree in trees:
                    print(pair(tree, preset, Path(mpl), args.install_warm_up), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
