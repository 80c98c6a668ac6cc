"""The map-shape metric's reference map is built once per machine for the same inputs, and never reused for others."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from albot1.data.open import open_sequence
from albot1.metrics import reference_map
from albot1.metrics.measures import map_shape as measure
from albot1.metrics.reference_map import entry_key, read_entry, reference_cloud
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run
from albot1.settings import reference_map_cache_dir

DATASET = "synthetic-office-startstop[:30]"


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A reference-map folder of this test alone, nothing held in memory before or after."""
    monkeypatch.setenv("ALBOT1_DECODED_CACHE", str(tmp_path / "decoded"))
    reference_map.forget()
    folder = reference_map_cache_dir()
    assert folder == tmp_path / "decoded" / "reference-maps"
    yield folder
    reference_map.forget()


@pytest.fixture
def builds(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The datasets whose scans the metric projected (one item per build of a reference map)."""
    calls: list[str] = []
    project = measure.projected_scans

    def counted(inputs: Any, *args: Any) -> Any:
        calls.append(inputs.dataset)
        return project(inputs, *args)

    monkeypatch.setattr(measure, "projected_scans", counted)
    return calls


def _run(tmp_path: Path, seed: int, name: str, dataset: str = DATASET) -> Path:
    result = run_method("odometry", open_sequence(dataset), degradation="gauss:0.1:1", seed=seed, dataset_name=dataset)
    return write_run(result, tmp_path / name)


def _without_stamps(record: Any) -> dict[str, Any]:
    data: dict[str, Any] = record.model_dump(mode="json")
    data.pop("run")
    return data


def _key(**changed: Any) -> str:
    base: dict[str, Any] = {
        "dataset": "aces",
        "checksums": {"aces.clf": "ab" * 32},
        "count": 3,
        "reference": np.arange(9, dtype=float).reshape(3, 3),
        "timestamps": np.array([0.0, 0.5, 1.0]),
        "sensor_offset": np.zeros(3),
        "voxel_m": 0.1,
        "max_points": 200_000,
    }
    return entry_key(**{**base, **changed})


def test_every_input_of_the_reference_map_is_in_its_key() -> None:
    base = _key()
    assert _key() == base  # deterministic
    changed = [
        _key(dataset="aces[:2]"),
        _key(checksums={"aces.clf": "cd" * 32}),
        _key(count=2),
        _key(reference=np.arange(9, dtype=float).reshape(3, 3) + 1e-9),
        _key(timestamps=np.array([0.0, 0.5, 1.001])),
        _key(sensor_offset=np.array([0.1, 0.0, 0.0])),
        _key(voxel_m=0.05),
        _key(max_points=1000),
    ]
    assert len({base, *changed}) == len(changed) + 1


def test_the_key_follows_the_code_version(monkeypatch: pytest.MonkeyPatch) -> None:
    base = _key()
    monkeypatch.setattr(reference_map, "code_version", lambda: "0.0.0+changed")
    assert _key() != base


def test_a_second_run_of_the_dataset_reuses_the_map_and_gets_the_same_numbers(
    tmp_path: Path, cache: Path, builds: list[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    first, second = _run(tmp_path, 0, "a"), _run(tmp_path, 1, "b")
    monkeypatch.setenv("ALBOT1_DECODED_CACHE", "off")
    uncached = [_without_stamps(evaluate_run(run)) for run in (first, second)]
    assert builds == [DATASET, DATASET]
    monkeypatch.setenv("ALBOT1_DECODED_CACHE", str(cache.parent))
    builds.clear()
    assert _without_stamps(evaluate_run(first)) == uncached[0]
    assert len(list(cache.glob("*.npz"))) == 1
    reference_map.forget()  # as a new process (a bench cell): only the disk entry is left
    assert _without_stamps(evaluate_run(second)) == uncached[1]
    assert _without_stamps(evaluate_run(first)) == uncached[0]
    assert builds == [DATASET]  # built once, for the first run; read back for the others


def test_another_prefix_of_the_dataset_is_another_map(tmp_path: Path, cache: Path, builds: list[str]) -> None:
    evaluate_run(_run(tmp_path, 0, "a"))
    shorter = "synthetic-office-startstop[:20]"
    block = evaluate_run(_run(tmp_path, 0, "b", shorter)).block("map_shape")
    assert block is not None
    assert builds == [DATASET, shorter]
    assert len(list(cache.glob("*.npz"))) == 2


def test_a_damaged_or_foreign_entry_is_built_again(tmp_path: Path, cache: Path, builds: list[str]) -> None:
    run = _run(tmp_path, 0, "a")
    expected = _without_stamps(evaluate_run(run))
    (entry,) = cache.glob("*.npz")
    key = entry.stem
    stored = read_entry(entry, key)
    assert stored is not None
    assert read_entry(entry, "0" * 64) is None  # an entry answers only for its own key
    for damage in (b"", entry.read_bytes()[:100], b"not a zip file"):
        entry.write_bytes(damage)
        reference_map.forget()
        assert _without_stamps(evaluate_run(run)) == expected
        np.testing.assert_array_equal(read_entry(entry, key), stored)  # rebuilt and stored again
    assert len(builds) == 4


def test_an_unwritable_folder_means_building_every_time(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("ALBOT1_DECODED_CACHE", str(blocker))
    reference_map.forget()
    cloud = np.array([[0.0, 1.0], [2.0, 3.0]])
    assert reference_cloud("k", lambda: cloud).tolist() == cloud.tolist()
    reference_map.forget()
    again = reference_cloud("k", lambda: cloud + 1)  # nothing was stored: built again
    assert again.tolist() == (cloud + 1).tolist()
    reference_map.forget()


def test_a_failed_build_stores_nothing(cache: Path) -> None:
    def fail() -> np.ndarray:
        raise RuntimeError("the scans do not fit")

    with pytest.raises(RuntimeError):
        reference_cloud("k", fail)
    assert not list(cache.glob("*.npz")) if cache.exists() else True
    assert reference_cloud("k", lambda: np.zeros((1, 2))).tolist() == [[0.0, 0.0]]


def test_a_flipped_zip_header_bit_is_a_miss_not_an_error(tmp_path: Path) -> None:
    """zipfile raises RuntimeError ("encrypted") or NotImplementedError (compression) for these bits."""
    entry = tmp_path / f"{'ab' * 32}.npz"
    assert reference_map.write_entry(entry, "ab" * 32, np.zeros((4, 2)))
    good = entry.read_bytes()
    central = good.index(b"PK\x01\x02")
    for position in (central + 8, central + 10):  # the central header's flags and method (zipfile reads these)
        damaged = bytearray(good)
        damaged[position] ^= 0x01
        entry.write_bytes(bytes(damaged))
        assert read_entry(entry, "ab" * 32) is None, position
