"""Verified, atomic downloads of dataset files into the cache.

A file is downloaded with ``urllib`` to a temporary file *in the destination
folder* (so the final ``os.replace`` is a rename on one file system, hence
atomic), its sha256 is computed while streaming, and only a matching file
is renamed into place. The file stays inside the cache folder (also after
resolving symlinks) and the download stops at the manifest's ``size`` (or
:data:`DEFAULT_MAX_BYTES`). Any HTTP/network error, size or checksum mismatch raises
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
from albot1.data.identity import content_sha256
from albot1.data.manifest import DataFile
from albot1.settings import Settings

_BLOCK = 1 << 20
TIMEOUT_S = 60.0
#: The most a download may write when its manifest entry gives no ``size`` (the largest public log of the
#: catalog is about 60 MB): a URL that never ends (``file:///dev/zero``) stops here, not at a full disk.
DEFAULT_MAX_BYTES = 2 * 1024**3


def sha256_of(path: Path) -> str:
    """Hex sha256 of a file (cached by its stat; :func:`albot1.data.identity.content_sha256`)."""
    return content_sha256(path, folder_ok=False)


def confined(root: Path, relative: str) -> Path:
    """``root / relative``, refused (FetchError) unless it stays inside ``root`` after resolving symlinks.

    A manifest's path is checked when it is parsed (no ``..``, not
    absolute); a symlink inside the cache that points elsewhere would still
    lead a write out of it, which this check catches.
    """
    dest = root / relative
    base = root.resolve()
    resolved = dest.resolve()
    if resolved == base or not resolved.is_relative_to(base):
        raise FetchError(
            f"{relative}: resolves to {resolved}, outside the download cache {base}; a fetched file must stay "
            "inside the cache (remove the symlink, or fix the manifest's path)"
        )
    return dest


def download_verified(
    url: str, dest: Path, sha256: str, *, size: int | None = None, timeout: float = TIMEOUT_S
) -> Path:
    """Download ``url`` to ``dest`` if its sha256 matches; atomic; FetchError otherwise.

    The download stops with a FetchError once it exceeds ``size`` (the
    manifest's byte count) or, when no size is given, :data:`DEFAULT_MAX_BYTES`.
    """
    limit = size if size is not None else DEFAULT_MAX_BYTES
    what = f"the manifest's size of {limit} bytes" if size is not None else f"the default limit of {limit} bytes"
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(dir=dest.parent, prefix=f".{dest.name}.", suffix=".part")
    tmp = Path(tmp_name)
    try:
        digest = hashlib.sha256()
        written = 0
        try:
            with os.fdopen(fd, "wb") as out, urllib.request.urlopen(url, timeout=timeout) as response:
                announced = response.headers.get("Content-Length") if response.headers else None
                if announced is not None and announced.isdigit() and int(announced) > limit:
                    raise FetchError(f"{url}: the server announces {announced} bytes, more than {what}; not downloaded")
                while block := response.read(min(_BLOCK, limit + 1 - written)):
                    written += len(block)
                    if written > limit:
                        raise FetchError(f"{url}: more than {what}; download stopped and discarded")
                    digest.update(block)
                    out.write(block)
        except urllib.error.HTTPError as exc:
            raise FetchError(f"{url}: HTTP {exc.code} {exc.reason}; expected the dataset file") from None
        except (urllib.error.URLError, OSError, ValueError) as exc:
            reason = getattr(exc, "reason", exc)
            raise FetchError(f"{url}: download failed ({reason})") from None
        if size is not None and written != size:
            raise FetchError(f"{url}: {written} bytes, but the manifest's size is {size}; file discarded")
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
    settings.cache_dir.mkdir(parents=True, exist_ok=True)
    dest = confined(settings.cache_dir, data_file.path)
    errors = []
    for url in urls:
        try:
            return download_verified(url, dest, data_file.sha256, size=data_file.size)
        except FetchError as exc:
            errors.append(str(exc))
    raise FetchError("; ".join(errors))
