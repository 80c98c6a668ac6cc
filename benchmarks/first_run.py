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

``--wheel`` measures a bare wheel install instead of a source tree: for each
tree, a snapshot of what the wheel is made of (as ``.ci/wheel-check`` takes
it) is built with ``pip wheel`` (in pip's isolated build environment, as CI
builds it; ``--no-build-isolation`` builds with this interpreter), its build
time reported, and installed with ``pip install --no-deps`` into a fresh
virtual environment in a temporary folder outside the checkout. The runs
then use that environment's interpreter, with no ``PYTHONPATH``. Its other
dependencies are this interpreter's site-packages, named in a ``.pth`` file
(a folder named there is not scanned for ``.pth`` files, so this
interpreter's editable install of the project is not seen);
``--wheel-deps install`` installs them from the index instead, as CI does
(minutes). ``--plain-wheel`` also builds each tree's wheel without its
compiled kernels (``ALBOT1_BUILD_KERNELS=0``: what a wheel was before they
were bundled) and alternates the two, pair by pair::

    python benchmarks/first_run.py --wheel --plain-wheel --presets plus places thesis --rounds 2

Presets: ``albot1`` presets on ``synthetic-office-loop``, and ``places``
(``albot1-places`` default on ``synthetic-places-loop``), the commands of
``docs/albot1-mapper.md``, "Compile time", and ``gtsam-graph`` (its default
on ``synthetic-office-loop``; its grid search's kernels). Wall seconds are only meaningful
on an idle machine (the load average is printed with every pair); the CPU
seconds are inflated less by a loaded one.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import resource
import shutil
import site
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

#: how `albot1 run` is started in a fresh interpreter (the console script's own entry point)
ENTRY = "from albot1.cli.app import main; main()"


#: what a wheel is built from: the files ``.ci/wheel-check`` copies out of the checkout
WHEEL_SOURCES = (
    "pyproject.toml",
    "setup.py",
    "MANIFEST.in",
    "README.md",
    "albot1",
    "datasets",
    "baselines",
    "benchmarks",
)


@dataclass(frozen=True)
class Install:
    """Where the runs come from: an interpreter and the source tree on its ``PYTHONPATH`` (None: its own install)."""

    label: str
    python: str
    tree: Path | None


def command(install: Install, preset: str, out: Path) -> list[str]:
    """The `albot1 run` arguments of ``preset`` (``places``, ``gtsam-graph``: that method's default)."""
    if preset == "places":
        run = ["albot1-places", "synthetic-places-loop"]
    elif preset == "gtsam-graph":
        run = ["gtsam-graph", "synthetic-office-loop"]
    else:
        run = ["albot1", "synthetic-office-loop", "--preset", preset]
    return [install.python, "-c", ENTRY, "run", *run, "--out", str(out)]


def _checked(argv: list[str], env: dict[str, str] | None = None) -> None:
    done = subprocess.run(argv, env=env, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(argv)}: exit {done.returncode}: {done.stderr.strip().splitlines()[-3:]}")


def wheel_install(tree: Path, folder: Path, kernels: bool, isolated: bool, deps: str) -> Install:
    """Build ``tree``'s wheel from a snapshot and install it into a fresh venv in ``folder``; build time printed."""
    source = folder / "src"
    source.mkdir(parents=True)
    for name in WHEEL_SOURCES:
        copy = shutil.copytree if (tree / name).is_dir() else shutil.copy2
        copy(tree / name, source / name)
    for cache in list(source.rglob("__pycache__")):
        shutil.rmtree(cache)
    shutil.rmtree(source / "albot1" / "_bundled", ignore_errors=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["ALBOT1_BUILD_KERNELS"] = "1" if kernels else "0"
    isolation = [] if isolated else ["--no-build-isolation"]
    start, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    _checked(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", *isolation, "-w", str(folder / "dist"), str(source)],
        env,
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    wheel = next((folder / "dist").glob("*.whl"))
    label = f"{tree.name}-wheel" + ("" if kernels else "-plain")
    size, wall = wheel.stat().st_size / 1e6, time.perf_counter() - start
    print(f"{label}: built {wheel.name} ({size:.2f} MB) in {wall:.1f} s ({cpu:.1f} CPU-s)", flush=True)
    _checked([sys.executable, "-m", "venv", str(folder / "venv")])
    python = str(folder / "venv" / "bin" / "python")
    if deps == "borrow":
        purelib = subprocess.run(
            [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        Path(purelib, "albot1-first-run-deps.pth").write_text(
            "\n".join(site.getsitepackages()) + "\n", encoding="utf-8"
        )
    _checked([python, "-m", "pip", "install", "-q", *(["--no-deps"] if deps == "borrow" else []), str(wheel)], env)
    return Install(label, python, None)


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


def pair(source: Install, preset: str, mpl: Path, install_warm_up: bool = False) -> str:
    """One cold and one warm run of ``preset`` from ``source`` on a fresh cache: a line of numbers.

    ``install_warm_up``: ``albot1 warm-up`` first, as ``make venv`` runs it after installing (timed apart).
    """
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="albot1-first-run-") as folder:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        if source.tree is not None:
            env["PYTHONPATH"] = str(source.tree)
        env["XDG_CACHE_HOME"] = str(Path(folder) / "cache")
        env["MPLCONFIGDIR"] = str(mpl)
        install = timed([source.python, "-c", ENTRY, "warm-up"], env, Path(folder)) if install_warm_up else None
        cold = timed(command(source, preset, Path(folder) / "cold"), env, Path(folder))
        warm = timed(command(source, preset, Path(folder) / "warm"), env, Path(folder))
    installed = f"install warm-up {install[0]:6.2f} s ({install[1]:5.2f} CPU-s)  " if install else ""
    return (
        f"{source.label}  {preset:8s} {installed}{'first' if install else 'cold'} "
        f"{cold[0]:6.2f} s ({cold[1]:5.2f} CPU-s)  "
        f"warm {warm[0]:5.2f} s ({warm[1]:4.2f} CPU-s)  "
        f"adds {cold[0] - warm[0]:5.2f} s ({cold[1] - warm[1]:5.2f} CPU-s)  "
        f"load {load:.1f} -> {os.getloadavg()[0]:.1f}"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presets", nargs="+", default=["thesis", "plus"], help="albot1 presets, places, gtsam-graph")
    parser.add_argument("--trees", nargs="+", type=Path, default=[Path.cwd()], help="source trees to alternate")
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument(
        "--install-warm-up", action="store_true", help="run `albot1 warm-up` first, as `make venv` does (timed apart)"
    )
    parser.add_argument("--wheel", action="store_true", help="build each tree's wheel, install it in a fresh venv")
    parser.add_argument("--plain-wheel", action="store_true", help="with --wheel: also a wheel without its kernels")
    parser.add_argument("--no-build-isolation", action="store_true", help="with --wheel: build with this interpreter")
    parser.add_argument("--wheel-deps", choices=["borrow", "install"], default="borrow", help="with --wheel")
    args = parser.parse_args(argv)
    trees = [tree.resolve() for tree in args.trees]
    with contextlib.ExitStack() as stack:
        mpl = stack.enter_context(tempfile.TemporaryDirectory(prefix="albot1-first-run-mpl-"))
        env = {**os.environ, "MPLCONFIGDIR": mpl, "PYTHONPATH": str(trees[0])}
        subprocess.run([sys.executable, "-c", "import matplotlib.pyplot"], env=env, cwd=mpl, check=True)  # font cache
        sources = list(_sources(stack, trees, args))
        for _ in range(args.rounds):
            for preset in args.presets:
                for source in sources:
                    print(pair(source, preset, Path(mpl), args.install_warm_up), flush=True)
    return 0


def _sources(stack: contextlib.ExitStack, trees: list[Path], args: argparse.Namespace) -> Iterator[Install]:
    """The installs measured: each tree on ``PYTHONPATH``, or (``--wheel``) each tree's wheel(s) in a fresh venv."""
    for tree in trees:
        if not args.wheel:
            yield Install(tree.name or str(tree), sys.executable, tree)
            continue
        for kernels in (True, False) if args.plain_wheel else (True,):
            folder = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="albot1-first-run-wheel-")))
            yield wheel_install(tree, folder, kernels, not args.no_build_isolation, args.wheel_deps)


if __name__ == "__main__":
    raise SystemExit(main())
