"""The dataset registry: one TOML manifest per public dataset in ``datasets/``.

A manifest says where a dataset's files live relative to the data folder
(``radish/intel.clf.bz2``), where they can be downloaded (raw GitHub URLs at
pinned commits, so the bytes never change), their sha256, licence and
citation, and how to load them (odometry source, max range, reference
poses, relations file). Files are found through
:meth:`albot1.settings.Settings.search_roots` -- ``ALBOT1_DATA_DIR`` first,
then the download cache -- never through a hard-coded path.

Manifests are project files (users may add their own), not package data;
see ``datasets/README.md`` for the schema.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

from albot1.data.errors import DataError, DatasetNotFoundError
from albot1.data.model import Sequence
from albot1.settings import Settings

_ROLES = ("log", "relations")


@dataclass(frozen=True)
class DataFile:
    """One file of a dataset: where it sits under a data root, where to get it, its checksum."""

    role: str
    path: str
    sha256: str
    size: int | None = None
    urls: tuple[str, ...] = ()


@dataclass(frozen=True)
class DatasetManifest:
    """A parsed ``datasets/<name>.toml``."""

    name: str
    description: str
    format: str
    files: tuple[DataFile, ...]
    license: str = ""
    citation: str = ""
    source: str = ""
    local_only: bool = False
    reference: str = ""
    notes: str = ""
    loader: dict[str, Any] = field(default_factory=dict)
    manifest_path: Path | None = None

    def file(self, role: str) -> DataFile | None:
        """The first file with ``role`` (``"log"`` or ``"relations"``)."""
        return next((f for f in self.files if f.role == role), None)

    @property
    def log(self) -> DataFile:
        found = self.file("log")
        assert found is not None  # _parse_manifest guarantees one log file
        return found


def _manifest_dir() -> Path:
    from albot1.resources import project_dir

    return project_dir() / "datasets"


def _require(data: dict[str, Any], key: str, kind: type, where: Path) -> Any:
    value = data.get(key)
    if not isinstance(value, kind):
        raise DataError(f"{where}: key {key!r} must be a {kind.__name__} (see datasets/README.md)")
    return value


def _parse_manifest(path: Path) -> DatasetManifest:
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise DataError(f"{path}: not a readable TOML manifest ({exc})") from None
    name = _require(data, "name", str, path)
    if name != path.stem:
        raise DataError(f"{path}: name {name!r} must equal the file name {path.stem!r}")
    files = []
    for i, entry in enumerate(_require(data, "files", list, path)):
        where = Path(f"{path} files[{i}]")
        role = _require(entry, "role", str, where)
        if role not in _ROLES:
            raise DataError(f"{where}: role {role!r}; expected one of {', '.join(_ROLES)}")
        sha = _require(entry, "sha256", str, where).lower()
        if len(sha) != 64 or any(c not in "0123456789abcdef" for c in sha):
            raise DataError(f"{where}: sha256 must be 64 hex digits")
        files.append(
            DataFile(
                role=role,
                path=_require(entry, "path", str, where),
                sha256=sha,
                size=entry.get("size"),
                urls=tuple(entry.get("urls", ())),
            )
        )
    if sum(f.role == "log" for f in files) != 1:
        raise DataError(f'{path}: expected exactly one file with role = "log"')
    loader = data.get("loader", {})
    if not isinstance(loader, dict):
        raise DataError(f"{path}: [loader] must be a table of loader options")
    return DatasetManifest(
        name=name,
        description=str(data.get("description", "")),
        format=str(data.get("format", "carmen")),
        files=tuple(files),
        license=str(data.get("license", "")),
        citation=str(data.get("citation", "")),
        source=str(data.get("source", "")),
        local_only=bool(data.get("local_only", False)),
        reference=str(data.get("reference", "")),
        notes=str(data.get("notes", "")),
        loader=dict(loader),
        manifest_path=path,
    )


@lru_cache(maxsize=1)
def _manifests() -> dict[str, DatasetManifest]:
    folder = _manifest_dir()
    return {p.stem: _parse_manifest(p) for p in sorted(folder.glob("*.toml"))}


def names() -> list[str]:
    """Registered dataset names, sorted."""
    return sorted(_manifests())


def get(name: str) -> DatasetManifest:
    """The manifest of ``name``; DatasetNotFoundError listing the known names otherwise."""
    try:
        return _manifests()[name]
    except KeyError:
        raise DatasetNotFoundError(f"unknown dataset {name!r}; known datasets: {', '.join(names())}") from None


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
    from albot1.data.loaders.registry import load

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
    from albot1.data.fetch import ensure_file

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
