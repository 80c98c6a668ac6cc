"""Verified, atomic downloads of dataset files into the cache.

A file is downloaded with ``urllib`` to a temporary file *in the destination
folder* (so the final ``os.replace`` is a rename on one file system, hence
atomic), its sha256 is computed while streaming, and only a matching file
is renamed into place. The file stays inside the cache folder (also after
resolving symlinks) and the download stops at the manifest's ``size`` (or
:data:`DEFAULT_MAX_BYTES`). Any HTTP/network error, size or checksum mismatch raises
:class:`~albot1.data.errors.FetchError` and leaves no file behind. A copy
already present under a search root with the right checksum is used as is.

A refused download says what arrived, in one line: a connection closed
before the announced length, an HTML page (a proxy's login or error page),
a reply that is not HTTP, a server silent for :data:`TIMEOUT_S`, a redirect
loop; a disk that fills up names the file being written, not the URL.
The part file of a fetch killed with SIGKILL is removed by the next fetch
of that file (:func:`_claim_part`).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import glob
import hashlib
import http.client
import os
import stat
import tempfile
import urllib.error
import urllib.request
from pathlib import Path
from typing import IO, NamedTuple

from albot1.atomic import normal_mode
from albot1.data.errors import FetchError
from albot1.data.identity import content_sha256
from albot1.data.manifest import DataFile
from albot1.settings import Settings

_BLOCK = 1 << 20
#: How many first bytes of a reply are kept to tell an HTML page (:data:`_HTML_STARTS`) from a dataset file.
_HEAD_BYTES = 64
_HTML_STARTS = (b"<!doctype html", b"<html")
TIMEOUT_S = 60.0
#: The most a download may write when its manifest entry gives no ``size`` (the largest public log of the
#: catalog is about 60 MB): a URL that never ends (``file:///dev/zero``) stops here, not at a full disk.
DEFAULT_MAX_BYTES = 2 * 1024**3


class _Received(NamedTuple):
    """What one download brought: its length, sha256, announced length and content type."""

    written: int
    sha256: str
    announced: int | None
    content_type: str
    #: the first bytes of the reply (an HTML page served as application/octet-stream is told by them)
    head: bytes = b""


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


def _reason(exc: BaseException) -> str:
    """The error's reason on one line (urllib's redirect-loop message spans three), without ``[Errno N]``."""
    reason = getattr(exc, "reason", None) or exc
    text = reason.strerror if isinstance(reason, OSError) and reason.strerror else str(reason)
    return " ".join(text.split()) or type(reason).__name__


def _unwritable(path: Path, exc: OSError, doing: str) -> FetchError:
    """The one line for a local write that failed (full disk, read-only or missing folder): it names ``path``."""
    fix = "free space there" if exc.errno == errno.ENOSPC else "make it writable"
    return FetchError(
        f"{path}: cannot {doing} ({_reason(exc).lower()}); nothing kept -- {fix}, or set ALBOT1_CACHE_DIR "
        "to another folder"
    )


def make_folder(folder: Path) -> None:
    """``folder`` and its parents, or a FetchError naming it (a file in the way, a read-only file system)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise FetchError(
            f"{folder}: a file is in the way; expected a folder for the downloads (set ALBOT1_CACHE_DIR)"
        ) from None
    except OSError as exc:
        raise _unwritable(folder, exc, "create the download folder") from None


def _write(out: IO[bytes], block: bytes | None, dest: Path) -> None:
    """Write ``block`` (None: flush); an OSError becomes a FetchError naming ``dest``."""
    try:
        if block is None:
            out.flush()
        else:
            out.write(block)
    except OSError as exc:
        raise _unwritable(dest, exc, "write the download") from None


def _receive(url: str, out: IO[bytes], dest: Path, limit: int, what: str, timeout: float) -> _Received:
    """Stream ``url`` into ``out`` (at most ``limit`` bytes); FetchError for every network or HTTP failure."""
    digest = hashlib.sha256()
    written = 0
    head = b""
    try:
        with urllib.request.urlopen(url, timeout=timeout) as response:
            headers = response.headers
            announced = headers.get("Content-Length") if headers else None
            length = int(announced) if announced is not None and announced.isdigit() else None
            if length is not None and length > limit:
                raise FetchError(f"{url}: the server announces {announced} bytes, more than {what}; not downloaded")
            while block := response.read(min(_BLOCK, limit + 1 - written)):
                written += len(block)
                if written > limit:
                    raise FetchError(f"{url}: more than {what}; download stopped and discarded")
                digest.update(block)
                head = head or block[:_HEAD_BYTES]
                _write(out, block, dest)
            _write(out, None, dest)
            content_type = headers.get_content_type() if headers and "Content-Type" in headers else ""
    except urllib.error.HTTPError as exc:
        exc.close()  # the error holds the reply and its socket; left open, it is only freed (with a warning) by gc
        if 300 <= exc.code < 400:
            raise FetchError(
                f"{url}: HTTP {exc.code}, a redirect loop or too many redirects; expected the dataset file"
            ) from None
        raise FetchError(f"{url}: HTTP {exc.code} {_reason(exc)}; expected the dataset file") from None
    except (TimeoutError, urllib.error.URLError) as exc:
        if isinstance(exc, TimeoutError) or isinstance(getattr(exc, "reason", None), TimeoutError):
            raise FetchError(
                f"{url}: no data from the server for {timeout:g} s after {written} bytes (timed out); "
                "download discarded -- retry, or use a mirror (--base-url)"
            ) from None
        raise FetchError(f"{url}: download failed ({_reason(exc)})") from None
    except http.client.InvalidURL as exc:
        raise FetchError(f"{url}: not a valid URL ({_reason(exc)}); expected a URL of the dataset file") from None
    except http.client.IncompleteRead:
        raise FetchError(
            f"{url}: the connection closed in the middle of the body after {written} bytes; download discarded (retry)"
        ) from None
    except http.client.HTTPException as exc:
        raise FetchError(
            f"{url}: the reply is not valid HTTP ({type(exc).__name__}: {_reason(exc)[:80]}); expected the dataset "
            "file (is the URL's port a web server's?)"
        ) from None
    except (OSError, ValueError) as exc:
        raise FetchError(f"{url}: download failed after {written} bytes ({_reason(exc)})") from None
    return _Received(written, digest.hexdigest(), length, content_type, head)


def _refusal(url: str, got: _Received, sha256: str, size: int | None) -> str:
    """Why a download that does not match the manifest is refused: the most telling fact first."""
    if got.announced is not None and got.written < got.announced:
        return (
            f"{url}: the connection closed after {got.written} of the {got.announced} bytes the server announced; "
            "file discarded (retry)"
        )
    if got.written == 0:
        return f"{url}: the server sent an empty reply (0 bytes), not the dataset file; nothing kept"
    if not url.lower().endswith((".html", ".htm")):
        # by its Content-Type, or by its first bytes when a server labels every reply application/octet-stream
        # (that used to be only "sha256 ... does not match", not saying a web page had arrived)
        label = f"Content-Type {got.content_type}" if got.content_type == "text/html" else None
        if label is None and got.head.lstrip().lower().startswith(_HTML_STARTS):
            label = f"Content-Type {got.content_type or 'not given'}, but it starts {got.head.lstrip()[:15]!r}"
        if label is not None:
            return (
                f"{url}: the server sent an HTML page ({got.written} bytes, {label}), not the dataset "
                "file (a proxy's login or error page?); file discarded"
            )
    if size is not None and got.written != size:
        return f"{url}: {got.written} bytes, but the manifest's size is {size}; file discarded"
    return f"{url}: sha256 {got.sha256} does not match the manifest's {sha256}; file discarded"


def download_verified(
    url: str, dest: Path, sha256: str, *, size: int | None = None, timeout: float = TIMEOUT_S
) -> Path:
    """Download ``url`` to ``dest`` if its sha256 matches; atomic; FetchError otherwise.

    The download stops with a FetchError once it exceeds ``size`` (the
    manifest's byte count) or, when no size is given, :data:`DEFAULT_MAX_BYTES`.
    A file whose length and sha256 match is taken even when the server
    announced another length: the checksum, not the headers, says it is the file.
    """
    limit = size if size is not None else DEFAULT_MAX_BYTES
    what = f"the manifest's size of {limit} bytes" if size is not None else f"the default limit of {limit} bytes"
    make_folder(dest.parent)
    try:
        fd, tmp = _claim_part(dest)
    except OSError as exc:
        raise _unwritable(dest, exc, "write the download") from None
    held = os.dup(fd)  # keeps the part's lock until it is renamed or removed (closing ``out`` does not)
    try:
        with os.fdopen(fd, "wb") as out:
            got = _receive(url, out, dest, limit, what, timeout)
        if got.sha256 != sha256 or (size is not None and got.written != size):
            raise FetchError(_refusal(url, got, sha256, size))
        try:
            os.chmod(tmp, normal_mode())  # mkstemp's file is private (0o600); a dataset file is not
            os.replace(tmp, dest)
        except OSError as exc:
            raise _unwritable(dest, exc, "put the verified download in place") from None
        return dest
    finally:
        tmp.unlink(missing_ok=True)
        os.close(held)


def _claim_part(dest: Path) -> tuple[int, Path]:
    """A new ``.NAME.*.part`` beside ``dest``, locked by this process; leftovers of killed fetches removed first.

    A fetch killed by SIGKILL (or a power cut) cannot remove its part file;
    its ``flock`` went with the process, so a part nobody holds is such a
    leftover and is removed (it is never read: only a verified file is
    renamed to ``dest``). The folder's own lock makes "remove the unheld
    parts" and "create and lock a new one" one step, so a concurrent fetch's
    part is never taken for a leftover.
    """
    folder = os.open(dest.parent, os.O_RDONLY)
    try:
        try:
            fcntl.flock(folder, fcntl.LOCK_EX)
        except OSError:  # a file system without locks (some NFS setups): leftovers stay, as before
            pass
        else:
            for part in dest.parent.glob(f".{glob.escape(dest.name)}.*.part"):
                _remove_if_unheld(part)
        fd, name = tempfile.mkstemp(dir=dest.parent, prefix=f".{dest.name}.", suffix=".part")
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return fd, Path(name)
    finally:
        os.close(folder)  # releases the folder's lock


def _remove_if_unheld(part: Path) -> None:
    """Remove ``part`` unless a running fetch holds its lock (a symlink or a folder is left alone)."""
    try:
        fd = os.open(part, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return  # another fetch is writing it (or the file system cannot tell)
        part.unlink(missing_ok=True)
    finally:
        os.close(fd)


def ensure_file(data_file: DataFile, urls: tuple[str, ...], settings: Settings) -> Path:
    """A verified local copy of ``data_file``: an existing one, else downloaded into the cache."""
    for root in settings.search_roots():
        candidate = root / data_file.path
        if candidate.is_file() and sha256_of(candidate) == data_file.sha256:
            return candidate
    if not urls:
        raise FetchError(f"{data_file.path}: no verified local copy and no download URL in the manifest")
    make_folder(settings.cache_dir)
    dest = confined(settings.cache_dir, data_file.path)
    errors = []
    for url in urls:
        try:
            return download_verified(url, dest, data_file.sha256, size=data_file.size)
        except FetchError as exc:
            errors.append(str(exc))
    raise FetchError("; ".join(errors))
