"""How Albot1's kernels are compiled: numba's own decorators, numba's own cache, numba's own off switch.

A *kernel* is a loop over numpy arrays and scalars in the subset numba
compiles, called from the mappers' Python code: it is decorated with
:func:`kernel`, i.e. ``numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)``. A function a
kernel calls is decorated with :func:`jitable` (``numba.extending.register_jitable``):
it stays the plain Python function when Python calls it and is compiled into
every kernel that calls it. The geometry helpers the kernels call live in a
lower layer that must not import numba (every metric and loader imports
them); they are registered here, in :data:`GEOMETRY_CALLEES`, which is the
only list of this kind (a kernel calling an unregistered plain function fails
to compile with numba's "Untyped global name" error, and the parity tests run
every kernel).

Nothing compiles at import: numba compiles a kernel on its first call, or
loads it from its on-disk cache. Numba checks a cached kernel against the
time stamp of the kernel's own source file only, not against the files of
the functions compiled into it; the cache therefore lives in a folder named
by the code version (:func:`albot1.versions.code_version`, a digest of every
source file of the package), set as ``NUMBA_CACHE_DIR`` here, before the
first kernel is decorated: any edit anywhere in the package starts a fresh
folder, and every cell and run of the same code on the machine shares one.
The folder is under the user's cache directory (``.../albot1-bench/numba/``),
so an installed wheel in a read-only site-packages caches too; if that
folder cannot be written, a per-user folder in the temporary directory is
used. Old versions' folders are never read again and may be deleted.

The pure-Python path is numba's documented switch: ``NUMBA_DISABLE_JIT=1`` in
the environment makes every decorator here return the function as written,
process-wide. A mapper with ``accelerate = false`` calls its kernels' Python
source (:func:`as_written`, numba's ``py_func``) instead, so one process can
run both; results are bit-identical either way (the parity tests check it).
"""

from __future__ import annotations

import getpass
import inspect
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, cast

#: numba's documented switch for plain error messages; why it is on: :data:`PLAIN_ERRORS_ENV`'s comment
PLAIN_ERRORS_ENV = "NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING"
# Typing a kernel, numba tries each overload of every operation and formats an error message for each one that
# does not fit (thousands per kernel, all discarded); with highlighting on, each message also sets colorama up
# and tears it down. Off, a cold compile costs about 3 % less CPU (docs/albot1-mapper.md, "Compile time, fifth
# round"). Numba reads the switch when it is first imported, hence here, before the import; a value set by the
# user is kept, and numba's default colour scheme ("no_color") adds no colour either way.
os.environ.setdefault(PLAIN_ERRORS_ENV, "1")
#: numba's documented switch for the CPU its code is compiled for; why ``generic``: :data:`CPU_NAME_ENV`'s comment
CPU_NAME_ENV = "NUMBA_CPU_NAME"
# Numba compiles for the host's CPU model unless told otherwise, and keys its cache by that model and its feature
# list, so kernels compiled on one machine are never loaded on another. With ``generic`` (the architecture's
# baseline, e.g. x86-64 without AVX) they load anywhere, which is what lets a wheel ship its kernels
# (:mod:`.kernel_bundle`). Measured on this project's machine (one CPU model, an Intel "rocketlake"): the same
# bits (benchmarks/fingerprints.py) and no slower per scan (docs/albot1-mapper.md, "Compile time, seventh round");
# without fast-math numba contracts no multiply-add, so the bits should not depend on the CPU model either. A
# value set by the user is kept (the bundle then does not match, and the kernels are compiled for that CPU).
os.environ.setdefault(CPU_NAME_ENV, "generic")

import numba  # noqa: E402  (after the switch above)
import numpy as np  # noqa: E402
from numba.core import config as numba_config  # noqa: E402
from numba.extending import register_jitable  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

from albot1 import versions  # noqa: E402
from albot1.config.numbers import is_plain  # noqa: E402
from albot1.errors import ConfigError  # noqa: E402
from albot1.geometry import se2, segments  # noqa: E402

F = TypeVar("F", bound=Callable[..., Any])

#: numba's environment variable for its cache folder (read at import and again by every compilation)
CACHE_DIR_ENV = "NUMBA_CACHE_DIR"
#: how many processes a cold warm-up compiles in (default: the CPUs this process may use; 1 = this process only)
PROCESSES_ENV = "ALBOT1_COMPILE_PROCESSES"


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError:
        return False
    return True


def cache_dir() -> Path:
    """The folder numba caches this code version's kernels in (created; see the module docstring)."""
    from platformdirs import user_cache_dir

    version = versions.code_version()
    path = Path(user_cache_dir("albot1-bench")) / "numba" / version
    if _writable(path):
        return path
    return Path(tempfile.gettempdir()) / f"albot1-bench-numba-{getpass.getuser()}" / version


def _use_cache_dir() -> Path:
    path = cache_dir()
    os.environ[CACHE_DIR_ENV] = str(path)  # numba re-reads its config from the environment when it compiles
    # numba may have been imported (and have read its environment) before this module: read it again
    reload_config: Callable[[], None] = numba_config.reload_config
    reload_config()
    return path


#: where this process's kernels are cached
CACHE_DIR: Path = _use_cache_dir()


#: numba's options of a kernel (``numba.njit``) and of a function kernels call (``register_jitable``)
KERNEL_OPTIONS: dict[str, Any] = {"cache": True, "nogil": True, "no_cfunc_wrapper": True}
JITABLE_OPTIONS: dict[str, Any] = {"no_cfunc_wrapper": True}


def kernel(fn: F) -> F:
    """``numba.njit(**KERNEL_OPTIONS)``: compiled on first call (or loaded from the cache), typed as written.

    Cached, ``nogil``, and ``no_cfunc_wrapper``: numba otherwise also builds, optimises and
    generates machine code for a C-callable twin of every compiled function
    (for ``cfunc`` callbacks and first-class function values, which nothing
    here uses); without it a cold compile costs 5-10 % less CPU and the
    kernels' code is the same (``docs/albot1-mapper.md``, "Compile time").
    """
    return cast(F, numba.njit(**KERNEL_OPTIONS)(fn))


def jitable(fn: F) -> F:
    """``numba.extending.register_jitable``: ``fn`` itself for Python callers, compiled into the kernels calling it.

    Compiled without a C-callable twin, as :func:`kernel` is.
    """
    jitted: F = register_jitable(**JITABLE_OPTIONS)(fn)
    return jitted


@jitable
def falses(n: int) -> NDArray[np.bool_]:
    """``n`` False values: a loop, not ``np.zeros``, is one numpy routine less for numba to compile."""
    out = np.empty(n, dtype=np.bool_)
    for z in range(n):
        out[z] = False
    return out


def readonly_float64(a: NDArray[Any]) -> NDArray[np.float64]:
    """``a`` as a read-only, C-contiguous float64 array (a view; a copy only when ``a`` is not float64 contiguous).

    Numba compiles a kernel once per set of argument types, and whether an
    array is writable is part of its type: loaders give read-only scans, a
    degradation or a caller's own arrays writable ones. A kernel called on
    ``readonly_float64`` arrays has one signature, so a warm-up compiles it once.
    """
    out = np.ascontiguousarray(a, dtype=np.float64)
    if out.flags.writeable:
        out = out.view()
        out.flags.writeable = False
    return out


def as_written(fn: F) -> F:
    """The Python source of kernel ``fn`` (numba's ``py_func``; ``fn`` itself when the JIT is disabled)."""
    return cast(F, getattr(fn, "py_func", fn))


def select(fn: F, compiled: bool) -> F:
    """Kernel ``fn`` compiled, or as written (``accelerate = false``): the same source and the same results."""
    return fn if compiled else as_written(fn)


def is_cached(fn: Callable[..., Any] | None = None) -> bool:
    """Whether this code version's cache holds kernel ``fn`` (any kernel when None; False: a warm-up compiles it).

    Numba names a kernel's cache index ``<module file stem>.<qualname>-<line>.py<version>.nbi``
    (numba's own file naming), in a subfolder of this code version's folder named for the source file's own
    folder: two checkouts or installs of the same code share the version's folder but not their subfolders, and
    numba does not load another path's entries. So the kernel's own subfolder is searched (numba's
    ``cache_path``), not the whole folder: a match elsewhere made a warm-up think a cold kernel was cached, so it
    compiled every kernel in one process instead of spreading them (a fresh clone's `make bench` waited 21 s
    instead of 14 s before its first cells when another checkout of the same commit had run).
    """
    if fn is None:
        return any(CACHE_DIR.rglob("*.nbi"))
    source = as_written(fn)
    pattern = f"{Path(inspect.getfile(source)).stem}.{source.__qualname__}-*.nbi"
    own = getattr(getattr(fn, "_cache", None), "cache_path", None)  # numba's locator for this kernel's source
    return any(Path(own).glob(pattern)) if own else any(CACHE_DIR.rglob(pattern))


def needs_compile(kernel: Callable[..., Any]) -> bool:
    """Whether calling ``kernel`` compiles it: numba's dispatcher has no signature here and no cache index.

    False for a function run as written (``NUMBA_DISABLE_JIT``): nothing to compile. The one test of "cold"
    the warm-ups of Albot1 and of gtsam-graph and the wheel's kernel bundle share.
    """
    signatures = getattr(kernel, "signatures", None)
    if signatures is None:
        return False
    return not signatures and not is_cached(kernel)


def compile_processes() -> int:
    """How many processes may compile kernels at once: ``ALBOT1_COMPILE_PROCESSES``, else the CPUs this process may use.

    Numba compiles under one lock per process (threads do not help), so a
    cold warm-up spreads its kernels over processes (:mod:`.warm_up`).
    """
    value = os.environ.get(PROCESSES_ENV, "").strip()
    if value:
        # ASCII digits only: int() alone reads "1_0" as 10 and "٣" as 3 (config/numbers.py's rule for user text)
        if not (is_plain(value) and value.isdigit()) or int(value) < 1:
            raise ConfigError(f"{PROCESSES_ENV}={value!r}: expected a whole number of processes (1 or more)")
        return int(value)
    affinity = getattr(os, "sched_getaffinity", None)
    return len(affinity(0)) if affinity is not None else os.cpu_count() or 1


#: the functions of lower layers (which do not import numba) that kernels call
GEOMETRY_CALLEES: tuple[Callable[..., Any], ...] = tuple(
    jitable(fn)
    for fn in (
        se2.wrap_angle,
        segments.orientation,
        segments.clip_parameter,
        segments.closest_parameter,
        segments.point_segment_distance,
        segments.line_angle,
        segments.segments_cross,
        segments.segment_distance,
    )
)
