"""The dataset registry: one TOML manifest per public dataset in ``datasets/``.

The manifest types and their parser live in :mod:`albot1.data.manifest`;
this module finds the manifests, answers "which datasets exist and where
are their files", opens them and fetches missing files. Files are found
through :meth:`albot1.settings.Settings.search_roots` -- ``ALBOT1_DATA_DIR``
first, then the download cache -- never through a hard-coded path.

Manifests are found with :func:`albot1.resources.list_resources`: the
project's ``datasets/`` (the checkout's, or the copy bundled in an installed
wheel), plus a user's own under ``ALBOT1_CONFIG_DIR/datasets/``; see
``datasets/README.md`` for the schema.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import Any

from albot1.config.suggest import unknown_name_message
from albot1.data.errors import DatasetNotFoundError
from albot1.data.fetch import ensure_file
from albot1.data.loaders.registry import load
from albot1.data.manifest import DataFile, DatasetManifest, parse_manifest
from albot1.data.model import Sequence
from albot1.resources import list_resources
from albot1.settings import Settings


@lru_cache(maxsize=1)
def _manifests() -> dict[str, DatasetManifest]:
    return {p.stem: parse_manifest(p) for p in list_resources("datasets")}


def names() -> list[str]:
    """Registered dataset names, sorted."""
    return sorted(_manifests())


def get(name: str) -> DatasetManifest:
    """The manifest of ``name``; DatasetNotFoundError listing the known names otherwise."""
    try:
        return _manifests()[name]
    except KeyError:
        raise DatasetNotFoundError(
            unknown_name_message("dataset", name, names(), listing="albot1 datasets list")
        ) from None


def find_file(data_file: DataFile, settings: Settings) -> Path | None:
    """The first existing copy of ``data_file`` under the search roots (no checksum check)."""
    for root in settings.search_roots():
        candidate = root / data_file.path
        if candidate.is_file():
            return candidate
    return None


def _missing(manifest: DatasetManifest, data_file: DataFile, settings: Settings) -> DatasetNotFoundError:
    roots = ", ".join(str(r) for r in settings.search_roots())
    hint = (
        "it is derived locally and cannot be downloaded"
        if manifest.local_only or not data_file.urls
        else f"run `albot1 datasets fetch {manifest.name}` or set ALBOT1_DATA_DIR"
    )
    return DatasetNotFoundError(f"dataset {manifest.name!r}: {data_file.path} not found under {roots}; {hint}")


def locate(name: str, settings: Settings) -> Path:
    """Path of the dataset's log file; DatasetNotFoundError naming the roots searched."""
    manifest = get(name)
    found = find_file(manifest.log, settings)
    if found is None:
        raise _missing(manifest, manifest.log, settings)
    return found


def is_available(name: str, settings: Settings) -> bool:
    """True when every file of the dataset exists under a search root."""
    manifest = get(name)
    return all(find_file(f, settings) is not None for f in manifest.files)


def open_dataset(name: str, settings: Settings, **options: Any) -> Sequence:
    """The dataset as a streamed Sequence; ``options`` override the manifest's loader options."""
    manifest = get(name)
    path = locate(name, settings)
    merged: dict[str, Any] = {**manifest.loader, **options}
    relations = manifest.file("relations")
    if relations is not None and "relations" not in options:
        found = find_file(relations, settings)
        if found is None:
            raise _missing(manifest, relations, settings)
        merged["relations"] = found
    if manifest.format == "carmen":
        merged.setdefault("name", manifest.name)
        merged.setdefault("license", manifest.license)
        merged.setdefault("citation", manifest.citation)
    return load(path, manifest.format, **merged)


def fetch(name: str, settings: Settings, *, base_url: str | None = None) -> Path:
    """Download the dataset's missing files into the cache, verified; returns the log's path.

    See :func:`albot1.data.fetch.download_verified` for the atomic, checksum-first
    write. ``base_url`` replaces the manifest URLs by ``base_url/<path>`` (mirrors, tests).
    """
    manifest = get(name)
    log_path: Path | None = None
    for data_file in manifest.files:
        urls = (f"{base_url.rstrip('/')}/{data_file.path}",) if base_url else data_file.urls
        if manifest.local_only and not base_url:
            found = find_file(data_file, settings)
            if found is None:
                raise _missing(manifest, data_file, settings)
            path = found
        else:
            path = ensure_file(data_file, urls, settings)
        if data_file.role == "log":
            log_path = path
    assert log_path is not None
    return log_path
