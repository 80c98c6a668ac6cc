"""The map-shape metric's reference map, built once per machine rather than once per scored run.

Why: every run of a dataset is compared with the same reference map (every
scan projected with its reference pose, thinned on the metric's grid), and
``albot1 bench`` scores each cell in a process of its own, so each cell
rebuilt it: iterating the dataset's scans again, projecting and thinning
them, about a third of ``evaluate_run`` for a cheap cell (issue 24). The
thinned cloud is therefore kept in one ``.npz`` file per reference map under
:func:`albot1.settings.reference_map_cache_dir` (beside the decoded logs;
``ALBOT1_DECODED_CACHE=off`` switches both off), and in memory for the rest
of the process.

An entry's name is a sha256 of everything the cloud depends on (:func:`entry_key`):
the dataset's name (its slice and loader options), the sha256 of its files,
the code version (the loaders, the projection and the thinning) and numpy's, the number
of scans scored, the reference poses and scan times of the run (bytes), the
sensor offset and the thinning's parameters. A changed parameter, dataset or
run is a new entry, never an old cloud. An entry is only written after the
whole cloud was built, so the checks the build makes (the dataset's scan
times are the run's, it has as many scans) held for exactly these inputs; a
hit stands for them. A damaged entry (it does not load, or holds another key
or a cloud of the wrong shape) is built again; an unwritable folder means
building every time. The cloud read back is the array that was stored, bit
for bit, so the metric's numbers are the same with or without the cache.
"""

from __future__ import annotations

import hashlib
import json
from collections import OrderedDict
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from albot1.data import decoded
from albot1.geometry.types import FloatArray
from albot1.settings import reference_map_cache_dir
from albot1.versions import code_version

#: Bumped by hand when what an entry holds changes.
LAYOUT = 1
#: Reference maps kept in memory per process (a process scoring many runs of a few datasets).
MEMORY_ENTRIES = 8

_memory: OrderedDict[str, FloatArray] = OrderedDict()


def entry_key(
    *,
    dataset: str,
    checksums: Mapping[str, str],
    count: int,
    reference: FloatArray,
    timestamps: FloatArray,
    sensor_offset: FloatArray,
    voxel_m: float,
    max_points: int,
    manifest_loader: Mapping[str, Any] | None = None,
) -> str:
    """The sha256 (hex) naming the reference map of these inputs; any change gives another key.

    ``manifest_loader``: the dataset manifest's loader options (``SequenceMetadata.manifest_loader``): another
    ``max_range`` reads other points from the same files.
    """
    digest = hashlib.sha256()
    described = {
        "layout": LAYOUT,
        "code": code_version(),
        "numpy": np.__version__,
        "dataset": dataset,
        "checksums": dict(sorted(checksums.items())),
        "count": int(count),
        "voxel_m": float(voxel_m).hex(),
        "max_points": int(max_points),
        "loader": dict(manifest_loader or {}),
    }
    digest.update(json.dumps(described, sort_keys=True).encode())
    for array in (reference[:count], timestamps[:count], sensor_offset):
        values = np.ascontiguousarray(array, dtype=np.float64)
        digest.update(repr(values.shape).encode())
        digest.update(values.tobytes())
    return digest.hexdigest()


def reference_cloud(key: str, build: Callable[[], FloatArray]) -> FloatArray:
    """The cloud stored under ``key`` (memory, then disk); else ``build()``, stored, returned.

    With the cache off (:func:`albot1.settings.reference_map_cache_dir` is None)
    it is ``build()``, every time.

    ``build`` raises when the cloud cannot be built (a MetricsError): nothing
    is stored then, so the next run checks again.
    """
    folder = reference_map_cache_dir()
    if folder is None:  # the cache is off: built every time, held nowhere
        return np.ascontiguousarray(build(), dtype=np.float64)
    if key in _memory:
        _memory.move_to_end(key)
        return _memory[key]
    entry = folder / f"{key}.npz"
    cloud = read_entry(entry, key)
    if cloud is None:
        cloud = np.ascontiguousarray(build(), dtype=np.float64)
        write_entry(entry, key, cloud)
    cloud.setflags(write=False)  # shared by every later call of this process
    _memory[key] = cloud
    while len(_memory) > MEMORY_ENTRIES:
        _memory.popitem(last=False)
    return cloud


def read_entry(entry: Path, key: str) -> FloatArray | None:
    """The cloud of ``entry``, or None when it is missing, damaged, of another key or not a finite (K, 2) cloud."""
    arrays = decoded.load_npz(entry)  # any damage, whatever zipfile raises for it, is a miss
    if not isinstance(arrays, dict) or "key" not in arrays or "points" not in arrays:
        return None
    stored_key, cloud = arrays["key"], arrays["points"]
    if stored_key.shape != () or str(stored_key) != key:
        return None
    if cloud.dtype != np.float64 or cloud.ndim != 2 or cloud.shape[1] != 2 or not np.isfinite(cloud).all():
        return None
    return np.ascontiguousarray(cloud)


def write_entry(entry: Path, key: str, cloud: FloatArray) -> bool:
    """Store ``cloud`` atomically at ``entry``; False (and nothing stored) when the folder cannot be written.

    The decoded-log cache's own writer (:func:`albot1.data.decoded.write_entry`): the entry is its ``key`` and
    ``points`` arrays.
    """
    return decoded.write_entry(entry, {"key": np.array(key), "points": cloud})


def forget() -> None:
    """Drop the clouds held in memory (tests; the disk entries stay)."""
    _memory.clear()


def clear(folder: Path | None = None) -> int:
    """Delete every stored reference map (``folder`` or the configured one) and those in memory; the number deleted."""
    forget()
    target = folder if folder is not None else reference_map_cache_dir()
    return 0 if target is None else decoded.clear(target)  # the decoded-log cache's own: every .npz entry of a folder
