"""Build the kernel bundle of a wheel: :func:`build`, called by ``setup.py``'s build step.

Compiles every kernel of Albot1 and of its places layer on its warm-up
samples (the argument types the mappers call them with), and those of the
other kernel sources it is given (another method's warm-up and samples,
listed by :mod:`albot1.methods.kernel_sources`, which names them all), and copies numba's
cache files of each kernel into ``DEST`` (:mod:`.kernel_bundle` explains
what is checked where they are used). The build step runs it in a process
whose user cache folder is empty, so that what is copied is what this build
compiled. A module of its own, imported by no other, because it needs every
kernel set, and the warm-up (which reads the bundle) is imported by the
mappers.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from albot1.errors import Albot1Error
from albot1.methods.albot1 import kernel_bundle, warm_up
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.perception.kernels import PerceptionKernels
from albot1.methods.albot1.places.kernels import PlacesKernels


class KernelBundleError(Albot1Error):
    """A kernel the warm-up compiled left no cache files to bundle: a wheel without it would say it has it."""


def _kernel_files(name: str, kernel: Any) -> list[Path]:
    """Numba's cache files of ``kernel`` (its index, then its data files), read from where numba wrote them."""
    where = getattr(kernel._cache, "cache_path", None)
    if where is None:  # numba's NullCache: the kernel was decorated without cache=True
        raise KernelBundleError(f"kernel bundle: {name} is compiled without numba's cache; expected cache=True")
    cached = Path(where)
    base = kernel._cache._impl.filename_base
    index = cached / f"{base}.nbi"
    if not index.is_file():
        raise KernelBundleError(f"kernel bundle: {name} was compiled but numba wrote no index {index}")
    data = sorted(p for p in cached.glob(f"{base}.*.nbc") if p.is_file())
    if not data:
        raise KernelBundleError(f"kernel bundle: {name} has an index but no data file in {cached}")
    return [index, *data]


#: ``(kernel name, kernel, sample arguments)``, as :func:`warm_up.sample_calls` gives them
Call = tuple[str, Callable[..., Any], tuple[Any, ...]]
#: another method's kernels: its warm-up (compiles them, or loads them) and its sample calls (names them)
KernelSource = tuple[Callable[[], None], Callable[[], Iterable[Call]]]


def albot1_kernel_sets() -> tuple[object, ...]:
    """Every kernel set of Albot1 and its places layer: the kernels of the bundle besides ``others``."""
    return (PerceptionKernels(), MappingKernels(), PlacesKernels())


def albot1_calls() -> list[Call]:
    """The sample calls of :func:`albot1_kernel_sets`."""
    return list(warm_up.sample_calls(*albot1_kernel_sets()))


def build(dest: Path, others: Iterable[KernelSource]) -> int:
    """Compile every kernel (or load this code version's cache) and copy numba's files to ``dest``: file count.

    ``others``: the kernels of other methods, besides Albot1's kernel sets.
    Raises :class:`KernelBundleError` naming the first kernel whose files are
    missing, so that a build never ships a bundle that lacks a kernel.
    """
    kernel_sets = albot1_kernel_sets()
    warm_up.warm_up(kernel_sets)
    calls = list(warm_up.sample_calls(*kernel_sets))
    for warm, sample_calls in others:
        warm()
        calls += sample_calls()
    kernels: dict[str, Any] = {}
    for name, kernel, _ in calls:
        if kernels.setdefault(name, kernel) is not kernel:
            raise KernelBundleError(f"kernel bundle: two kernels are named {name}")
    if dest.exists():
        shutil.rmtree(dest)
    files: dict[str, str] = {}
    for name, kernel in sorted(kernels.items()):
        folder = kernel_bundle.bundle_folder(kernel)
        for path in _kernel_files(name, kernel):
            (dest / folder).mkdir(parents=True, exist_ok=True)
            shutil.copyfile(path, dest / folder / path.name)
            files[f"{folder}/{path.name}"] = kernel_bundle.sha256(path)
    manifest = {**kernel_bundle.fingerprint(), "files": files}
    dest.mkdir(parents=True, exist_ok=True)
    (dest / kernel_bundle.MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return len(files)
