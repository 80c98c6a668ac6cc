"""Fetching against a local HTTP server on 127.0.0.1: verified, atomic, no re-download, clean failures."""

from __future__ import annotations

import hashlib
import http.server
import threading
from collections.abc import Iterator
from functools import partial
from pathlib import Path

import pytest

from albot1.data import catalog
from albot1.data.errors import FetchError
from albot1.data.fetch import download_verified
from albot1.settings import Settings

PAYLOAD = b"FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1.0 host 1.0\n" * 50


class _Handler(http.server.SimpleHTTPRequestHandler):
    requests: list[str] = []

    def do_GET(self) -> None:  # noqa: N802 (http.server API)
        type(self).requests.append(self.path)
        super().do_GET()

    def log_message(self, *args: object) -> None:
        pass


@pytest.fixture
def server(tmp_path: Path) -> Iterator[tuple[str, Path, list[str]]]:
    root = tmp_path / "www"
    (root / "radish").mkdir(parents=True)
    (root / "radish" / "tiny.clf").write_bytes(PAYLOAD)
    _Handler.requests = []
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), partial(_Handler, directory=str(root)))
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{httpd.server_address[1]}", root, _Handler.requests
    finally:
        httpd.shutdown()
        httpd.server_close()


def _manifest(tmp_path: Path, url: str, sha: str) -> None:
    project = tmp_path / "project"
    (project / "baselines").mkdir(parents=True)
    (project / "datasets").mkdir()
    (project / "datasets" / "tiny.toml").write_text(
        f'name = "tiny"\ndescription = "test"\nformat = "carmen"\nlicense = "CC0"\ncitation = "none"\n\n'
        f'[[files]]\nrole = "log"\npath = "radish/tiny.clf"\nsha256 = "{sha}"\nurls = ["{url}"]\n\n'
        f'[loader]\nodometry = "laser-pose"\n'
    )


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    monkeypatch.setenv("ALBOT1_CONFIG_DIR", str(tmp_path / "project"))
    catalog._manifests.cache_clear()
    yield tmp_path / "project"
    catalog._manifests.cache_clear()


def leftovers(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.name.startswith(".")]


def test_fetch_downloads_verifies_and_then_reuses(server, project, tmp_path: Path) -> None:
    base, _, requests = server
    _manifest(tmp_path, f"{base}/radish/tiny.clf", hashlib.sha256(PAYLOAD).hexdigest())
    settings = Settings(data_dir=None, cache_dir=tmp_path / "cache")
    path = catalog.fetch("tiny", settings)
    assert path == tmp_path / "cache" / "radish" / "tiny.clf" and path.read_bytes() == PAYLOAD
    assert catalog.fetch("tiny", settings) == path
    assert requests == ["/radish/tiny.clf"]  # the second fetch found the verified copy
    assert len(list(catalog.open_dataset("tiny", settings))) == 50


def test_bad_checksum_leaves_nothing(server, project, tmp_path: Path) -> None:
    base, _, _ = server
    _manifest(tmp_path, f"{base}/radish/tiny.clf", "0" * 64)
    cache = tmp_path / "cache"
    with pytest.raises(FetchError, match="sha256 .* does not match the manifest's 0000"):
        catalog.fetch("tiny", Settings(data_dir=None, cache_dir=cache))
    assert not (cache / "radish" / "tiny.clf").exists() and not leftovers(cache)


def test_http_error_and_base_url(server, project, tmp_path: Path) -> None:
    base, _, requests = server
    _manifest(tmp_path, f"{base}/missing/tiny.clf", hashlib.sha256(PAYLOAD).hexdigest())
    cache = tmp_path / "cache"
    with pytest.raises(FetchError, match="HTTP 404"):
        catalog.fetch("tiny", Settings(data_dir=None, cache_dir=cache))
    assert not leftovers(cache)
    path = catalog.fetch("tiny", Settings(data_dir=None, cache_dir=cache), base_url=base + "/")
    assert path.read_bytes() == PAYLOAD and requests[-1] == "/radish/tiny.clf"


def test_copy_in_data_dir_is_used_without_download(server, project, tmp_path: Path) -> None:
    base, root, requests = server
    _manifest(tmp_path, f"{base}/radish/tiny.clf", hashlib.sha256(PAYLOAD).hexdigest())
    assert catalog.fetch("tiny", Settings(data_dir=root, cache_dir=tmp_path / "cache")) == root / "radish/tiny.clf"
    assert requests == []


def test_unreachable_host_is_a_fetch_error(tmp_path: Path) -> None:
    with pytest.raises(FetchError, match="download failed"):
        download_verified("http://127.0.0.1:9/none", tmp_path / "f", "0" * 64, timeout=2)
    assert list(tmp_path.iterdir()) == []


def test_base_url_percent_encodes_a_path_with_a_space_or_an_accent(server, project, tmp_path: Path) -> None:
    """``base_url/<path>`` used to be sent as typed: urllib refuses a space, so such a file never came from a mirror."""
    base, root, requests = server
    (root / "radish" / "ti ny é.clf").write_bytes(PAYLOAD)
    _manifest(tmp_path, "http://127.0.0.1:9/x", hashlib.sha256(PAYLOAD).hexdigest())
    toml = tmp_path / "project" / "datasets" / "tiny.toml"
    toml.write_text(toml.read_text().replace("radish/tiny.clf", "radish/ti ny é.clf"))
    path = catalog.fetch("tiny", Settings(data_dir=None, cache_dir=tmp_path / "cache"), base_url=base)
    assert path == tmp_path / "cache" / "radish" / "ti ny é.clf" and path.read_bytes() == PAYLOAD
    assert requests == ["/radish/ti%20ny%20%C3%A9.clf"]
