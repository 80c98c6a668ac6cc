"""The dataset manifest: the types of ``datasets/<name>.toml`` and their parser.

A manifest says where a dataset's files live relative to a data root
(``radish/intel.clf.bz2``), where they can be downloaded (raw GitHub URLs at
pinned commits, so the bytes never change), their sha256, licence and
citation, and how to load them (odometry source, max range, reference
poses, relations file). The schema is documented in ``datasets/README.md``.

The types live apart from the registry (:mod:`albot1.data.catalog`) and the
downloader (:mod:`albot1.data.fetch`) because both use them and neither
should import the other.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import Any

from albot1.config.suggest import did_you_mean
from albot1.config.toml_lines import Location, key_lines, line_of
from albot1.data.errors import DataError
from albot1.data.loaders.registry import FORMATS
from albot1.data.relations import RepeatPolicy, repeat_policy

#: The roles a file of a dataset may have.
ROLES = ("log", "relations")


@dataclass(frozen=True)
class DataFile:
    """One file of a dataset: where it sits under a data root, where to get it, its checksum."""

    role: str
    path: str
    sha256: str
    size: int | None = None
    urls: tuple[str, ...] = ()
    #: a relations file's reading of identically repeated lines (``relations_repeats``): ``keep`` where the
    #: published figures count them as listed; None = the default (drop)
    repeats: RepeatPolicy | None = None


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
    #: the catalog name of the dataset whose recording this one is another version of (a corrected or thinned
    #: copy of the same drive: same place, route and scans); "" = its own recording. Held-in marks treat the two
    #: as one (albot1.report.tuning): values tuned on one log were tuned on the other's data.
    recording: str = ""

    def file(self, role: str) -> DataFile | None:
        """The first file with ``role`` (``"log"`` or ``"relations"``)."""
        return next((f for f in self.files if f.role == role), None)

    @property
    def log(self) -> DataFile:
        found = self.file("log")
        assert found is not None  # parse_manifest guarantees one log file
        return found


#: The keys of a manifest and of one of its ``[[files]]`` tables (``datasets/README.md``, "Schema").
TOP_KEYS = (
    "name",
    "description",
    "format",
    "license",
    "citation",
    "source",
    "local_only",
    "reference",
    "notes",
    "files",
    "loader",
    "recording",
)
FILE_KEYS = ("role", "path", "sha256", "size", "urls", "repeats")


@dataclass(frozen=True)
class _Where:
    """Where in a manifest a value sits: the file, its ``[[files]]`` entry, and the line of a key.

    Why: a manifest's errors named the file and the entry but no line, so a user with several ``[[files]]``
    tables counted them by hand (the project's rule for bad input is file and line).
    """

    path: Path
    lines: dict[Location, int]
    #: ``()`` for the top level, ``("files", i)`` inside the i-th ``[[files]]`` table
    table: Location = ()

    def at(self, key: str | None = None) -> str:
        """``FILE:LINE`` of ``key`` (or of its table, or no line when neither is written), then the entry."""
        location = (*self.table, key) if key is not None else self.table
        line = line_of(self.lines, location) if location else None
        entry = f" files[{self.table[1]}]" if self.table else ""
        return f"{self.path}{f':{line}' if line is not None else ''}{entry}"


def _unknown_keys(data: dict[str, Any], known: tuple[str, ...], where: _Where) -> None:
    """A DataError for the first key the schema does not have.

    An unknown key used to be ignored without a word, so a typo lost what it
    said: ``[loaders]`` for ``[loader]`` loaded a CARMEN log with the default
    odometry instead of the one asked for, ``url =`` for ``urls =`` left a
    dataset that "has no download URL".
    """
    for key in data:
        if key not in known:
            raise DataError(
                f"{where.at(key)}: unknown key {key!r}{did_you_mean(key, known)}; expected only {', '.join(known)} "
                "(see datasets/README.md)"
            )


def _format(value: str, where: _Where) -> str:
    """The manifest's ``format``: a readable format (it used to fail only when the dataset was opened, unnamed)."""
    if value not in FORMATS:
        raise DataError(
            f"{where.at('format')}: format {value!r}{did_you_mean(value, list(FORMATS))} is no format the datasets "
            f"are read in; expected one of {', '.join(FORMATS)}"
        )
    return value


#: TOML's names of the Python types a manifest value may have (for error messages).
_TOML_TYPES = {str: "string", int: "integer", bool: "boolean", list: "array", dict: "table"}


def _require(data: dict[str, Any], key: str, kind: type, where: _Where) -> Any:
    value = data.get(key)
    if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
        found = "nothing" if key not in data else f"a {_TOML_TYPES.get(type(value), type(value).__name__)}"
        raise DataError(
            f"{where.at(key)}: key {key!r} must be a {_TOML_TYPES[kind]}, found {found} (see datasets/README.md)"
        )
    return value


def _optional(data: dict[str, Any], key: str, kind: type, where: _Where, default: Any) -> Any:
    """``data[key]`` checked against ``kind`` when present, else ``default``."""
    return _require(data, key, kind, where) if key in data else default


def _strings(data: dict[str, Any], key: str, where: _Where) -> tuple[str, ...]:
    values = _optional(data, key, list, where, [])
    if not all(isinstance(v, str) for v in values):
        raise DataError(f"{where.at(key)}: key {key!r} must be a list of strings (see datasets/README.md)")
    return tuple(values)


def _size(value: int | None, where: _Where) -> int | None:
    if value is not None and value < 0:
        raise DataError(f"{where.at('size')}: size {value} must be a number of bytes >= 0")
    return value


def _relative_path(value: str, where: _Where) -> str:
    """A file's ``path``: relative, inside its data root (no ``..``, not absolute); DataError otherwise.

    The path is joined to the data folder and to the download cache, where a
    fetch writes it: ``../../x`` or ``/etc/x`` would read or overwrite a file
    outside them.
    """
    if (
        not value.strip()
        or PurePosixPath(value).is_absolute()
        or PureWindowsPath(value).is_absolute()
        or value.startswith("~")
        or "\\" in value
        or "\0" in value
        or any(part in ("", ".", "..") for part in value.split("/"))
    ):
        raise DataError(
            f"{where.at('path')}: path {value!r} must be a relative path inside the data folder, like "
            "'radish/aces.clf.bz2' (no leading '/' or '~', no '..' or '.' parts, '/' as separator)"
        )
    return value


def parse_manifest(path: Path) -> DatasetManifest:
    """Read and check one manifest; DataError naming the file, the line (and file entry) on bad input."""
    try:
        text = path.read_text(encoding="utf-8")
        data = tomllib.loads(text)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise DataError(f"{path}: not a readable TOML manifest ({exc})") from None
    top = _Where(path, key_lines(text))
    _unknown_keys(data, TOP_KEYS, top)
    name = _require(data, "name", str, top)
    if name != path.stem:
        raise DataError(f"{top.at('name')}: name {name!r} must equal the file name {path.stem!r}")
    files = []
    for i, entry in enumerate(_require(data, "files", list, top)):
        where = _Where(path, top.lines, ("files", i))
        if not isinstance(entry, dict):
            raise DataError(f"{where.at()}: expected a [[files]] table, got {type(entry).__name__}")
        _unknown_keys(entry, FILE_KEYS, where)
        role = _require(entry, "role", str, where)
        if role not in ROLES:
            raise DataError(f"{where.at('role')}: role {role!r}; expected one of {', '.join(ROLES)}")
        sha = _require(entry, "sha256", str, where).lower()
        if len(sha) != 64 or any(c not in "0123456789abcdef" for c in sha):
            raise DataError(f"{where.at('sha256')}: sha256 must be 64 hex digits")
        repeats = _optional(entry, "repeats", str, where, None)
        if repeats is not None:
            if role != "relations":
                raise DataError(f'{where.at("repeats")}: repeats goes with role = "relations", not {role!r}')
            repeats = repeat_policy(repeats, where.at("repeats"))
        files.append(
            DataFile(
                role=role,
                path=_relative_path(_require(entry, "path", str, where), where),
                sha256=sha,
                size=_size(_optional(entry, "size", int, where, None), where),
                urls=_strings(entry, "urls", where),
                repeats=repeats,
            )
        )
    if sum(f.role == "log" for f in files) != 1:
        raise DataError(f'{top.at("files")}: expected exactly one file with role = "log"')
    recording = _optional(data, "recording", str, top, "")
    if recording == name:
        raise DataError(
            f"{top.at('recording')}: recording names the dataset itself; leave it out for a recording of its own"
        )
    return DatasetManifest(
        name=name,
        description=_optional(data, "description", str, top, ""),
        format=_format(_optional(data, "format", str, top, "carmen"), top),
        files=tuple(files),
        license=_optional(data, "license", str, top, ""),
        citation=_optional(data, "citation", str, top, ""),
        source=_optional(data, "source", str, top, ""),
        local_only=_optional(data, "local_only", bool, top, False),
        reference=_optional(data, "reference", str, top, ""),
        notes=_optional(data, "notes", str, top, ""),
        loader=dict(_optional(data, "loader", dict, top, {})),
        manifest_path=path,
        recording=recording,
    )
