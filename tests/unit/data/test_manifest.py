"""The manifest parser: each kind of bad input is one DataError naming the file, the line, the entry and the key."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.data.errors import DataError
from albot1.data.manifest import parse_manifest

SHA = "ab" * 32
GOOD = f'name = "lab"\nformat = "carmen"\n\n[[files]]\nrole = "log"\npath = "mine/lab.clf"\nsha256 = "{SHA}"\n'


RELATIONS = f'[[files]]\nrole = "relations"\npath = "mine/lab.relations"\nsha256 = "{SHA}"\n'


def test_a_relations_file_may_declare_how_repeated_lines_count(tmp_path: Path) -> None:
    assert parse_manifest(write(tmp_path, GOOD + RELATIONS)).file("relations").repeats is None  # type: ignore[union-attr]
    declared = parse_manifest(write(tmp_path, GOOD + RELATIONS + 'repeats = "keep"\n')).file("relations")
    assert declared is not None and declared.repeats == "keep"


def write(tmp_path: Path, text: str, name: str = "lab") -> Path:
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_minimal_manifest_gets_the_documented_defaults(tmp_path: Path) -> None:
    path = write(tmp_path, GOOD)
    manifest = parse_manifest(path)
    assert (manifest.name, manifest.format, manifest.local_only, manifest.loader) == ("lab", "carmen", False, {})
    assert manifest.log.path == "mine/lab.clf" and manifest.log.urls == () and manifest.log.size is None
    assert manifest.file("relations") is None and manifest.manifest_path == path


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("name = [", r"lab.toml: not a readable TOML manifest"),
        ('name = "other"\nfiles = []', r"lab.toml:1: name 'other' must equal the file name 'lab'"),
        ('name = "lab"', r"lab.toml: key 'files' must be a array, found nothing"),
        ('name = "lab"\nfiles = [1]', r"lab.toml:2 files\[0\]: expected a \[\[files\]\] table, got int"),
        ('name = "lab"\nfiles = []', r'lab.toml:2: expected exactly one file with role = "log"'),
        (GOOD.replace('role = "log"', 'role = "map"'), r"lab.toml:5 files\[0\]: role 'map'; expected one of log"),
        (GOOD.replace(SHA, "xyz"), r"lab.toml:7 files\[0\]: sha256 must be 64 hex digits"),
        (GOOD + 'urls = "https://x"\n', r"lab.toml:8 files\[0\]: key 'urls' must be a array, found a string"),
        (GOOD + "urls = [1]\n", r"lab.toml:8 files\[0\]: key 'urls' must be a list of strings"),
        (GOOD + "size = true\n", r"lab.toml:8 files\[0\]: key 'size' must be a integer, found a boolean"),
        ('local_only = "yes"\n' + GOOD, r"lab.toml:1: key 'local_only' must be a boolean, found a string"),
        ('loader = "carmen"\n' + GOOD, r"lab.toml:1: key 'loader' must be a table, found a string"),
        ("description = 3\n" + GOOD, r"lab.toml:1: key 'description' must be a string, found a integer"),
        (GOOD + 'repeats = "keep"\n', r"lab.toml:8 files\[0\]: repeats goes with role = \"relations\", not 'log'"),
        (GOOD + RELATIONS + 'repeats = "twice"\n', r"lab.toml:12 files\[1\]: relations_repeats='twice'; expected drop"),
        # an unknown key used to be ignored: [loaders] lost the loader options, url = ... the download URL
        (
            GOOD + '[loaders]\nodometry = "odom"\n',
            r"lab.toml:8: unknown key 'loaders' \(did you mean 'loader'\?\); expected only name, description",
        ),
        ('fromat = "carmen"\n' + GOOD, r"lab.toml:1: unknown key 'fromat' \(did you mean 'format'\?\)"),
        (GOOD + 'url = "https://x/lab.clf"\n', r"lab.toml:8 files\[0\]: unknown key 'url' \(did you mean 'urls'\?\)"),
        (GOOD + 'sha = "x"\n', r"lab.toml:8 files\[0\]: unknown key 'sha'.*expected only role, path, sha256"),
        # a format no loader reads used to fail only when the dataset was opened, without naming the manifest
        (GOOD.replace('"carmen"', '"albotlog"'), r"lab.toml:2: format 'albotlog' \(did you mean 'albot-log'\?\) is no"),
        (GOOD.replace('"carmen"', '"rawlog"'), r"lab.toml:2: format 'rawlog' is no format the datasets are read in"),
        # the line of the key in the second of several [[files]] tables (there was no line at all)
        (GOOD + RELATIONS + 'sha256_ = "x"\n', r"lab.toml:12 files\[1\]: unknown key 'sha256_'"),
        (GOOD + "\n# a comment\n" + RELATIONS.replace("relations", "map", 1), r"lab.toml:11 files\[1\]: role 'map'"),
    ],
)
def test_bad_manifests_name_file_entry_and_key(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(DataError, match=message):
        parse_manifest(write(tmp_path, text))
