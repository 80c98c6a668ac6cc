"""Where the project finds datasets and keeps its caches.

Datasets are never found through a hard-coded path: ``ALBOT1_DATA_DIR`` names
a folder laid out like the shared dataset copies (``radish/``,
``radish-corrected/``, ...), and downloads go to ``ALBOT1_CACHE_DIR``
(default: the user's cache directory). Lookups try the data folder first and
the cache second, so a read-only data folder works.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from albot1.errors import ConfigError

DATA_DIR_ENV = "ALBOT1_DATA_DIR"
CACHE_DIR_ENV = "ALBOT1_CACHE_DIR"
#: Where decoded logs are cached (:mod:`albot1.data.decoded`): a folder, or ``off`` to decode every time.
DECODED_CACHE_ENV = "ALBOT1_DECODED_CACHE"
#: Values of :data:`DECODED_CACHE_ENV` that switch the decoded-log cache off.
DISABLED = frozenset(("off", "0", "no", "false", "none"))


def _user_cache_dir() -> Path:
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("albot1-bench"))


def _default_cache_dir() -> Path:
    return _user_cache_dir() / "datasets"


#: The file of :mod:`albot1.data.identity`'s checksum cache.
#: ``albot1 bench``'s results root when ``--results`` is not given (relative to the working directory): a
#: page's "Regenerate" command names ``--results`` only for another one
RESULTS_ROOT = Path("results")
CHECKSUM_CACHE = "checksums.json"


def checksum_cache_file() -> Path:
    """Where the data checksums are cached: beside the download cache of ``ALBOT1_CACHE_DIR``, else the user cache.

    Under ``ALBOT1_CACHE_DIR`` it is a hidden file (``.checksums.json``), as
    that folder holds the data files themselves.
    """
    cache = os.environ.get(CACHE_DIR_ENV)
    if cache:
        return Path(cache).expanduser() / f".{CHECKSUM_CACHE}"
    return _user_cache_dir() / CHECKSUM_CACHE


def decoded_cache_dir() -> Path | None:
    """The folder of decoded logs: ``ALBOT1_DECODED_CACHE``, else ``<user cache>/albot1-bench/decoded``; None = off.

    Decoding a raw log costs seconds and every benchmark cell opens one, so
    each log is decoded once per machine (``docs/benchmarking.md``, "Decoded-log cache").
    """
    value = os.environ.get(DECODED_CACHE_ENV, "").strip()
    if value.lower() in DISABLED:
        return None
    return Path(value).expanduser() if value else _user_cache_dir() / "decoded"


def reference_map_cache_dir() -> Path | None:
    """The folder of the map-shape metric's reference maps: ``reference-maps`` in the decoded logs' folder; None = off.

    Derived from the logs as the decoded logs are, it follows the same switch
    (``ALBOT1_DECODED_CACHE``: another folder, or ``off`` for neither); see
    :mod:`albot1.metrics.reference_map`.
    """
    decoded = decoded_cache_dir()
    return None if decoded is None else decoded / "reference-maps"


@dataclass(frozen=True)
class Settings:
    """Resolved dataset locations; build with :func:`get_settings`."""

    data_dir: Path | None
    cache_dir: Path
    #: Where ``data_dir`` came from, as the user wrote it (named by the error of a data folder that is a file).
    data_dir_origin: str = DATA_DIR_ENV

    def search_roots(self) -> list[Path]:
        """Folders searched for dataset files, most preferred first.

        A data folder that is a file is refused (ConfigError): nothing could
        ever be found under it, so taking it as an empty folder would hide
        the mistake behind a download or another copy. A data folder that
        does not exist yet is searched as empty (:meth:`roots_text` says so).
        """
        roots = [self.data_dir] if self.data_dir is not None else []
        if self.data_dir is not None and self.data_dir.exists() and not self.data_dir.is_dir():
            raise ConfigError(
                f"{self.data_dir_origin}{'=' if self.data_dir_origin == DATA_DIR_ENV else ' '}{self.data_dir}: "
                "a file, not a folder; expected a folder of dataset copies "
                "laid out like radish/, radish-corrected/ (or leave it unset to use the download cache only)"
            )
        roots.append(self.cache_dir)
        return roots

    def roots_text(self) -> str:
        """The search roots for a message, each missing one marked ``(no such folder)`` (a typo shows at once)."""
        return ", ".join(f"{r}{'' if r.is_dir() else ' (no such folder)'}" for r in self.search_roots())


def get_settings(data_dir: str | Path | None = None, cache_dir: str | Path | None = None) -> Settings:
    """Settings from explicit arguments (CLI options), else the environment, else defaults."""
    data = data_dir if data_dir is not None else os.environ.get(DATA_DIR_ENV) or None
    cache = cache_dir if cache_dir is not None else os.environ.get(CACHE_DIR_ENV) or None
    return Settings(
        data_dir=Path(data).expanduser() if data else None,
        cache_dir=Path(cache).expanduser() if cache else _default_cache_dir(),
        data_dir_origin="--data-dir" if data_dir is not None else DATA_DIR_ENV,
    )
