"""Compile Albot1's kernels with numba, or hand them out as written: one source, two speeds.

A kernel is a plain Python function over numpy arrays and scalars in the
subset numba compiles. :func:`kernel_compiler` returns a :class:`Compiler`
that maps each kernel to its jitted version (``accelerate`` and numba
importable) or to itself, so results never depend on the flag (the tests
compare both on every kernel and on whole runs).

Compiled code can only call compiled code, so every function a kernel calls
(found from the names its code uses, transitively, among this package's
functions, e.g. :func:`albot1.geometry.segments.segment_distance`) is
compiled too: each is cloned with a copy of its module's globals in which
those callees are replaced by their jitted versions. The source modules are
never modified, so the plain functions stay plain.

Compiled kernels are cached on disk by numba (later processes start in well
under a second). Numba validates a cached function against its own source
file only, not against callees in other files; each cache entry is
therefore also stamped with a digest of the source files of every function
it calls, so editing a callee recompiles its callers.
"""

from __future__ import annotations

import hashlib
import types
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, TypeVar, cast

F = TypeVar("F", bound=Callable[..., Any])

#: Only functions from this package are compiled as callees (numpy's own Python functions are numba's business).
_PACKAGE = "albot1."


@dataclass(frozen=True)
class Compiler:
    """Maps kernels to the versions to run: jitted when :attr:`jitted`, else the functions themselves."""

    jitted: bool
    _compiled: dict[int, Callable[..., Any]] = field(default_factory=dict, repr=False)

    def __call__(self, kernel: F) -> F:
        """The version of ``kernel`` to run (same signature, same results)."""
        return cast(F, self._compiled.get(id(kernel), kernel))


def callees(kernel: Callable[..., Any]) -> list[types.FunctionType]:
    """``kernel`` and every package function it calls by global name, transitively, in discovery order."""
    found: dict[int, types.FunctionType] = {}
    pending = [cast(types.FunctionType, kernel)]
    while pending:
        fn = pending.pop()
        if id(fn) in found:
            continue
        found[id(fn)] = fn
        for name in _global_names(fn.__code__):
            value = fn.__globals__.get(name)
            if isinstance(value, types.FunctionType) and value.__module__.startswith(_PACKAGE):
                pending.append(value)
    return list(found.values())


def _global_names(code: types.CodeType) -> set[str]:
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):  # comprehensions and nested functions
            names |= _global_names(const)
    return names


def kernel_compiler(accelerate: bool, kernels: Iterable[Callable[..., Any]]) -> Compiler:
    """A :class:`Compiler` for ``kernels`` (and their callees): jitted when ``accelerate`` and numba imports."""
    if not accelerate:
        return Compiler(jitted=False)
    try:
        import numba
    except ImportError:
        return Compiler(jitted=False)
    functions: dict[int, types.FunctionType] = {}
    for kernel in kernels:
        for fn in callees(kernel):
            functions.setdefault(id(fn), fn)
    sources: dict[str, bytes] = {}
    module_globals: dict[str, dict[str, Any]] = {}
    compiled: dict[int, Callable[..., Any]] = {}
    for key, fn in functions.items():
        namespace = module_globals.setdefault(fn.__module__, dict(fn.__globals__))
        clone = types.FunctionType(fn.__code__, namespace, fn.__name__, fn.__defaults__, fn.__closure__)
        clone.__qualname__ = fn.__qualname__
        clone.__module__ = fn.__module__
        clone.__doc__ = fn.__doc__
        dispatcher = numba.njit(cache=True, nogil=True)(clone)
        _stamp_cache(dispatcher, _source_digest(callees(fn), sources))
        compiled[key] = dispatcher
    # Point every clone's callees at the jitted versions; numba resolves globals when it compiles (first call).
    for namespace in module_globals.values():
        for name, value in namespace.items():
            if isinstance(value, types.FunctionType) and id(value) in compiled:
                namespace[name] = compiled[id(value)]
    return Compiler(jitted=True, _compiled=compiled)


def _source_digest(functions: Iterable[types.FunctionType], sources: dict[str, bytes]) -> str:
    """sha256 over the source files of ``functions`` (a function's code depends on its callees' files too).

    ``sources`` memoises file contents across calls.
    """
    digest = hashlib.sha256()
    for path in sorted({fn.__code__.co_filename for fn in functions}):
        if path not in sources:
            try:
                with open(path, "rb") as fh:
                    sources[path] = fh.read()
            except OSError:  # no readable source (e.g. a zip import): numba's own check is all there is
                sources[path] = b""
        digest.update(path.encode())
        digest.update(sources[path])
    return digest.hexdigest()


def _stamp_cache(dispatcher: Any, stamp: str) -> None:
    """Add ``stamp`` to the freshness stamp numba checks before loading ``dispatcher``'s cache entry.

    This reaches into numba's cache object (``_cache._cache_file._source_stamp``,
    checked with numba 0.68; a unit test fails if it moves); if a numba release
    renames it, the cache falls back to numba's own per-file check, which only
    misses edits to callees in other files.
    """
    cache_file = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
    if cache_file is not None and hasattr(cache_file, "_source_stamp"):
        cache_file._source_stamp = (cache_file._source_stamp, stamp)
