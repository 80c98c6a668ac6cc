"""Imported once by the cell forkserver so that every forked cell starts warm.

Each import is attempted separately, so one broken import does not stop
every cell: the same import fails again inside the cell that needs it,
where it is recorded as that cell's failure. A failure here is never
swallowed: each is reported once, as one warning line on the runner's
stderr naming the module and the error (:func:`warm` returns them).

What is imported by name: the modules below (the bench's own layer and the
layers under it; ``tests/unit/bench/test_bench_imports_by_name.py`` checks
them against the layer contract), the loader of every registered data
format and the mapper class of every available registered method, or of
only those named by ``ALBOT1_PRELOAD_METHODS`` (comma-separated; the runner
names its grid's methods there when it starts the server, so a grid of one
cheap method does not pay for importing and warming up the others; a cell
of a method left out imports and warms it up itself).
"""

from __future__ import annotations

import signal

# Ctrl-C reaches the whole process group, this server too, and its preload (a cold numba compile takes tens of
# seconds) is what it interrupts. Python's KeyboardInterrupt escaped ``multiprocessing.forkserver.main``, which
# catches only ImportError, and printed a traceback above the runner's clean "interrupted" line; an exception
# raised by a handler of our own could land in a finalizer and print "Exception ignored in: ...". So while it
# preloads, the server takes SIGINT's default action: it ends at once and says nothing (the runner says what
# happened, and its compile helpers end the same way, :func:`albot1.methods.albot1.warm_up.helper_main`).
# Put back at the end (:func:`_preloaded`): the server hands its SIGINT handler to every cell it forks, which
# records Ctrl-C as "interrupted". First thing, before the module's other imports (in which a Ctrl-C still printed
# the traceback; docs/benchmarking.md, "The runner").
_SIGINT_BEFORE = signal.signal(signal.SIGINT, signal.SIG_DFL)
# The runner started this server with SIGINT blocked (albot1.bench.limits._sigint_held): a Ctrl-C in the server's
# own start waited for this line, and now ends it as it would during the preload.
signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})

import contextlib  # noqa: E402
import functools  # noqa: E402
import gc  # noqa: E402
import importlib  # noqa: E402
import logging  # noqa: E402
import os  # noqa: E402
import sys  # noqa: E402
from collections.abc import Callable, Collection, Iterable  # noqa: E402
from typing import TYPE_CHECKING  # noqa: E402

from albot1 import versions  # noqa: E402

if TYPE_CHECKING:
    from albot1.methods.registry import MethodRegistry, MethodSpec


# First, before the slow imports: every cell forked from this server shares this value, so the cells of
# one grid agree on the code version the runner planned with (see albot1.bench.cells).
versions.code_version()
# The commit every run records (albot1.runs.execute), once here instead of once per cell: two `git` commands
# (describe, status of the code paths; ~20 ms of CPU and a process start each cell). Read here, like the code
# version, it is the value of the code the cells run. The library versions are read after the imports (_warm).
versions.git_commit()

import matplotlib  # noqa: E402

from albot1.bench.limits import METHODS_ENV  # noqa: E402

_log = logging.getLogger(__name__)

matplotlib.use("Agg")

#: The modules every cell uses, imported by name (see the module docstring).
MODULES = (
    "numpy",
    "scipy.spatial",
    "shapely",
    "matplotlib.pyplot",
    "pydantic",
    "albot1.bench.cells",
    "albot1.bench.cell_main",
    "albot1.runs.execute",
    "albot1.runs.folder",
    "albot1.data.open",
    "albot1.data.catalog",
    "albot1.data.loaders.registry",
    "albot1.data.synthetic.worlds",
    "albot1.runs.evaluate",
    "albot1.metrics.ate",
    "albot1.metrics.rpe",
    "albot1.metrics.loop_gap",
    "albot1.metrics.orientation",
    "albot1.metrics.relations",
    "albot1.metrics.map_shape",
    "albot1.metrics.updates",
    "albot1.metrics.cost",
    # Imported by every cell on first use, not by the modules above (issue 24, docs/benchmarking.md, "Session 22"):
    # each import costs a forked cell 2-9 ms of CPU, again in every cell, where here it is paid once.
    "platformdirs",  # albot1.settings: the decoded-log and reference-map caches' folder
    "shapely.ops",  # the synthetic worlds' free space (albot1.data.synthetic.floorplan)
    "encodings.cp437",  # zipfile reads the member names of every .npz (decoded logs, reference maps) with it
    "encodings.utf_8_sig",  # albot1.data.text: every text file is read with a byte-order mark dropped
)


def _attempt(what: str, load: Callable[[], object], failures: list[str]) -> None:
    try:
        load()
    except Exception as exc:  # noqa: BLE001 -- reported once here, recorded again by the cell that needs it
        failures.append(f"{what}: {type(exc).__name__}: {exc}")


def warm(modules: Iterable[str] = MODULES, methods: Collection[str] | None = None) -> list[str]:
    """Import ``modules``, each data format's loader and each available method's class; the failures, one per line.

    ``methods``: only these registered methods (None: all of them).
    """
    from albot1.config.targets import resolve_target
    from albot1.data.catalog import warm_manifests
    from albot1.data.loaders.registry import FORMATS
    from albot1.methods.registry import method_registry
    from albot1.methods.warm_ups import warm_up_methods

    failures: list[str] = []
    for name in modules:
        _attempt(f"module {name}", functools.partial(importlib.import_module, name), failures)
    for loader_target, _ in FORMATS.values():
        _attempt(f"loader {loader_target}", functools.partial(resolve_target, loader_target), failures)
    # The dataset manifests, parsed here once instead of in every cell that opens a public log (~12-20 ms each,
    # docs/benchmarking.md, "Session 24"); each cell still lists them, and says in its cell.log which are a user's.
    _attempt("dataset manifests", warm_manifests, failures)
    registry: MethodRegistry | None = None
    try:
        registry = method_registry()
    except Exception as exc:  # noqa: BLE001 -- an installed plugin declares a bad entry point
        failures.append(f"method registry: {type(exc).__name__}: {exc}")
    if methods is not None and registry is not None:
        _say_unknown(methods, [spec.name for spec in registry])
    warmed: list[str] = []
    for spec in registry or ():
        if (methods is None or spec.name in methods) and spec.available():
            _attempt(f"method {spec.name} ({spec.target})", functools.partial(_load_method, spec), failures)
            warmed.append(spec.name)
    # The versions of the libraries just imported, read here, right after the imports, for every cell (a search of
    # the installed metadata, ~2 ms per library) and kept while this server lives: they name the modules its cells
    # run even if another version is installed meanwhile. A library no preloaded method imports is read again by
    # the cell that imports it (albot1.versions.library_versions).
    versions.library_versions()
    # Every preset's warm-up, once, here, before any fork: every cell forked from this server then starts with the
    # kernels in memory, so a cell's start-up is not paid once per cell (1.3-1.9 s for Albot1 with numba's cache
    # filled).
    failures.extend(warm_up_methods(warmed, registry).lines())
    return failures


def _load_method(spec: MethodSpec) -> None:
    """Import ``spec``'s mapper class and the library modules it names in ``preload_modules`` (``Mapper``)."""
    for name in getattr(spec.load_class(), "preload_modules", ()):
        importlib.import_module(name)


def _say_unknown(methods: Collection[str], registered: list[str]) -> None:
    """Warn about names in ``ALBOT1_PRELOAD_METHODS`` that no registered method has (a user's typo).

    Why: such a name preloads nothing, without a word, and every cell of the
    method meant then pays its own imports and warm-up (39 s instead of 2 s
    for an Albot1 cell with a cold numba cache); the results are the same.
    """
    unknown = sorted(set(methods) - set(registered))
    if unknown:
        _log.warning(
            "albot1 bench: %s names no registered method: %s (nothing preloaded for it); expected names from: %s",
            METHODS_ENV,
            ", ".join(repr(name) for name in unknown),
            ", ".join(registered),
        )


def methods_to_preload() -> frozenset[str] | None:
    """The method names in ``ALBOT1_PRELOAD_METHODS`` (None when it is unset: every method)."""
    value = os.environ.get(METHODS_ENV)
    if value is None:
        return None
    return frozenset(name.strip() for name in value.split(",") if name.strip())


def _warm() -> None:
    # The server shares the runner's stdout, which carries the runner's tables: what a module prints as it is
    # imported here (a plugin's banner) goes to stderr, beside the runner's other lines.
    with contextlib.redirect_stdout(sys.stderr):
        failures = warm(methods=methods_to_preload())
    for failure in failures:
        _log.warning("albot1 bench: preloading %s (each cell that needs it will fail with this reason)", failure)
    _warm_matplotlib()


def collect_garbage() -> None:
    """Free the garbage the imports and warm-ups left, once, here, before any cell is forked.

    Why: a cell is a fork of this server and inherits its heap and its cycle
    collector's state. The joint warm-up leaves about 49,000 unreachable
    objects and a full collection due (generation 2's count at its
    threshold), so each cell's first full collection, set off by whatever
    allocated next (the places layer's network files at the end of a run,
    issue 24), walked the whole inherited heap of some 330,000 objects,
    touching, and so copying, every page of it: 0.2 s of the cell's timed
    wall on an idle machine, over a second on a loaded one. Collected here,
    a cell starts with nothing due; the cell then freezes the inherited heap
    (:func:`albot1.bench.cell_main.freeze_inherited_heap`), so no later
    collection walks it either.
    """
    gc.collect()


def _warm_matplotlib() -> None:
    """Render one tiny figure so the font cache and the Agg renderer are set up before forking."""
    import io

    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(1, 1))
    ax.plot([0, 1], [0, 1], label="x")
    ax.legend()
    fig.savefig(io.BytesIO(), format="png", bbox_inches="tight")
    plt.close(fig)


def _preloaded() -> None:
    """Give SIGINT back the handler it had before the preload (Python's KeyboardInterrupt), for the cells."""
    signal.signal(signal.SIGINT, signal.default_int_handler if _SIGINT_BEFORE is None else _SIGINT_BEFORE)


_warm()
collect_garbage()  # every cell forked from here starts with no garbage and no collection due
_preloaded()  # last: a cell interrupted by Ctrl-C raises KeyboardInterrupt, as anywhere else
