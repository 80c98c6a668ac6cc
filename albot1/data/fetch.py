"""Verified, atomic downloads of dataset files into the cache.

A file is downloaded with ``urllib`` to a temporary file *in the destination
folder* (so the final ``os.replace`` is a rename on one file system, hence
atomic), its sha256 is computed while streaming, and only a matching file
is renamed into place. Any HTTP/network error or checksum mismatch raises
:class:`~albot1.data.errors.FetchError` and leaves no file behind. A copy
already present under a search root with the right checksum is used as is.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import urllib.error
import urllib.request
from pathlib import Path

from albot1.atomic import normal_mode
from albot1.data.errors import FetchError
from albot1.data.manifest import DataFile
from albot1.settings import Settings

_BLOCK = 1 << 20
TIMEOUT_S = 60.0


def sha256_of(path: Path) -> str:
    """Hex sha256 of a file, read in 1 MiB blocks."""
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(_BLOCK), b""):
            digest.update(block)
    return digest.hexdigest()


def download_verified(url: str, dest: Path, sha256: str, *, timeout: float = TIMEOUT_S) -> Path:
    """Download ``url`` to ``dest`` if its sha256 matches; atomic; FetchError otherwise."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(dir=dest.parent, prefix=f".{dest.name}.", suffix=".part")
    tmp = Path(tmp_name)
    try:
        digest = hashlib.sha256()
        try:
            with os.fdopen(fd, "wb") as out, urllib.request.urlopen(url, timeout=timeout) as response:
                for block in iter(lambda: response.read(_BLOCK), b""):
                    digest.update(block)
                    out.write(block)
        except urllib.error.HTTPError as exc:
            raise FetchError(f"{url}: HTTP {exc.code} {exc.reason}; expected the dataset file") from None
        except (urllib.error.URLError, OSError, ValueError) as exc:
            reason = getattr(exc, "reason", exc)
            raise FetchError(f"{url}: download failed ({reason})") from None
        got = digest.hexdigest()
        if got != sha256:
            raise FetchError(f"{url}: sha256 {got} does not match the manifest's {sha256}; file discarded")
        os.chmod(tmp, normal_mode())  # mkstemp's file is private (0o600); a dataset file is not
        os.replace(tmp, dest)
        return dest
    finally:
        tmp.unlink(missing_ok=True)


def ensure_file(data_file: DataFile, urls: tuple[str, ...], settings: Settings) -> Path:
    """A verified local copy of ``data_file``: an existing one, else downloaded into the cache."""
    for root in settings.search_roots():
        candidate = root / data_file.path
        if candidate.is_file() and sha256_of(candidate) == data_file.sha256:
            return candidate
    if not urls:
        raise FetchError(f"{data_file.path}: no verified local copy and no download URL in the manifest")
    errors = []
    for url in urls:
        try:
            return download_verified(url, settings.cache_dir / data_file.path, data_file.sha256)
        except FetchError as exc:
            errors.append(str(exc))
    raise FetchError("; ".join(errors))
