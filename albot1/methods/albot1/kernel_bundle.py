"""Kernels compiled when the wheel is built, shipped in it, and handed to numba's cache where they fit (issue 24).

Why: a bare ``pip install`` of the wheel has no install step of ours, so
without this its first run compiles every kernel its preset calls (about
5 s more than a warm run for ``plus``; ``docs/albot1-mapper.md``, "Compile
time, seventh round"). The build step (``setup.py``, through
:mod:`.kernel_bundle_build`) compiles every kernel on its warm-up samples
and copies numba's own cache files into ``albot1/_bundled/kernels/``, one
folder per source folder of the package, with a manifest. Before a
warm-up compiles, :func:`seed` copies the files of each cold kernel into
this code version's numba cache (:data:`compiled.CACHE_DIR`), where numba
then loads them as if it had compiled them itself.

Why this is safe: the code is numba's own (compiled by numba, loaded by
numba, checked by numba: its version, the source file's stamp (its sha256
from numba 0.68 on; its mtime and size before, which an install does not
keep, so with an older numba the bundle is never used), the CPU target
and the kernel's bytecode), compiled for numba's ``generic`` CPU
(:data:`compiled.CPU_NAME_ENV`), so it runs on any machine of the
architecture. A kernel is seeded only when every check numba will make
passes here first: the manifest names this code version, this numba,
llvmlite and Python, and this process's CPU target; the bundled index
holds this source file's stamp and a key for each of the kernel's
samples; and every file has the sha256 the manifest records. The kernel
is then loaded at once, and its files taken back should numba fail. Anything
else (another numba, a user's ``NUMBA_CPU_NAME``, a damaged or foreign
file, a cache folder that cannot be written, a change in numba's
internals) leaves the kernel cold, and the warm-up compiles it as before.
Numba's internals read here (:func:`_index_entries`) are those of the
numba the bundle was built with, which the manifest pins; the tests run
them on the installed numba.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import platform
import sys
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import llvmlite
import numba
from llvmlite import binding as llvm
from numba.core import config as numba_config

from albot1.methods.albot1 import compiled

#: the package folder (``albot1/``): bundled files are named by their source folder relative to it
PACKAGE_DIR = Path(compiled.__file__).resolve().parents[2]
#: where the build step puts the kernels in the wheel (``albot1/_bundled`` is left out of the code version)
BUNDLE_DIR = PACKAGE_DIR / "_bundled" / "kernels"
MANIFEST = "manifest.json"
#: the layout of the bundle; a bundle of another format is not read
FORMAT = 1
#: the suffixes of numba's cache files: an index per kernel, a data file per compiled signature
SUFFIXES = (".nbi", ".nbc")


def fingerprint() -> dict[str, str]:
    """What the build and this process must share for numba to accept the bundled kernels (the manifest's keys)."""
    return {
        "format": str(FORMAT),
        "code_version": compiled.CACHE_DIR.name,
        "numba": numba.__version__,
        "llvmlite": llvmlite.__version__,
        # sys.abiflags is POSIX-only before Python 3.14
        "python": f"{platform.python_implementation()} {platform.python_version()} {getattr(sys, 'abiflags', '')}",
        "target": llvm.get_process_triple(),
        "cpu_name": str(getattr(numba_config, "CPU_NAME", None)),
        "cpu_features": str(getattr(numba_config, "CPU_FEATURES", None)),
    }


def bundle_folder(kernel: Any) -> str:
    """The bundle's folder of ``kernel``'s cache files: its source folder relative to the package, POSIX-style."""
    return Path(kernel.py_func.__code__.co_filename).resolve().parent.relative_to(PACKAGE_DIR).as_posix()


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def read_manifest(bundle: Path = BUNDLE_DIR) -> dict[str, Any] | None:
    """The bundle's manifest when it matches this process (:func:`fingerprint`), else None (no bundle, or foreign)."""
    try:
        manifest = json.loads((bundle / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(manifest, dict) or not isinstance(manifest.get("files"), dict):
        return None
    if any(manifest.get(key) != value for key, value in fingerprint().items()):
        return None
    return manifest


def _read_index(index: Path) -> tuple[Any, Any, Any]:
    """Numba's index file: its numba version (pickled), then the pickled ``(source stamp, {key: data file})``."""
    with index.open("rb") as f:
        version = pickle.load(f)
        stamp, overloads = pickle.loads(f.read())
    return version, stamp, overloads


def _index_entries(kernel: Any, index: Path, samples: list[tuple[Any, ...]]) -> set[str] | None:
    """The data files of ``index`` (a bundled numba index of ``kernel``) if numba will accept it here, else None.

    Numba reads an index only when its version and the stamp of the kernel's
    source file match (``numba.core.caching.IndexDataCacheFile``), and uses
    it only if it holds numba's key of every sample's signature for this
    process's CPU target.
    """
    cache = kernel._cache
    version, stamp, overloads = _read_index(index)
    if version != numba.__version__ or stamp != cache._impl.locator.get_source_stamp():
        return None
    if not isinstance(overloads, dict):
        return None
    codegen = kernel.targetctx.codegen()
    for args in samples:
        signature = tuple(kernel.typeof_pyval(a) for a in args)
        if cache._index_key(signature, codegen) not in overloads:
            return None
    return {str(name) for name in overloads.values()}


def _copy(source: Path, target: Path) -> None:
    """Copy ``source`` to ``target`` through a temporary file (a reader never sees half a file)."""
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(source.read_bytes())
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def seed(
    calls: Iterable[tuple[str, Callable[..., Any], tuple[Any, ...]]],
    is_cold: Callable[[Callable[..., Any]], bool],
    bundle: Path | None = None,
) -> list[str]:
    """Hand numba's cache the bundled files of every cold kernel of ``calls`` that numba will accept: their names.

    ``calls``: ``(kernel name, kernel, sample arguments)`` as a warm-up
    makes them; ``is_cold``: whether a kernel still has to be compiled;
    ``bundle``: :data:`BUNDLE_DIR` unless given (read when called). A
    kernel is left alone (and so compiled by the warm-up) when anything
    does not match; see the module docstring.
    """
    bundle = BUNDLE_DIR if bundle is None else bundle
    try:
        manifest = read_manifest(bundle)
    except Exception:  # noqa: BLE001 -- whatever this platform or numba lacks: the kernels are compiled as before
        return []
    if manifest is None:
        return []
    samples: dict[str, list[tuple[Any, ...]]] = {}
    kernels: dict[str, Callable[..., Any]] = {}
    for name, kernel, args in calls:
        kernels[name] = kernel
        samples.setdefault(name, []).append(args)
    seeded: list[str] = []
    for name, kernel in kernels.items():
        try:
            copied = _seed_one(kernel, samples[name], manifest["files"], bundle) if is_cold(kernel) else []
        except Exception:  # noqa: BLE001 -- any mismatch (numba's internals, a damaged file): compiled as before
            continue
        if copied and _loads(kernel, samples[name], copied):
            seeded.append(name)
    return seeded


def _loads(kernel: Callable[..., Any], samples: list[tuple[Any, ...]], copied: list[Path]) -> bool:
    """Load ``kernel`` now (numba reads what was just seeded); should numba fail, take the seeded files back.

    The checks before the copy are numba's own, so numba loads the kernel;
    this covers what they cannot see (a data file numba cannot rebuild),
    so that such a kernel is compiled by the warm-up instead of failing the run.
    """
    try:
        for args in samples:
            kernel(*args)
    except Exception:  # noqa: BLE001 -- numba could not use the seeded files: they go, and the kernel is compiled
        for path in reversed(copied):  # the index first: numba reads the data files only through it
            try:
                path.unlink(missing_ok=True)
            except OSError:  # e.g. a file another process holds open on Windows: numba recompiles over it
                pass
        return False
    return True


def _seed_one(kernel: Any, samples: list[tuple[Any, ...]], files: dict[str, str], bundle: Path) -> list[Path]:
    """Copy ``kernel``'s bundled files into numba's cache if numba will accept them: the files copied (index last)."""
    folder = bundle_folder(kernel)
    base = kernel._cache._impl.filename_base
    index = bundle / folder / f"{base}.nbi"
    relative = f"{folder}/{index.name}"
    if files.get(relative) is None or sha256(index) != files[relative]:
        return []
    data = _index_entries(kernel, index, samples)
    if data is None:
        return []
    for name in data:
        if files.get(f"{folder}/{name}") != sha256(bundle / folder / name):
            return []
    target = Path(kernel._cache.cache_path)
    if (target / index.name).exists():  # numba's own index: never replaced
        return []
    target.mkdir(parents=True, exist_ok=True)
    copied: list[Path] = []
    for name in sorted(data):
        _copy(bundle / folder / name, target / name)
        copied.append(target / name)
    _copy(index, target / index.name)  # last: numba reads the data files only through the index
    return [*copied, target / index.name]
