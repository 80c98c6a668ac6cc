"""The shipped manifests: every public dataset is registered, pinned, checksummed and loadable by name."""

from __future__ import annotations

import re

import pytest

from albot1.data import catalog
from albot1.data.errors import DatasetNotFoundError
from albot1.resources import shipped_dir
from albot1.settings import Settings

RAW = ["intel", "aces", "fr079", "mit-csail", "fr-clinic"]
PINNED = re.compile(
    r"^https://raw\.githubusercontent\.com/("
    r"MOLAorg/mola_test_datasets/13a2ed141116bc654e14ffca1d88fb740b3d1253/datasets/radish/"
    r"|acschaefer/ple/cfcb5a7f12a793b616357381a688cfcc26eed347/data/carmen/"
    r"|INESCTEC/ricoslam/52bfaa91c8e5e56f119265d409b1692ca29d48d2/inesctec_mrdt_slam_2d_datasets/data/)"
)


#: The SLAM-corrected logs the project registers (datasets/*-corrected.toml).
CORRECTED_LOGS = 13


def test_the_corrected_logs_derived_from_the_catalog_are_the_manifests_folders(corrected_logs: list[str]) -> None:
    """The root conftest's list (every test over "each corrected log" uses it) against the files themselves."""
    files = sorted(p.stem for p in shipped_dir("datasets").glob("*-corrected.toml"))
    assert len(files) == CORRECTED_LOGS
    assert corrected_logs == files


def test_every_dataset_of_the_readme_is_registered(corrected_logs: list[str]) -> None:
    readme = (shipped_dir("datasets") / "README.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"`([a-z0-9-]+-corrected)`", readme))
    assert listed == set(corrected_logs)
    assert set(RAW) | {"mit-killian"} | listed <= set(catalog.names())


@pytest.mark.parametrize("name", catalog.names())
def test_manifest_fields(name: str) -> None:
    m = catalog.get(name)
    assert m.name == name and m.description and m.license and m.citation and m.format == "carmen"
    for f in m.files:
        assert re.fullmatch(r"[0-9a-f]{64}", f.sha256)
        assert not f.path.startswith("/")
        if not m.local_only:
            assert f.urls and all(PINNED.match(u) and u.endswith(f.path.split("/")[-1]) for u in f.urls)


def test_corrected_logs_take_reference_from_the_flaser_pose(corrected_name: str) -> None:
    manifest = catalog.get(corrected_name)
    assert manifest.log.path == f"radish-corrected/{corrected_name}.log.gz"
    assert manifest.loader["reference"] == "laser-pose"
    assert manifest.loader["odometry"] == ("laser-pose" if corrected_name == "orebro-corrected" else "odom-segments")


def test_mit_killian_is_local_only_and_aces_has_relations() -> None:
    assert catalog.get("mit-killian").local_only and not catalog.get("mit-killian").log.urls
    relations = catalog.get("aces").file("relations")
    assert relations is not None and relations.path == "radish/aces.relations"


@pytest.mark.parametrize(
    ("name", "sha256_prefix", "size"),
    [
        ("intel", "330378f1", 265713),
        ("mit-csail", "ffd7ebe9", 98468),
        ("fr079", "7e7f06b4", 133044),
        ("fr-clinic", "583b7bba", 260314),
    ],
)
def test_the_standard_logs_register_their_relations_files(name: str, sha256_prefix: str, size: int) -> None:
    relations = catalog.get(name).file("relations")
    assert relations is not None and relations.path == f"radish/{name}.relations"
    assert relations.sha256.startswith(sha256_prefix) and relations.size == size
    assert relations.urls[0].endswith(f"/{name}.relations")


@pytest.mark.parametrize("name", RAW)
def test_the_published_relations_files_are_read_as_the_published_evaluator_reads_them(name: str) -> None:
    """Repeated lines count as listed there (docs/metrics.md: dropping aces' nine shifts its numbers by ~5 %)."""
    relations = catalog.get(name).file("relations")
    assert relations is not None and relations.repeats == "keep"


def test_unknown_and_missing_datasets(tmp_path) -> None:
    with pytest.raises(DatasetNotFoundError, match=r"unknown dataset 'nope'; `albot1 datasets list` lists all \d+"):
        catalog.get("nope")
    settings = Settings(data_dir=tmp_path / "empty", cache_dir=tmp_path / "cache")
    with pytest.raises(DatasetNotFoundError, match=r"radish/intel\.clf\.bz2 not found under .*datasets fetch intel"):
        catalog.locate("intel", settings)
    with pytest.raises(DatasetNotFoundError, match="derived locally and cannot be downloaded"):
        catalog.open_dataset("mit-killian", settings)
