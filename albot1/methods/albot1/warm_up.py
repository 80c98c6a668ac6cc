"""One small call per kernel, so numba compiles (or loads from its cache) every kernel before the first scan.

Numba compiles a kernel for the argument types of its first call. The
mappers call each kernel with one set of types (dtype, dimensions, layout,
read-only flag), so one small call per kernel with those types, made by
:func:`warm_up` before a run's timed loop, leaves nothing to compile during
the scans (a test checks that whole runs after a warm-up compile nothing
new). The same calls are the parity tests' small inputs: each kernel run
compiled and as written gives the same bits.

Changing a kernel's argument types means changing its sample here; the
tests name the kernel whose sample no longer fits.

A cold warm-up (this code version's first on the machine) spreads the
compile over processes, as numba compiles under one lock per process; see
:func:`warm_up` and ``docs/albot1-mapper.md`` ("Kernels", "Compile time").
Several warm-ups in a row (the bench's forkserver warms every preset of
every method) balance better as one: inside :func:`together` they only note
their kernels, and one warm-up compiles them all on leaving it.
"""

from __future__ import annotations

import contextlib
import importlib
import inspect
import math
import multiprocessing
import os
import signal
import tempfile
import threading
import time
from collections.abc import Callable, Collection, Iterator
from multiprocessing.process import BaseProcess
from pathlib import Path
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from albot1.methods.albot1 import compiled, kernel_bundle


def kernel_names(kernels: object) -> list[str]:
    """The kernels a kernel set (``PerceptionKernels``, ...) holds: its attributes other than ``compiled``."""
    return [name for name in vars(kernels) if name != "compiled"]


def _update_sample(seg: NDArray[np.float64]) -> tuple[Any, ...]:
    """A two-surface map and a view far from it: only additions, so a second call repeats the first exactly."""
    cap = 8
    box = np.zeros((cap, 4))
    box[:2] = np.column_stack(
        [seg[:, [0, 2]].min(1), seg[:, [1, 3]].min(1), seg[:, [0, 2]].max(1), seg[:, [1, 3]].max(1)]
    )
    state = (np.resize(seg, (cap, 4)), np.arange(cap) < 2, np.zeros(cap, dtype=np.int64))
    slots = (np.where(np.arange(cap) < 2, np.arange(cap), -1), np.arange(cap, dtype=np.int64), box)
    view = seg + 20.0
    log = np.zeros((cap, 3), dtype=np.int64)
    return (*state, *slots, log, 2, 2, 0, view, 20.0, 20.0, True, 1, 0.4, 0.1, 0.4, True, True)


def _samples() -> dict[str, list[tuple[Any, ...]]]:
    """Argument tuples per kernel name, typed as the mappers call them (scan arrays may be read-only)."""
    angles = np.radians(np.arange(90.0, -90.5, -10.0))
    ranges = 3.0 + 0.5 * np.cos(3.0 * angles)
    ranges[5] = np.nan
    seg = np.array([[-1.0, 2.0, 0.0, 2.5], [0.2, 2.5, 1.5, 2.0]])
    kinds = np.array([[1, 2], [2, 1]], dtype=np.int64)
    ids = np.arange(2, dtype=np.int64)
    poly = np.array([[0.0, 0.0], [-3.0, 3.0], [3.0, 3.0]])
    points = np.ascontiguousarray(seg.reshape(-1, 2))
    starts = np.zeros((1, 3))
    ok = np.ones((2, 2), dtype=np.bool_)
    scan_angles = np.radians(np.arange(-90.0, 90.5, 10.0))
    scan_ranges = np.full(scan_angles.size, 2.5)
    return {
        "build_view": [(ranges, angles, 30.0, 0.6, 0.2, 0.1, 0.1, math.radians(30.0), 0.0, 0.1, 0.0, 0.0, False)],
        "recognise_landmarks": [(seg, kinds, seg + 0.01, kinds, 0.05, 0.3, 0.04, math.radians(5.0), 0.4, True)],
        "update_surfaces": [_update_sample(seg)],
        "place_segments": [(seg, 0.5, -0.2, math.cos(0.3), math.sin(0.3))],
        "landmark_rows": [(seg, kinds, 0.4)],
        "refine_pose": [
            (starts, seg, seg + 0.01, ok, points, seg, 0.0, 0.0, 0.0, 0.0, 0.0, 0.05, 0.1, 0.05, 2.0, 0.5, 8, math.inf)
        ],
        "measurement_costs": [
            (np.zeros((2, 3)), seg, seg + 0.01, ok, points, seg, 0.05, 0.1, 0.05, 2.0, 0.5, math.inf)
        ],
        "screen_directions": [(0.1, 0.2, 0.05, np.diag([1e4, 2.0, 1e3]), 0.0, 0.0, 0.0, 0.4, 400.0)],
        "scan_points": [(compiled.readonly_float64(scan_ranges), compiled.readonly_float64(scan_angles), 30.0, 2)],
        "perceive": [
            (compiled.readonly_float64(scan_ranges), compiled.readonly_float64(scan_angles), 30.0, 0.6, 0.2, 0.1, 0.1)
            + (math.radians(30.0), 0.0, 0.1, 0.0, 0.0, False, 0.4, 30.0, 2)
        ],
        "refine_and_score": [
            (starts, seg, seg + 0.01, ok, points, seg, 0.0, 0.0, 0.0, 0.05, 0.1, 0.05, 2.0, 0.5, 8, math.inf)
        ],
        "robust_starts": [
            (seg, kinds, ids, np.array([0, -1]), np.array([0.5, np.nan]), np.array([0.1, np.nan]))
            + (np.array([0.01, np.nan]), ids[::-1].copy(), seg + 0.01, kinds, 0.0, 0.0, 0.0)
            + (np.radians(np.arange(-30.0, 31.0, 10.0)), 3, 0.05, 0.02)
        ],
        "detect_exits": [(seg, kinds, 0.6, 1.2, 0.5, 6.0, True)],
        "seen_through": [(seg, ids, np.ones(2, dtype=np.bool_), 0.5, 0.0, poly)],
        "near_exit": [(seg, ids, ids, 1, 10, 1, 0.5, 0.0, 0.5)],
        "update_sides": [
            (seg, np.zeros(2, dtype=np.int64), np.zeros((2, 2)), np.zeros(2, dtype=np.int64), ids, ids)
            + (0.5, 0.0, 0.2, 1, 10, 1)
        ],
        "merge_collinear": [(seg, 0.1, 0.2, 0.4)],
        "colocated": [(seg, points.reshape(2, 4).copy(), ids, ids[:0], poly, seg, 0.4, True)],
        "same_any": [(seg, seg, 0.1, 0.4)],
        "match_structure": [
            (seg, np.array([-1, 1], dtype=np.int64), seg, 0.1, 0.4, 5, 1, poly, np.array([0, 3], dtype=np.int64))
            + (0, np.zeros(3), np.zeros(2), 0.8, 3.0)
        ],
    }


def sample_calls(*kernel_sets: object) -> Iterator[tuple[str, Callable[..., Any], tuple[Any, ...]]]:
    """``(kernel name, kernel, arguments)`` for every sample of every kernel of ``kernel_sets``."""
    samples = _samples()
    for kernels in kernel_sets:
        for name in kernel_names(kernels):
            for args in samples[name]:
                yield name, getattr(kernels, name), args


def _claim(claims: Path, name: str) -> bool:
    """Whether this process takes kernel ``name`` (the first process to create its claim file does)."""
    try:
        os.close(os.open(claims / name, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        return False
    return True


def compile_claimed(claims: str, kernel_sets: list[str], names: list[str]) -> None:
    """A helper process's part of a cold warm-up: compile every kernel of ``names`` no other process claimed first.

    ``kernel_sets`` are ``module:Class`` of the kernel sets; numba writes
    each kernel compiled here into this code version's cache, which the
    process that started this one then loads.
    """
    sets = [getattr(importlib.import_module(spec.partition(":")[0]), spec.partition(":")[2])() for spec in kernel_sets]
    _compile(Path(claims), list(sample_calls(*sets)), names)


def helper_main(claims: str, kernel_sets: list[str], names: list[str]) -> None:
    """A helper process's entry: :func:`compile_claimed`, ended by Ctrl-C at once and silently.

    Ctrl-C reaches the whole process group, the helpers too: a
    KeyboardInterrupt in a helper made multiprocessing print its traceback
    above the clean line of the process that started it, which is
    interrupted too and says so. SIGINT's default action ends the helper
    without a word; whatever it did not compile, the process that started
    it compiles itself (or, interrupted, no longer needs).
    """
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    compile_claimed(claims, kernel_sets, names)


#: Kernels that share dear callees with another: claimed right after it, by the same process, when they are cold.
#: ``measurement_costs`` calls ``pose_cost``, ``nearest_surface`` and ``huber_cost`` as ``refine_pose`` does: about
#: 0.7 CPU s compiled once instead of once in each of two processes. A fused kernel (:mod:`.mapping.step_kernels`)
#: calls the kernels it fuses, which its compile reuses when this process has compiled them.
_FOLLOWS: dict[str, tuple[str, ...]] = {
    "refine_pose": ("measurement_costs", "refine_and_score"),
    "build_view": ("landmark_rows", "scan_points", "perceive"),
}


def _compile(claims: Path, calls: list[tuple[str, Callable[..., Any], tuple[Any, ...]]], names: list[str]) -> None:
    for first in names:
        if not _claim(claims, first):
            continue
        # its followers claimed with it: another process reaching one first would compile the shared callees again
        followers = [name for name in _FOLLOWS.get(first, ()) if name in names and _claim(claims, name)]
        for name in (first, *followers):
            for called, kernel, args in calls:
                if called == name:
                    kernel(*args)


def _helpers(claims: Path, kernel_sets: tuple[object, ...], names: list[str]) -> list[BaseProcess]:
    """Start the helper processes of a cold warm-up (none when one process may compile or one kernel is cold).

    Forked where the platform can and this process runs no other thread: a
    fork starts in milliseconds with numba and the kernels already imported;
    otherwise spawned (a fresh interpreter imports them, about a second).
    """
    count = min(compiled.compile_processes(), len(names)) - 1
    if count < 1 or multiprocessing.current_process().daemon:  # a daemonic process (a Dask worker) has no children
        return []
    forking = "fork" in multiprocessing.get_all_start_methods() and threading.active_count() == 1
    context = multiprocessing.get_context("fork") if forking else multiprocessing.get_context("spawn")
    specs = [f"{type(k).__module__}:{type(k).__qualname__}" for k in kernel_sets]
    helpers: list[BaseProcess] = [
        context.Process(target=helper_main, args=(str(claims), specs, names), daemon=True) for _ in range(count)
    ]
    before = sum(1 for _ in claims.iterdir())
    for helper in helpers:
        helper.start()
    if forking:
        _first_claims(claims, helpers, before + len(helpers))
    return helpers


def _first_claims(claims: Path, helpers: list[BaseProcess], claimed: int, wait_s: float = 0.5) -> None:
    """Wait (at most ``wait_s``) until ``claimed`` kernels are claimed (each helper's first): the dearest go to them.

    This process has already paid numba's set-up before the fork; were it
    also to claim the dearest kernel (a fork starts in about a millisecond,
    this process goes on at once), it would finish last. With the thesis
    kernels: ``update_surfaces`` alone takes as long as the rest.
    """
    deadline = time.perf_counter() + wait_s
    while time.perf_counter() < deadline and any(helper.is_alive() for helper in helpers):
        if sum(1 for _ in claims.iterdir()) >= claimed:
            return
        time.sleep(0.001)


def warm_up(
    kernel_sets: tuple[object, ...], announce: Callable[[str], None] | None = None, skip: Collection[str] = ()
) -> None:
    """Call every kernel of ``kernel_sets`` once with its mappers' argument types: numba compiles them now.

    With numba's cache filled (any earlier run of this code version on this
    machine) this is a cache load. Kernels missing from the cache are
    compiled by up to :func:`compiled.compile_processes` processes at once:
    helper processes and this one take the cold kernels one by one, dearest
    to compile first (:func:`compile_cost`; a claim file each), and numba's cache hands this process what the
    helpers compiled. Whatever a helper did not deliver (it failed, or was
    slower) this process compiles itself, so a helper changes only the time.
    ``announce`` receives a line before and after a real compilation, none
    for a cache load. ``skip``: kernels the caller's configuration never
    calls (``MappingKernels.not_called``), neither compiled nor loaded.
    Inside :func:`together` the kernels are only noted, and compiled on leaving it.
    """
    calls = [call for call in sample_calls(*kernel_sets) if call[0] not in skip]
    if _open.batch is not None:
        _open.batch.add(kernel_sets, calls, announce)
        return
    _warm(kernel_sets, calls, announce)


class _Batch:
    """The kernels of the warm-ups made inside :func:`together`: each (kernel, sample) once, in first-seen order."""

    def __init__(self) -> None:
        self.kernel_sets: dict[type, object] = {}
        self.calls: dict[tuple[str, int, int], tuple[str, Callable[..., Any], tuple[Any, ...]]] = {}
        self.announce: Callable[[str], None] | None = None

    def add(
        self,
        kernel_sets: tuple[object, ...],
        calls: list[tuple[str, Callable[..., Any], tuple[Any, ...]]],
        announce: Callable[[str], None] | None,
    ) -> None:
        for kernels in kernel_sets:
            self.kernel_sets.setdefault(type(kernels), kernels)
        seen: dict[tuple[str, int], int] = {}
        for name, kernel, args in calls:  # the same kernel's n-th sample: the same argument types in every warm-up
            n = seen[name, id(kernel)] = seen.get((name, id(kernel)), -1) + 1
            self.calls.setdefault((name, id(kernel), n), (name, kernel, args))
        self.announce = self.announce or announce


class _Open(threading.local):
    """This thread's open :func:`together` block (a warm-up in another thread is not taken into it)."""

    batch: _Batch | None = None


_open = _Open()


@contextlib.contextmanager
def together() -> Iterator[None]:
    """Make the warm-ups called inside one: they note their kernels, which are all compiled when the block ends.

    Why: each cold warm-up ends when its slowest process does, so warm-ups in
    a row (the thesis kernels, then Albot1+'s, then the places layer's, as
    the bench's forkserver warms every preset of both methods) each wait for
    their own dearest kernel while the other process idles; one warm-up over
    the union keeps both busy to the end. Nested blocks join the outermost; a
    block covers the warm-ups of its own thread.
    Nothing is compiled when the block raises.
    """
    if _open.batch is not None:
        yield
        return
    batch = _open.batch = _Batch()
    try:
        yield
    finally:
        _open.batch = None
    if batch.calls:
        _warm(tuple(batch.kernel_sets.values()), list(batch.calls.values()), batch.announce)


def _warm(
    kernel_sets: tuple[object, ...],
    calls: list[tuple[str, Callable[..., Any], tuple[Any, ...]]],
    announce: Callable[[str], None] | None,
) -> None:
    """:func:`warm_up` of ``calls`` (the samples of ``kernel_sets`` that are to be called)."""
    kernels = {name: kernel for name, kernel, _ in calls}
    if any(compiled.needs_compile(kernel) for kernel in kernels.values()):
        kernel_bundle.seed(
            calls, compiled.needs_compile
        )  # the wheel's own compiled kernels, where numba will accept them
    cold = sorted(
        (name for name, kernel in kernels.items() if compiled.needs_compile(kernel)),
        key=lambda n: -compile_cost(n, kernels[n]),
    )
    if cold and announce is not None:
        announce(f"albot1: compiling the numba kernels once for this code version (cache: {compiled.CACHE_DIR})")
    start = time.perf_counter()
    if cold:
        with tempfile.TemporaryDirectory(prefix="albot1-compile-") as folder:
            _set_up_numba()  # before the fork: forked helpers inherit it
            helpers = _helpers(Path(folder), kernel_sets, cold)
            try:
                _compile(Path(folder), calls, cold)
            except BaseException:  # a failed compile or an interrupt: the helpers' work is no longer wanted
                for helper in helpers:
                    helper.terminate()
                raise
            finally:
                for helper in helpers:
                    helper.join()
    for _, kernel, args in calls:
        kernel(*args)
    if cold and announce is not None:
        announce(f"albot1: kernels compiled in {time.perf_counter() - start:.1f} s")


def _copy(a: NDArray[np.float64]) -> NDArray[np.float64]:
    out = np.empty(a.shape[0])
    for i in range(a.shape[0]):
        out[i] = a[i]
    return out


def _set_up_numba() -> None:
    """Pay numba's one-time set-up (its typing and target registries, LLVM, arrays) with a throw-away function.

    Why not with the cheapest kernel, as before: a forked helper starts when
    this returns, and the dearest kernel goes to it, so whatever is compiled
    here lies on the longest path of a cold warm-up; this function (not
    cached, nothing written) costs less than any kernel and leaves about as
    little for each process to set up. Measured with
    ``benchmarks/compile_cost.py warm-up thesis``: the longest path 4.8 ->
    4.5-4.6 CPU-s (``docs/albot1-mapper.md``, "Compile time").
    """
    import numba  # here, not at the top: :mod:`.compiled` (imported above) sets numba's switches before its import

    copy = cast(Callable[[NDArray[np.float64]], NDArray[np.float64]], numba.njit(_copy))
    copy(np.zeros(1))


#: CPU seconds of each kernel's cold compile in one process, measured: the order a cold warm-up claims them in.
#: ``benchmarks/compile_cost.py kernels plus`` and ``... places`` on the idle 2-core machine (a callee two kernels
#: share is charged to the first). Only the order matters: dearest first, so that the last kernels claimed are
#: cheap and the processes finish together (longest-processing-time-first scheduling).
COMPILE_CPU_S: dict[str, float] = {
    "update_surfaces": 3.44,
    "refine_pose": 2.28,
    "screen_directions": 2.08,
    "build_view": 1.88,
    "match_structure": 1.87,
    "recognise_landmarks": 1.24,
    "measurement_costs": 0.61,
    "detect_exits": 0.55,
    "colocated": 0.54,
    "same_any": 0.46,
    "merge_collinear": 0.43,
    "update_sides": 0.38,
    "landmark_rows": 0.22,
    "scan_points": 0.18,
    "seen_through": 0.17,
    "near_exit": 0.17,
    "place_segments": 0.15,
    # the fused kernels (plusfast10, under load 9-11: scaled by build_view's idle/loaded ratio, 1.88 / 2.58 s);
    # perceive cold with the three kernels it calls (plus's warm-up leaves those out), refine_and_score after
    # refine_pose and measurement_costs (its follower: their code reused)
    "perceive": 3.1,
    "refine_and_score": 0.31,
    # plusfast11, under load 6-7: 3.78 and 3.20 s, scaled by update_surfaces' idle/loaded ratio (3.44 / 10.5 s)
    "robust_starts": 1.15,
}
#: CPU seconds per source line for a kernel not (yet) in :data:`COMPILE_CPU_S`: about what the measured ones cost
_CPU_S_PER_LINE = 0.012


def compile_cost(name: str, kernel: Callable[..., Any]) -> float:
    """Kernel ``name``'s measured cold-compile CPU seconds (:data:`COMPILE_CPU_S`), else an estimate from its length."""
    measured = COMPILE_CPU_S.get(name)
    if measured is not None:
        return measured
    return _CPU_S_PER_LINE * len(inspect.getsourcelines(compiled.as_written(kernel))[0])
