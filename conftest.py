"""Fixtures shared by tests/ and benchmarks/: where the public datasets are, and skips when they are not.

Integration tests take the dataset folder from ``ALBOT1_DATA_DIR`` (set by
the Makefile and .ci/run when the shared copies exist) and skip with a reason
naming the missing file otherwise.

The SLAM-corrected logs are taken from the catalog (:func:`corrected_names`),
never listed by hand, so a test over "every corrected log" covers a manifest
as soon as it is added; ``tests/unit/data/test_catalog_manifests.py`` checks
the derived list against the manifests folder and the datasets README.
"""

from __future__ import annotations

import functools
import gc
import importlib
import json
import math
import os
import shutil
import signal
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from hypothesis import settings

from albot1.data import catalog
from albot1.methods.plugins import ENTRY_POINT_GROUP
from albot1.methods.registry import method_registry

# The plotting backend without importing matplotlib here (half a second of every collection): it reads this
# variable when a test first imports it, and the CLI and cell processes the tests start inherit it.
os.environ.setdefault("MPLBACKEND", "Agg")

#: What marks a SLAM-corrected log in the catalog: its name is ``<site>-corrected`` (datasets/README.md).
CORRECTED_SUFFIX = "-corrected"


def corrected_names() -> list[str]:
    """The registered SLAM-corrected logs (``acapulco-corrected``, ...), sorted."""
    return [name for name in catalog.names() if name.endswith(CORRECTED_SUFFIX)]


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """A test that takes ``corrected_name`` runs once for each corrected log of the catalog."""
    if "corrected_name" in metafunc.fixturenames:
        metafunc.parametrize("corrected_name", corrected_names())


@pytest.fixture(scope="session")
def corrected_logs() -> list[str]:
    """Every corrected log of the catalog at once (:func:`corrected_names`)."""
    return corrected_names()


def _data_dir() -> Path | None:
    value = os.environ.get("ALBOT1_DATA_DIR")
    return Path(value) if value else None


@pytest.fixture(scope="session")
def data_file() -> Callable[[str], Path]:
    """``data_file("radish/aces.clf.bz2")`` -> the path, or skip the test with the reason."""

    def find(relative: str) -> Path:
        root = _data_dir()
        if root is None:
            pytest.skip(f"ALBOT1_DATA_DIR is not set; integration data {relative} unavailable")
        path = root / relative
        if not path.exists():
            pytest.skip(f"{path} is absent (set ALBOT1_DATA_DIR to the public dataset copies)")
        return path

    return find


#: Installs a distribution declaring ``{method name: "module:Class"}`` under the entry point group albot1.methods.
PluginInstaller = Callable[[dict[str, str]], Path]


@pytest.fixture
def own_project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A user's own config folder (``ALBOT1_CONFIG_DIR``, its ``datasets/`` made) and checksum cache.

    Manifests are read once per process (``catalog._manifests``): the cache is cleared on the way in and out, so
    no test sees another's datasets. (Here, not in a conftest.py of a test folder: a second module named
    ``conftest`` would shadow this one for the tests that import helpers from it.)
    """
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "checksum-cache"))
    (tmp_path / "project" / "datasets").mkdir(parents=True)
    monkeypatch.setenv("ALBOT1_CONFIG_DIR", str(tmp_path / "project"))
    catalog._manifests.cache_clear()
    yield tmp_path / "project"
    catalog._manifests.cache_clear()


@pytest.fixture
def install_method_plugin(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[PluginInstaller]:
    """Install a real plugin distribution (a ``*.dist-info`` with ``entry_points.txt``) for one test.

    The folder goes first on ``sys.path`` (and ``PYTHONPATH``, for the CLI and
    cell processes), exactly where an installed distribution's metadata is
    found by :mod:`importlib.metadata`; the process's method registry is
    built again from it, and again after the test without it.
    """

    def install(methods: dict[str, str]) -> Path:
        site = tmp_path / "plugin-site"
        info = site / "albot1_test_plugin-0.1.dist-info"
        info.mkdir(parents=True, exist_ok=True)
        (info / "METADATA").write_text("Metadata-Version: 2.1\nName: albot1-test-plugin\nVersion: 0.1\n")
        lines = "".join(f"{name} = {target}\n" for name, target in methods.items())
        (info / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\n{lines}")
        monkeypatch.syspath_prepend(str(site))
        monkeypatch.setenv("PYTHONPATH", os.pathsep.join(p for p in (str(site), os.environ.get("PYTHONPATH")) if p))
        importlib.invalidate_caches()
        method_registry.cache_clear()
        return site

    yield install
    method_registry.cache_clear()


@pytest.fixture
def fault_plugin(install_method_plugin: PluginInstaller) -> None:
    """The failure-injecting test mapper installed as the plugin method ``fault`` (tests/integration)."""
    install_method_plugin({"fault": "bench_fault_mappers:FaultMapper"})


def write_complete_run(run_dir: Path, key: str) -> None:
    """Make ``run_dir`` a complete run folder of cell ``key`` as the bench reads it: DONE, metrics.json, result.json.

    The smallest files that pass the store's completeness check
    (``ResultsStore.is_complete``: a ``result.json`` of that very key), for
    tests of the runner's bookkeeping that run no method.
    """
    result = {
        "key": key,
        "method": "odometry",
        "dataset": "w",
        "preset": "default",
        "degradation": "none",
        "seed": 0,
        "scans": 1,
        "config": {},
        "versions": {"code": "v"},
        "dataset_info": {"source": "w", "format": "synthetic", "odometry_source": "", "reference_source": ""},
        "counters": {"views": 1, "updates": 1},
        "timing": {
            **dict.fromkeys(("per_scan_ms_median", "per_scan_ms_p95", "per_scan_ms_mean")),
            **dict.fromkeys(("finish_s", "total_s", "wall_s", "peak_mb"), 0.0),
        },
        "map_file": "map.npz",
        "has_reference": False,
        "relations": 0,
    }
    run_dir.mkdir(parents=True, exist_ok=True)
    (run_dir / "result.json").write_text(json.dumps(result))
    (run_dir / "metrics.json").write_text("{}")
    (run_dir / "DONE").write_text(f"{key}\n")


# -- collection without the cyclic garbage collector ---------------------------------------------------------


@pytest.hookimpl(wrapper=True)
def pytest_collection(session: pytest.Session) -> Iterator[None]:
    """Collect with the cyclic garbage collector paused; it is back in its former state before the first test.

    Collecting imports about 1,600 modules and rewrites the assertions of every test file. Almost all the
    objects this makes (modules, classes, functions, parametrisations) live until the session ends, yet
    each full pass of the collector walks them all again, and as the heap grows the passes come more often
    and cost more: 19 full passes, 1.3-1.4 of a cold collection's 5.8 CPU-s, for next to nothing freed
    (peak memory 168 MB with them, 172 MB without; docs/benchmarking.md). Reference counting still frees
    everything that is not in a cycle; the cycles left are collected by the first pass after collection.
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        return (yield)
    finally:
        if enabled:
            gc.enable()


# -- the order tests run in, so that the long ones start first ------------------------------------------------

#: Measured seconds of the tests that take over a second (``pytest --record-durations=tests/durations.json``);
#: only the order of the values matters (they come from whatever machine measured them).
DURATIONS_FILE = Path(__file__).parent / "tests" / "durations.json"
#: The estimate of a test marked ``slow`` that the file does not list (new or renamed since it was measured).
SLOW_DEFAULT_S = 2.0
#: Tests under this many seconds are left out of the file (a unit of them costs about nothing).
RECORD_MIN_S = 1.0


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--record-durations",
        metavar="PATH",
        help=f"write the seconds of every test over {RECORD_MIN_S:g} s (setup + call + teardown) to PATH as JSON "
        "(tests/durations.json orders `make test`: longest first)",
    )


@dataclass(frozen=True)
class Unit:
    """The tests of one module: xdist's ``loadscope`` gives a module to one worker whole (fixtures built once)."""

    name: str
    nodeids: tuple[str, ...]
    seconds: float


def schedule_units(
    tests: list[tuple[str, str, bool, bool]], durations: dict[str, float], slow_default_s: float = SLOW_DEFAULT_S
) -> list[Unit]:
    """The modules of ``tests`` (nodeid, module, marked slow, shares state), the longest first.

    The estimate of a test is its ``durations`` entry (``slow_default_s``
    for a slow test not listed, 0 otherwise), that of a module the sum; ties
    keep the collection order. Within a module the longest test goes first,
    because xdist hands a worker its next module when the current one has
    two tests left: a long test left at the end would hold that next module
    up behind it while the other worker runs out of work. A module whose
    tests share state (a module- or class-scoped fixture: part 2 of a worked
    example continuing part 1's folder) keeps its collection order.
    """
    grouped: dict[str, list[tuple[str, float]]] = {}
    ordered: set[str] = set()
    for nodeid, module, slow, shares in tests:
        grouped.setdefault(module, []).append((nodeid, durations.get(nodeid, slow_default_s if slow else 0.0)))
        if shares:
            ordered.add(module)
    units = [
        Unit(
            name,
            tuple(n for n, _ in (group if name in ordered else sorted(group, key=lambda test: -test[1]))),
            math.fsum(s for _, s in group),  # exactly rounded: the same whatever the order (a test re-derives it)
        )
        for name, group in grouped.items()
    ]
    return sorted(units, key=lambda unit: -unit.seconds)


# -- the edit-test loop (`make test-fast`): chosen by measured cost, property tests with fewer examples ----------

#: A test that tests/durations.json lists at this many seconds or more is marked ``slow``, so ``make test-fast``
#: (``-m "not slow ..."``) leaves it to ``make test``. The file holds every test that took ``RECORD_MIN_S`` or more
#: in a recorded run, so the bound is that: a test it does not list (quicker, or new since the file was
#: recorded) stays in the lane until a refreshed file lists it. Measured: docs/benchmarking.md, "Session 23, test-fast".
FAST_MAX_S = RECORD_MIN_S
#: The hypothesis profile ``make test-fast`` loads (``--hypothesis-profile=fast``): every property test runs, each
#: with at most this many examples (its own ``@settings(max_examples=...)`` is capped, since a decorator's value
#: wins over any profile's). ``make test`` and CI run the default profile: every test's own count.
FAST_PROFILE = "fast"
FAST_MAX_EXAMPLES = 10
settings.register_profile(FAST_PROFILE, max_examples=FAST_MAX_EXAMPLES)


@pytest.hookimpl(tryfirst=True)
def pytest_itemcollected(item: pytest.Item) -> None:
    """Markers from what a test reads and what it costs, before ``-m`` selects; fewer examples in the fast profile.

    A test that takes ``data_file`` reads the public logs: it is marked ``integration`` like the tests there
    (``make test-fast`` promises "without the public logs" by deselecting that marker, but a unit test that asked
    for a public log through the fixture was kept unless its module said so). A test the durations file lists at
    ``FAST_MAX_S`` or more is marked ``slow`` (:data:`FAST_MAX_S`): the lane is chosen by measured cost, not by
    hand-set marks alone, so a test that grew slow leaves it at the next refresh of the file. Under the ``fast``
    hypothesis profile a property test is kept whatever its recorded seconds (they were for its own example count)
    and runs at most ``FAST_MAX_EXAMPLES`` examples.
    """
    if "data_file" in getattr(item, "fixturenames", ()):
        item.add_marker(pytest.mark.integration)
    test = _hypothesis_test(item)
    if test is not None and settings.get_current_profile_name() == FAST_PROFILE:
        _cap_examples(test, FAST_MAX_EXAMPLES)  # its recorded seconds were for its own count: not this lane's cost
    elif _durations().get(item.nodeid, 0.0) >= FAST_MAX_S:
        item.add_marker(pytest.mark.slow)


def _hypothesis_test(item: pytest.Item) -> Any:
    """The function hypothesis's ``@given`` made of ``item``'s test (a method's function), or None."""
    test = getattr(item, "obj", None)
    test = getattr(test, "__func__", test)  # a method's function: the settings live on it
    return test if getattr(test, "is_hypothesis_test", False) else None


def _cap_examples(test: Any, most: int) -> None:
    """Run a ``@given`` test with at most ``most`` examples: the settings it reads each time it is called."""
    own = getattr(test, "_hypothesis_internal_use_settings", None)
    if isinstance(own, settings) and own.max_examples > most:
        test._hypothesis_internal_use_settings = settings(own, max_examples=most)


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Run the longest modules first, each kept together.

    ``make test`` hands its workers one module at a time in this order
    (``--dist loadscope --no-loadscope-reorder``), so the module of a
    whole-log test of a minute or two starts at the beginning, beside the
    other long ones, instead of starting last and keeping the other workers
    idle until it ends; the short modules fill the gaps at the end. A module
    goes to one worker whole, so its module-scoped fixtures (a report built
    once for several tests) are built once. It runs after the other plugins'
    hooks (``trylast``), so it orders what a ``-m``/``-k`` selection kept
    (``make test-fast``): ordered before the selection, the kept tests were in
    an order of the whole suite's module sums, not of their own.
    """
    durations = _durations()
    modules = [_module(item) or item.nodeid for item in items]
    sharing = {module for module, item in zip(modules, items) if _shares_state(item)}
    tests = [
        (item.nodeid, module, item.get_closest_marker("slow") is not None, module in sharing)
        for module, item in zip(modules, items)
    ]
    by_id = {item.nodeid: item for item in items}
    items[:] = [by_id[nodeid] for unit in schedule_units(tests, durations) for nodeid in unit.nodeids]


def _shares_state(item: pytest.Item) -> bool:
    """Whether ``item`` uses a module- or class-scoped fixture (pytest's own record of the fixtures it uses)."""
    info = getattr(item, "_fixtureinfo", None)
    definitions = getattr(info, "name2fixturedefs", {}) or {}
    return any(d.scope in ("module", "class") for defs in definitions.values() for d in defs)


@functools.cache
def _durations() -> dict[str, float]:
    """The durations file's seconds by node id, read once per process (every collected test looks itself up)."""
    try:
        values = json.loads(DURATIONS_FILE.read_text())
    except (OSError, ValueError):
        return {}  # no file (or a broken one): slow tests first by the marker alone
    return (
        {str(k): float(v) for k, v in values.items() if isinstance(v, int | float)} if isinstance(values, dict) else {}
    )


def _module(item: pytest.Item) -> str | None:
    module = getattr(item, "module", None)
    return module.__name__ if module is not None else None


#: Each test's seconds so far under ``--record-durations`` (None: not recording, or an xdist worker).
_recorded: dict[str, float] | None = None


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    """Add up each test's phases (the xdist controller receives every worker's reports)."""
    if _recorded is not None:
        _recorded[report.nodeid] = _recorded.get(report.nodeid, 0.0) + report.duration


def pytest_sessionfinish(session: pytest.Session) -> None:
    path = session.config.getoption("record_durations", None)
    if _recorded is not None and path:
        kept = {nodeid: round(s, 1) for nodeid, s in sorted(_recorded.items()) if s >= RECORD_MIN_S}
        Path(path).write_text(json.dumps(kept, indent=1) + "\n")


@pytest.fixture(scope="session", autouse=True)
def _decoded_cache_of_the_session(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Decoded logs go to one folder per test session (not the user's cache), unless ALBOT1_DECODED_CACHE says.

    Under pytest-xdist the controller makes that folder (:func:`pytest_configure`) and every worker inherits it, so
    a log decoded by one worker is read back by the others instead of being decoded once per worker.
    """
    with pytest.MonkeyPatch.context() as patch:
        if not os.environ.get(DECODED_CACHE_ENV):
            patch.setenv(DECODED_CACHE_ENV, str(tmp_path_factory.mktemp("decoded")))
        yield


# -- what the xdist controller does before its workers start ---------------------------------------------------

#: the decoded-log cache's variable (albot1.settings; not imported here, to keep the controller's start-up light)
DECODED_CACHE_ENV = "ALBOT1_DECODED_CACHE"


def pytest_configure(config: pytest.Config) -> None:
    """On the xdist controller of a run with workers: one decoded-log folder for all of them (and the recorder).

    Each worker would otherwise decode the public logs it opens into a folder of its own
    (:func:`_decoded_cache_of_the_session`); the workers inherit the controller's environment.
    Ctrl-C is given back its Python meaning (:func:`_ctrl_c_as_python_has_it`) in the controller and each worker.
    """
    global _recorded
    _ctrl_c_as_python_has_it()
    if config.getoption("record_durations", None) and not hasattr(config, "workerinput"):
        _recorded = {}
    workers = getattr(config.option, "numprocesses", None) or 0
    if hasattr(config, "workerinput") or workers < 1 or config.option.collectonly:
        return
    folder = Path(tempfile.mkdtemp(prefix="albot1-test-session-"))
    config.stash[_SESSION_FOLDER] = folder
    if not os.environ.get(DECODED_CACHE_ENV):
        os.environ[DECODED_CACHE_ENV] = str(folder / "decoded")


def _ctrl_c_as_python_has_it() -> None:
    """SIGINT raising KeyboardInterrupt, when the run was started with it ignored (``cmd &`` in a script, nohup).

    A shell without job control starts a background command with SIGINT ignored, and Python then leaves it
    ignored, as do the processes the tests start: the tests of Ctrl-C handling (the bench's interrupt line, a
    cell's "interrupted" record) failed under such a run, for what the terminal did, not the code. A handler
    set here is reset to the default at ``exec``, so the tests' subprocesses get Python's own as well.
    """
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_unconfigure(config: pytest.Config) -> None:
    folder = config.stash.get(_SESSION_FOLDER, None)
    if folder is not None:
        shutil.rmtree(folder, ignore_errors=True)


_SESSION_FOLDER = pytest.StashKey[Path]()
