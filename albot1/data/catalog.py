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

import os
from dataclasses import replace
from functools import lru_cache
from pathlib import Path
from typing import Any
from urllib.parse import quote

from albot1.config.suggest import unknown_name_message
from albot1.data.errors import ChecksumError, DataError, DatasetNotFoundError
from albot1.data.fetch import ensure_file
from albot1.data.identity import content_sha256
from albot1.data.loaders.registry import load
from albot1.data.manifest import DataFile, DatasetManifest, parse_manifest
from albot1.data.model import Sequence
from albot1.resources import list_resources, resource_dirs
from albot1.settings import Settings

#: Each manifest file parsed, by (path, modification time, size): kept across forks, unlike ``_manifests``.
_PARSED: dict[tuple[Path, int, int], DatasetManifest] = {}


@lru_cache(maxsize=1)
def _manifests() -> dict[str, DatasetManifest]:
    """Every registered manifest by name: the files listed (and a user's replacement said) once a process.

    A forked process lists them again (``os.register_at_fork`` below): its
    ``ALBOT1_CONFIG_DIR`` may differ from its parent's, and a bench cell's
    ``cell.log`` must say which user's file replaced the project's. Parsing,
    the ~12-20 ms of it, is done again only for a file new or changed since
    (:func:`warm_manifests`; docs/benchmarking.md, "Session 24").
    """
    return {p.stem: _parse(p) for p in list_resources("datasets")}


def _parse(path: Path) -> DatasetManifest:
    try:
        stat = path.stat()
    except OSError:
        return parse_manifest(path)  # which says what is wrong with the file
    key = (path, stat.st_mtime_ns, stat.st_size)
    if key not in _PARSED:
        _PARSED[key] = parse_manifest(path)
    return _PARSED[key]


def warm_manifests() -> None:
    """Parse every manifest file of this process's folders into the memo, saying nothing, listing nothing.

    The cells' forkserver calls it (:mod:`albot1.bench.preload`), so that a
    cell opening a public log finds its manifests parsed; what the cell's own
    listing says (a user's file replacing the project's) is still said there.
    """
    for directory in resource_dirs("datasets"):
        for path in directory.glob("*.toml"):
            if path.is_file():
                _parse(path)


os.register_at_fork(after_in_child=_manifests.cache_clear)


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
    roots = settings.roots_text()
    hint = (
        "it is derived locally and cannot be downloaded"
        if manifest.local_only or not data_file.urls
        else f"run `albot1 datasets fetch {manifest.name}` or set ALBOT1_DATA_DIR"
    )
    return DatasetNotFoundError(f"dataset {manifest.name!r}: {data_file.path} not found under {roots}; {hint}")


def _folder_refusal(manifest: DatasetManifest, data_file: DataFile, found: Path) -> str:
    """Why a manifest's file that is a folder is refused, and which file inside to name instead.

    A ROS2 bag is a folder, but a manifest's sha256 is ``sha256sum`` of one
    file: the entry names the bag's storage file, and the loader reads the
    ``metadata.yaml`` beside it. This used to be "a folder, not a regular
    file; expected a data file", naming neither the manifest nor the fix.
    """
    where = f" ({manifest.manifest_path})" if manifest.manifest_path else ""
    storage = sorted(p.name for p in found.iterdir() if p.suffix in (".mcap", ".db3") and p.is_file())
    hint = (
        f'; for a ROS2 bag name its storage file: path = "{data_file.path}/{storage[0]}" with sha256 of '
        f"`sha256sum {found / storage[0]}`"
        if storage
        else ""
    )
    return (
        f"{found}: a folder, but the manifest of dataset {manifest.name!r}{where} names it as its "
        f"{data_file.role} file; expected a file (sha256 is the checksum of one file){hint}"
    )


def verified_file(manifest: DatasetManifest, data_file: DataFile, settings: Settings) -> Path:
    """The first copy of ``data_file`` under the search roots, checked against the manifest's sha256.

    The checksum is computed once and cached (:mod:`albot1.data.identity`).
    The copy that would be read must be the right one: a wrong copy is
    refused (ChecksumError naming both checksums and the fix), even when a
    verified copy sits in a later root, since silently reading the other
    one would hide which data a result came from.
    """
    copies = [root / data_file.path for root in settings.search_roots() if (root / data_file.path).exists()]
    if not copies:
        raise _missing(manifest, data_file, settings)
    found = copies[0]
    if found.is_dir():
        raise DataError(_folder_refusal(manifest, data_file, found))
    got = content_sha256(found, folder_ok=False)
    if got == data_file.sha256:
        return found
    where = f" ({manifest.manifest_path})" if manifest.manifest_path else ""
    good = next((c for c in copies[1:] if content_sha256(c, folder_ok=False) == data_file.sha256), None)
    if good is not None:
        fix = f"a verified copy is at {good}: remove or replace the wrong one (or point ALBOT1_DATA_DIR elsewhere)"
    elif manifest.local_only or not data_file.urls:
        fix = "replace it with the file the manifest names (it is derived locally), or remove it"
    else:
        fix = f"remove it and run `albot1 datasets fetch {manifest.name}`, or replace it with the right file"
    raise ChecksumError(
        f"{found}: sha256 {got}, but the manifest of dataset {manifest.name!r}{where} says {data_file.sha256}; {fix}"
    )


def locate(name: str, settings: Settings) -> Path:
    """Path of the dataset's verified log file; DatasetNotFoundError naming the roots searched, ChecksumError."""
    manifest = get(name)
    return verified_file(manifest, manifest.log, settings)


def is_available(name: str, settings: Settings) -> bool:
    """True when every file of the dataset exists under a search root."""
    manifest = get(name)
    return all(find_file(f, settings) is not None for f in manifest.files)


def copy_problem(name: str, settings: Settings) -> str | None:
    """Why a present copy of the dataset would be refused (a checksum mismatch), None when none would.

    Missing files are not a problem here (:func:`is_available` says so);
    the checksums are cached, so listing the catalog costs one hash per file once.
    """
    manifest = get(name)
    for data_file in manifest.files:
        if find_file(data_file, settings) is None:
            continue
        try:
            verified_file(manifest, data_file, settings)
        except ChecksumError as exc:
            return str(exc)
    return None


def open_dataset(name: str, settings: Settings, *, manifest_relations: bool = True, **options: Any) -> Sequence:
    """The dataset as a streamed Sequence; ``options`` override the manifest's loader options.

    ``manifest_relations=False``: the manifest's relations file is neither
    verified nor read nor recorded (the caller attaches a file of its own,
    ``?relations=FILE``, :func:`albot1.data.open.open_sequence`).
    """
    manifest = get(name)
    path = locate(name, settings)
    merged: dict[str, Any] = {**manifest.loader, **options}
    checksums = {path.name: manifest.log.sha256}
    relations = manifest.file("relations") if manifest_relations else None
    if relations is not None and "relations" not in options:
        found = verified_file(manifest, relations, settings)
        merged["relations"] = found
        checksums[found.name] = relations.sha256
        if relations.repeats is not None:
            merged.setdefault("relations_repeats", relations.repeats)
    if manifest.format == "carmen":
        merged.setdefault("name", manifest.name)
        merged.setdefault("license", manifest.license)
        merged.setdefault("citation", manifest.citation)
    sequence = load(path, manifest.format, **merged)
    metadata = replace(
        sequence.metadata,
        checksums={**sequence.metadata.checksums, **checksums},
        manifest_loader=dict(manifest.loader),
    )
    return sequence.with_metadata(metadata)


def fetch(name: str, settings: Settings, *, base_url: str | None = None) -> Path:
    """Download the dataset's missing files into the cache, verified; returns the log's path.

    See :func:`albot1.data.fetch.download_verified` for the atomic, checksum-first
    write. ``base_url`` replaces the manifest URLs by ``base_url/<path>`` (mirrors, tests), the path
    percent-encoded (a space or a non-ASCII letter in a path is no valid URL as it stands).
    """
    manifest = get(name)
    log_path: Path | None = None
    for data_file in manifest.files:
        urls = (f"{base_url.rstrip('/')}/{quote(data_file.path)}",) if base_url else data_file.urls
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
