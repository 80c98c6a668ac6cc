"""A registered dataset's manifest `[loader]` options are part of a run's key and record.

Why: `max_range` or the odometry source of `datasets/<name>.toml` change the scans and poses a method is given
from the same files, and they do not appear in the dataset's name; a manifest edited or replaced through
`ALBOT1_CONFIG_DIR` kept the older cells ("already complete (kept)") and recorded nothing of the options.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from albot1.bench.plan import plan_suite
from albot1.bench.suite import load_suite
from albot1.data import catalog
from albot1.data.open import open_sequence
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run
from albot1.settings import Settings

PAYLOAD = "".join(f"FLASER 3 1.0 2.0 3.0 {0.1 * i:.1f} 0 0 {0.1 * i:.1f} 0 0 {i}.0 host {i}.0\n" for i in range(12))
SHA = hashlib.sha256(PAYLOAD.encode()).hexdigest()


@pytest.fixture(autouse=True)
def private_catalog(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "checksum-cache"))
    (tmp_path / "project" / "datasets").mkdir(parents=True)
    monkeypatch.setenv("ALBOT1_CONFIG_DIR", str(tmp_path / "project"))
    log = tmp_path / "data" / "radish" / "tiny.clf"
    log.parent.mkdir(parents=True)
    log.write_text(PAYLOAD)
    catalog._manifests.cache_clear()
    yield
    catalog._manifests.cache_clear()


def _manifest(tmp_path: Path, max_range: float) -> None:
    (tmp_path / "project" / "datasets" / "tiny.toml").write_text(
        f'name = "tiny"\nformat = "carmen"\n\n[[files]]\nrole = "log"\npath = "radish/tiny.clf"\nsha256 = "{SHA}"\n'
        f'\n[loader]\nodometry = "laser-pose"\nmax_range = {max_range}\n'
    )
    catalog._manifests.cache_clear()


def _settings(tmp_path: Path) -> Settings:
    return Settings(data_dir=tmp_path / "data", cache_dir=tmp_path / "cache")


def _key(tmp_path: Path) -> str:
    suite = tmp_path / "suite.toml"
    suite.write_text('[[methods]]\nname = "odometry"\n\n[[datasets]]\nname = "tiny"\nsweep = false\n')
    [cell] = plan_suite(load_suite(suite), _settings(tmp_path)).cells
    return cell.key


def test_a_manifest_with_other_loader_options_plans_another_key(tmp_path: Path) -> None:
    _manifest(tmp_path, 80.0)
    first = _key(tmp_path)
    assert _key(tmp_path) == first  # nothing changed: the cell is kept
    _manifest(tmp_path, 2.5)  # the 3.0 m beam is now no return: other scans from the same file
    assert _key(tmp_path) != first


def test_a_run_records_the_manifest_loader_options_and_is_stored_under_the_planned_key(tmp_path: Path) -> None:
    _manifest(tmp_path, 2.5)
    planned = _key(tmp_path)
    result = run_method("odometry", open_sequence("tiny", settings=_settings(tmp_path)), dataset_name="tiny")
    folder = write_run(result, tmp_path / "runs")
    assert folder.name == planned
    info = json.loads((folder / "result.json").read_text())["dataset_info"]
    assert info["manifest_loader"] == {"odometry": "laser-pose", "max_range": 2.5}
    assert info["data_sha256"] == {"tiny.clf": SHA}
