"""Catalog files verified on use, fetched files confined to the cache, downloads limited in size."""

from __future__ import annotations

import hashlib
import http.server
import os
import threading
import time
from pathlib import Path

import pytest

from albot1.data import catalog, fetch
from albot1.data.errors import ChecksumError, DataError, FetchError
from albot1.data.manifest import parse_manifest
from albot1.data.open import open_sequence
from albot1.runs.folder import run_key
from albot1.settings import Settings

PAYLOAD = b"FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1.0 host 1.0\n" * 50
WRONG = b"FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1.0 host 1.0\n" * 20
SHA = hashlib.sha256(PAYLOAD).hexdigest()


#: every test here in its own config folder and checksum cache (the root conftest.py's own_project)
pytestmark = pytest.mark.usefixtures("own_project")


def manifest(
    tmp_path: Path, *, path: str = "radish/tiny.clf", url: str = "http://127.0.0.1:9/x", size: str = ""
) -> Path:
    folder = tmp_path / "project" / "datasets"
    folder.mkdir(parents=True, exist_ok=True)
    (tmp_path / "project" / "baselines").mkdir(exist_ok=True)
    toml = folder / "tiny.toml"
    toml.write_text(
        f'name = "tiny"\nformat = "carmen"\n\n[[files]]\nrole = "log"\npath = "{path}"\nsha256 = "{SHA}"\n'
        f'urls = ["{url}"]\n{size}\n[loader]\nodometry = "laser-pose"\n'
    )
    return toml


def put(root: Path, data: bytes) -> Path:
    target = root / "radish" / "tiny.clf"
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_bytes(data)
    return target


def test_a_verified_copy_opens_and_names_its_checksum(tmp_path: Path) -> None:
    manifest(tmp_path)
    put(tmp_path / "data", PAYLOAD)
    sequence = open_sequence("tiny[:5]", settings=Settings(tmp_path / "data", tmp_path / "cache"))
    assert sequence.metadata.checksums == {"tiny.clf": SHA}


def test_a_wrong_copy_in_the_data_folder_never_wins_over_the_verified_cache_copy(tmp_path: Path) -> None:
    toml = manifest(tmp_path)
    wrong = put(tmp_path / "data", WRONG)
    good = put(tmp_path / "cache", PAYLOAD)
    with pytest.raises(ChecksumError) as caught:
        open_sequence("tiny", settings=Settings(tmp_path / "data", tmp_path / "cache"))
    assert str(caught.value) == (
        f"{wrong}: sha256 {hashlib.sha256(WRONG).hexdigest()}, but the manifest of dataset 'tiny' ({toml}) says "
        f"{SHA}; a verified copy is at {good}: remove or replace the wrong one (or point ALBOT1_DATA_DIR elsewhere)"
    )


def test_a_wrong_copy_alone_says_how_to_fetch_the_right_one(tmp_path: Path) -> None:
    manifest(tmp_path)
    put(tmp_path / "cache", WRONG)
    with pytest.raises(ChecksumError, match=r"remove it and run `albot1 datasets fetch tiny`"):
        catalog.locate("tiny", Settings(None, tmp_path / "cache"))


def test_a_path_dataset_edited_after_its_run_gets_a_new_key(tmp_path: Path) -> None:
    log = put(tmp_path, PAYLOAD)
    first = open_sequence(str(log)).metadata.checksums
    log.write_bytes(WRONG)
    stamp = time.time() + 5  # a later mtime, as an edit gives
    os.utime(log, (stamp, stamp))
    second = open_sequence(str(log)).metadata.checksums
    assert first == {"tiny.clf": SHA} and second == {"tiny.clf": hashlib.sha256(WRONG).hexdigest()}
    keys = {run_key(str(log), "odometry", {}, "none", 0, {"code": "v"}, data) for data in (first, second)}
    assert len(keys) == 2
    assert run_key("w", "odometry", {}, "none", 0, {"code": "v"}, {}) == run_key(
        "w", "odometry", {}, "none", 0, {"code": "v"}
    )


@pytest.mark.parametrize(
    "bad", ["../../../x", "/etc/x", "radish/../../x", "~/x", "./x", "a//x", "radish\\\\x", "", "a/"]
)
def test_a_manifest_path_outside_the_data_folder_is_refused(tmp_path: Path, bad: str) -> None:
    toml = manifest(tmp_path, path=bad)
    with pytest.raises(DataError, match=r"files\[0\]: path .* must be a relative path inside the data folder"):
        parse_manifest(toml)


def test_a_symlink_in_the_cache_cannot_lead_a_download_out_of_it(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    cache.mkdir()
    outside = tmp_path / "outside"
    outside.mkdir()
    (cache / "radish").symlink_to(outside)
    with pytest.raises(
        FetchError, match=r"radish/tiny.clf: resolves to .*outside/tiny.clf, outside the download cache"
    ):
        fetch.confined(cache, "radish/tiny.clf")
    assert fetch.confined(cache, "other/tiny.clf") == cache / "other" / "tiny.clf"


@pytest.mark.timeout(30)
def test_an_endless_download_stops_at_the_manifest_size(tmp_path: Path) -> None:
    with pytest.raises(FetchError, match=r"file:///dev/zero: more than the manifest's size of 1000 bytes; download"):
        fetch.download_verified("file:///dev/zero", tmp_path / "dl" / "f", SHA, size=1000)
    assert list((tmp_path / "dl").iterdir()) == []


@pytest.mark.timeout(30)
def test_an_endless_download_without_a_size_stops_at_the_default_limit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(fetch, "DEFAULT_MAX_BYTES", 3 * 1024 * 1024)
    with pytest.raises(FetchError, match=r"more than the default limit of 3145728 bytes; download stopped"):
        fetch.download_verified("file:///dev/zero", tmp_path / "dl" / "f", SHA)
    assert list((tmp_path / "dl").iterdir()) == []


class _Endless(http.server.BaseHTTPRequestHandler):
    announce = True

    def do_GET(self) -> None:  # noqa: N802 (http.server API)
        self.send_response(200)
        if type(self).announce:
            self.send_header("Content-Length", str(10**12))
        self.end_headers()
        try:
            for _ in range(10_000):
                self.wfile.write(b"\0" * 65536)
        except OSError:
            pass

    def log_message(self, *args: object) -> None:
        pass


@pytest.mark.timeout(60)
@pytest.mark.parametrize("announce", [True, False])
def test_a_server_sending_more_than_the_size_is_cut_off(tmp_path: Path, announce: bool) -> None:
    _Endless.announce = announce
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Endless)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    url = f"http://127.0.0.1:{httpd.server_address[1]}/log"
    try:
        expected = "announces 1000000000000 bytes, more than" if announce else "more than the manifest's size"
        with pytest.raises(FetchError, match=expected):
            fetch.download_verified(url, tmp_path / "dl" / "f", SHA, size=4096)
    finally:
        httpd.shutdown()
        httpd.server_close()
    assert list((tmp_path / "dl").iterdir()) == []


def test_a_short_download_names_both_sizes(tmp_path: Path) -> None:
    source = tmp_path / "src.clf"
    source.write_bytes(PAYLOAD)
    with pytest.raises(FetchError, match=rf"{len(PAYLOAD)} bytes, but the manifest's size is {len(PAYLOAD) + 1}"):
        fetch.download_verified(source.as_uri(), tmp_path / "out" / "f", SHA, size=len(PAYLOAD) + 1)
    assert (
        fetch.download_verified(source.as_uri(), tmp_path / "out" / "f", SHA, size=len(PAYLOAD)).read_bytes() == PAYLOAD
    )


def test_the_catalog_listing_names_a_wrong_copy(tmp_path: Path) -> None:
    manifest(tmp_path)
    settings = Settings(None, tmp_path / "cache")
    assert catalog.copy_problem("tiny", settings) is None  # missing is not a wrong copy
    put(tmp_path / "cache", PAYLOAD)
    assert catalog.copy_problem("tiny", settings) is None
    put(tmp_path / "cache", WRONG)
    problem = catalog.copy_problem("tiny", settings)
    assert problem is not None and problem.startswith(f"{tmp_path / 'cache' / 'radish' / 'tiny.clf'}: sha256 ")
    assert SHA in problem


CATALOG_RELATIONS = b"1.0 2.0 0.5 0 0 0 0 0\n1.0 2.0 0.5 0 0 0 0 0\n"  # a repeated line: reading it warns


def test_a_relations_option_replaces_the_catalogs_file_unread(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """``NAME?relations=FILE`` reads FILE only: the catalog's own file is not read, warned about nor in the key."""
    toml = manifest(tmp_path)
    toml.write_text(
        toml.read_text() + f'\n[[files]]\nrole = "relations"\npath = "radish/tiny.relations"\n'
        f'sha256 = "{hashlib.sha256(CATALOG_RELATIONS).hexdigest()}"\nurls = ["http://127.0.0.1:9/r"]\n'
    )
    put(tmp_path / "data", PAYLOAD)
    (tmp_path / "data" / "radish" / "tiny.relations").write_bytes(CATALOG_RELATIONS)
    own = tmp_path / "own.relations"
    own.write_text("1.0 3.0 0.25 0 0 0 0 0\n")
    settings = Settings(tmp_path / "data", tmp_path / "cache")
    assert len(open_sequence("tiny", settings=settings).relations or ()) == 1  # the catalog's, its repeat said
    assert "repeat an earlier line" in caplog.text
    caplog.clear()
    sequence = open_sequence(f"tiny?relations={own}", settings=settings)
    assert sequence.relations is not None and sequence.relations.t2.tolist() == [3.0]
    assert sequence.metadata.checksums == {
        "tiny.clf": SHA,
        "own.relations": hashlib.sha256(own.read_bytes()).hexdigest(),
    }
    # Nothing said of relations (the 3-beam FLASER log's geometry warning comes from the CARMEN loader).
    assert [r.getMessage() for r in caplog.records if r.name != "albot1.data.loaders.carmen.loader"] == []
    (tmp_path / "data" / "radish" / "tiny.relations").unlink()  # not even looked for
    assert open_sequence(f"tiny?relations={own}", settings=settings).relations is not None


@pytest.mark.timeout(30)
@pytest.mark.parametrize("special", ["fifo", "/dev/zero", "folder"])
def test_a_relations_option_naming_a_special_file_is_refused_before_reading(tmp_path: Path, special: str) -> None:
    log = put(tmp_path, PAYLOAD)
    target = {"fifo": tmp_path / "p", "/dev/zero": Path("/dev/zero"), "folder": tmp_path}[special]
    if special == "fifo":
        os.mkfifo(target)
    with pytest.raises(
        DataError, match=rf"^{target}: a .*, not a regular file; expected a regular file for the option"
    ):
        open_sequence(f"{log}?relations={target}")


@pytest.mark.timeout(30)
def test_a_bag_folder_holding_a_fifo_is_refused_before_its_loader_opens_it(tmp_path: Path) -> None:
    bag = tmp_path / "bag"
    bag.mkdir()
    os.mkfifo(bag / "metadata.yaml")
    (bag / "bag_0.db3").write_bytes(b"")
    with pytest.raises(DataError) as caught:
        open_sequence(str(bag))
    assert str(caught.value) == (
        f"{bag / 'metadata.yaml'}: a FIFO (named pipe) inside the bag folder {bag}; expected regular files only"
    )
