"""The command line on untrusted data and files: one line, a non-zero exit, no traceback, no hang.

Each test runs the real entry point (``albot1.cli.app.main``) in a child
process, so the one-line error handling of ``main`` is what is checked.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import socket
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from albot1.data.loaders.registry import writer_for
from albot1.data.open import open_sequence

WORLD = "synthetic-office-startstop"


def albot1(*args: str, env: dict[str, str] | None = None, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-c", "from albot1.cli.app import main; main()", *args]
    return subprocess.run(
        command, capture_output=True, text=True, timeout=120, env={**os.environ, **(env or {})}, cwd=cwd
    )


def one_line_error(done: subprocess.CompletedProcess[str]) -> str:
    assert done.returncode == 1, (done.stdout, done.stderr)
    assert "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("albot1: error: "), done.stderr
    return lines[0]


def carmen_log(path: Path, scans: int = 40) -> Path:
    writer_for("carmen").write(open_sequence(f"{WORLD}[:{scans}]"), path)
    return path


def project(tmp_path: Path, path: str, sha: str, url: str = "http://127.0.0.1:9/x", size: int | None = None) -> Path:
    folder = tmp_path / "project"
    (folder / "datasets").mkdir(parents=True, exist_ok=True)
    (folder / "datasets" / "tiny.toml").write_text(
        f'name = "tiny"\nformat = "carmen"\n\n[[files]]\nrole = "log"\npath = "{path}"\nsha256 = "{sha}"\n'
        f'urls = ["{url}"]\n' + (f"size = {size}\n" if size is not None else "")
    )
    return folder


def test_a_wrong_catalog_copy_is_refused_with_both_checksums(tmp_path: Path) -> None:
    log = carmen_log(tmp_path / "data" / "radish" / "tiny.clf")
    right = "a" * 64
    env = {
        "ALBOT1_CONFIG_DIR": str(project(tmp_path, "radish/tiny.clf", right)),
        "ALBOT1_DATA_DIR": str(tmp_path / "data"),
    }
    env["ALBOT1_CACHE_DIR"] = str(tmp_path / "cache")
    line = one_line_error(albot1("datasets", "info", "tiny", env=env))
    got = hashlib.sha256(log.read_bytes()).hexdigest()
    assert line == (
        f"albot1: error: {log}: sha256 {got}, but the manifest of dataset 'tiny' "
        f"({tmp_path / 'project' / 'datasets' / 'tiny.toml'}) says {right}; remove it and run "
        "`albot1 datasets fetch tiny`, or replace it with the right file"
    )


def test_datasets_info_names_the_data_checksum(tmp_path: Path) -> None:
    log = carmen_log(tmp_path / "t.clf")
    done = albot1("datasets", "info", str(log), "--json", env={"ALBOT1_CACHE_DIR": str(tmp_path / "cache")})
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["data_sha256"] == {"t.clf": hashlib.sha256(log.read_bytes()).hexdigest()}


@pytest.mark.parametrize(
    ("path", "url", "size", "expected"),
    [
        ("../../escaped.clf", "http://127.0.0.1:9/x", None, "path '../../escaped.clf' must be a relative path"),
        ("/tmp/escaped.clf", "http://127.0.0.1:9/x", None, "path '/tmp/escaped.clf' must be a relative path"),
        ("radish/zero.clf", "file:///dev/zero", 5000, "file:///dev/zero: more than the manifest's size of 5000 bytes"),
    ],
)
@pytest.mark.timeout(120)
def test_a_manifest_cannot_write_outside_the_cache_or_fill_the_disk(
    tmp_path: Path, path: str, url: str, size: int | None, expected: str
) -> None:
    env = {"ALBOT1_CONFIG_DIR": str(project(tmp_path, path, "b" * 64, url, size))}
    env["ALBOT1_CACHE_DIR"] = str(tmp_path / "cache" / "deep")
    line = one_line_error(albot1("datasets", "fetch", "tiny", env=env))
    assert expected in line
    assert not (tmp_path / "escaped.clf").exists() and not Path("/tmp/escaped.clf").exists()


@pytest.mark.slow
@pytest.mark.timeout(120)
def test_special_files_are_refused_up_front_and_never_hang(tmp_path: Path) -> None:
    fifo = tmp_path / "log.clf"
    os.mkfifo(fifo)
    line = one_line_error(albot1("datasets", "info", str(fifo)))
    assert line == (
        f"albot1: error: {fifo}: a FIFO (named pipe), not a regular file; expected a log file or a ROS2 bag folder"
    )
    suite = tmp_path / "s.toml"
    suite.write_text(f'[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "{fifo}"\n')
    line = one_line_error(albot1("bench", str(suite), "--results", str(tmp_path / "r"), "--no-progress"))
    assert line.endswith(f"{fifo}: a FIFO (named pipe), not a regular file; expected a log file or a ROS2 bag folder")
    for special in ("/dev/zero", "/dev/urandom", "/proc/self/environ"):
        line = one_line_error(albot1("datasets", "info", special))
        assert line.startswith(f"albot1: error: {special}: a ") and "not a regular file" in line
        assert "0 bytes)" not in line


def test_an_unrecognised_file_is_described_not_quoted(tmp_path: Path) -> None:
    secret = tmp_path / "passwd"
    secret.write_text("root:x:0:0:root:/root:/bin/bash\n")
    line = one_line_error(albot1("datasets", "info", str(secret)))
    assert "root" not in line.replace(str(tmp_path), "")
    assert f"{secret}:1: the first line that is not a comment (text, 31 characters) begins no known format" in line


@pytest.mark.slow
def test_hand_edited_store_files_are_one_line_naming_file_and_field(tmp_path: Path) -> None:
    results = tmp_path / "results" / "s"
    results.mkdir(parents=True)
    grid = results / "grid.json"
    grid.write_text(
        json.dumps(
            {
                "suite": "s",
                "suite_path": None,
                "description": "",
                "cells": "x",
                "skipped_datasets": [],
                "skipped_methods": [],
                "config_failures": {},
                "seeds": [],
                "degradations": [],
                "machine": {},
            }
        )
    )
    line = one_line_error(albot1("report", str(results), "--out", str(tmp_path / "rep")))
    expected = f"{grid}: not a grid plan written by `albot1 bench`: cells: Input should be a valid list, found x"
    assert line == f"albot1: error: {expected}"


@pytest.mark.slow
def test_a_report_names_the_data_and_escapes_names(tmp_path: Path) -> None:
    log = carmen_log(tmp_path / "<b>bold.clf")
    suite = tmp_path / "s.toml"
    suite.write_text(f'[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "{log}"\n')
    env = {"ALBOT1_CACHE_DIR": str(tmp_path / "cache")}
    done = albot1("bench", str(suite), "--results", str(tmp_path / "r"), "--no-progress", "-j", "1", env=env)
    assert done.returncode == 0, done.stderr
    done = albot1("report", str(tmp_path / "r" / "s"), "--out", str(tmp_path / "rep"), "--no-plots", env=env)
    assert done.returncode == 0, done.stderr
    readme = (tmp_path / "rep" / "README.md").read_text()
    page = (tmp_path / "rep" / "index.html").read_text()
    short = hashlib.sha256(log.read_bytes()).hexdigest()[:12]
    assert "<b>" not in readme and "&lt;b&gt;bold.clf sha256 " + short in readme
    assert "<b>" not in page and f"data: &lt;b&gt;bold.clf sha256 {short}" in page
    tables = (tmp_path / "rep" / "metrics.md").read_text()
    assert "<b>" not in tables and f"Data: &lt;b&gt;bold.clf sha256 {short}." in tables
    result = next((tmp_path / "r" / "s" / "runs").glob("*/result.json"))
    checksums = {log.name: hashlib.sha256(log.read_bytes()).hexdigest()}
    assert json.loads(result.read_text())["dataset_info"]["data_sha256"] == checksums
    assert json.loads((result.parent / "metrics.json").read_text())["run"]["data_sha256"] == checksums


@pytest.mark.slow
def test_a_dataset_edited_after_its_cell_ran_is_run_again_not_kept(tmp_path: Path) -> None:
    log = carmen_log(tmp_path / "t.clf")
    suite = tmp_path / "s.toml"
    suite.write_text(f'[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "{log}"\n')
    args = ("bench", str(suite), "--results", str(tmp_path / "r"), "--no-progress", "-j", "1")
    env = {"ALBOT1_CACHE_DIR": str(tmp_path / "cache")}
    assert albot1(*args, env=env).returncode == 0
    again = albot1(*args, env=env)
    assert again.returncode == 0 and "1 of 1 cells already complete (kept)" in again.stderr
    log.unlink()
    carmen_log(log, scans=30)  # the same file name, other content
    edited = albot1(*args, env=env)
    assert edited.returncode == 0 and "already complete" not in edited.stderr, edited.stderr
    runs = sorted(p.parent.name for p in (tmp_path / "r" / "s" / "runs").glob("*/result.json"))
    assert len(runs) == 2  # the old data's cell is kept apart, under its own key
    scans = [json.loads(p.read_text())["scans"] for p in (tmp_path / "r" / "s" / "runs").glob("*/result.json")]
    assert sorted(scans) == [30, 40]


def test_fetch_says_when_a_wrong_copy_would_still_be_read_first(tmp_path: Path) -> None:
    good = carmen_log(tmp_path / "www" / "radish" / "tiny.clf")
    wrong = carmen_log(tmp_path / "data" / "radish" / "tiny.clf", scans=20)
    sha = hashlib.sha256(good.read_bytes()).hexdigest()
    env = {"ALBOT1_CONFIG_DIR": str(project(tmp_path, "radish/tiny.clf", sha, good.as_uri()))}
    env.update({"ALBOT1_DATA_DIR": str(tmp_path / "data"), "ALBOT1_CACHE_DIR": str(tmp_path / "cache")})
    done = albot1("datasets", "fetch", "tiny", env=env)
    line = one_line_error(done)
    assert done.stdout.strip() == f"tiny: {tmp_path / 'cache' / 'radish' / 'tiny.clf'}"
    assert line.startswith(f"albot1: error: fetched, but the dataset cannot be used yet: {wrong}: sha256 ")
    assert f"a verified copy is at {tmp_path / 'cache' / 'radish' / 'tiny.clf'}" in line


@pytest.mark.timeout(120)
def test_fetch_from_a_port_that_does_not_speak_http_is_one_line(tmp_path: Path) -> None:
    """A reply that is not HTTP (here an SSH banner) used to end ``datasets fetch`` in a traceback."""
    listener = socket.create_server(("127.0.0.1", 0))

    def banner() -> None:
        with contextlib.suppress(OSError):
            connection, _ = listener.accept()
            with connection:
                connection.sendall(b"SSH-2.0-OpenSSH_9.6\r\n\r\n")

    threading.Thread(target=banner, daemon=True).start()
    url = f"http://127.0.0.1:{listener.getsockname()[1]}/tiny.clf"
    env = {"ALBOT1_CONFIG_DIR": str(project(tmp_path, "radish/tiny.clf", "c" * 64, url))}
    env["ALBOT1_CACHE_DIR"] = str(tmp_path / "cache")
    try:
        line = one_line_error(albot1("datasets", "fetch", "tiny", env=env))
    finally:
        listener.close()
    assert line == (
        f"albot1: error: {url}: the reply is not valid HTTP (BadStatusLine: SSH-2.0-OpenSSH_9.6); expected the "
        "dataset file (is the URL's port a web server's?)"
    )
    assert [p.name for p in (tmp_path / "cache" / "radish").iterdir()] == []


@pytest.mark.parametrize("how", ["env", "option"])
def test_a_data_folder_that_is_a_file_is_refused_not_ignored(tmp_path: Path, how: str) -> None:
    """It used to be searched as an empty folder: `fetch` downloaded instead and `list` said "missing (fetch)"."""
    not_a_folder = tmp_path / "datasets.txt"
    not_a_folder.write_text("x\n")
    env = {"ALBOT1_CONFIG_DIR": str(project(tmp_path, "radish/tiny.clf", "c" * 64)), "ALBOT1_CACHE_DIR": str(tmp_path)}
    option: tuple[str, ...] = ("--data-dir", str(not_a_folder)) if how == "option" else ()
    if how == "env":
        env["ALBOT1_DATA_DIR"] = str(not_a_folder)
    named = f"ALBOT1_DATA_DIR={not_a_folder}" if how == "env" else f"--data-dir {not_a_folder}"
    for command in (("datasets", "list"), ("datasets", "fetch", "tiny")):
        assert one_line_error(albot1(*command, *option, env=env)) == (
            f"albot1: error: {named}: a file, not a folder; expected a folder of dataset copies laid out like "
            "radish/, radish-corrected/ (or leave it unset to use the download cache only)"
        )


def test_a_data_folder_that_does_not_exist_is_marked_where_the_roots_are_named(tmp_path: Path) -> None:
    env = {
        "ALBOT1_CONFIG_DIR": str(project(tmp_path, "radish/tiny.clf", "c" * 64)),
        "ALBOT1_DATA_DIR": str(tmp_path / "typo"),
        "ALBOT1_CACHE_DIR": str(tmp_path),
    }
    listing = albot1("datasets", "list", env=env)
    assert listing.returncode == 0 and listing.stdout.splitlines()[-1] == (
        f"searched: {tmp_path / 'typo'} (no such folder), {tmp_path}"
    )
    assert one_line_error(albot1("datasets", "info", "tiny", env=env)) == (
        f"albot1: error: dataset 'tiny': radish/tiny.clf not found under {tmp_path / 'typo'} (no such folder), "
        f"{tmp_path}; run `albot1 datasets fetch tiny` or set ALBOT1_DATA_DIR"
    )
