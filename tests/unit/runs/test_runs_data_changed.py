"""A stored run evaluated after its data file changed: the number that would need the new data says so."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.data.loaders.registry import writer_for
from albot1.data.open import open_sequence
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import read_result, write_run


def test_map_shape_is_not_computed_against_data_that_changed_since_the_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ALBOT1_CACHE_DIR", str(tmp_path / "cache"))
    log = tmp_path / "w.clf"
    writer_for("carmen").write(open_sequence("synthetic-office-startstop[:30]"), log)
    result = run_method("odometry", open_sequence(str(log)), dataset_name=str(log))
    run_dir = write_run(result, tmp_path / "runs")
    assert read_result(run_dir).dataset_info.data_sha256.keys() == {"w.clf"}
    assert evaluate_run(run_dir).block("map_shape") is not None
    # The same scans and times, one range changed: only the checksum can tell.
    lines = log.read_text().splitlines(keepends=True)
    index = next(i for i, line in enumerate(lines) if line.startswith("ROBOTLASER1"))
    fields = lines[index].split(" ")
    fields[9] = f"{float(fields[9]) + 0.5:.3f}"
    lines[index] = " ".join(fields)
    log.write_text("".join(lines))
    metrics = evaluate_run(run_dir)
    assert metrics.block("map_shape") is None
    assert metrics.reason("map_shape") == (
        f"cannot reopen dataset {str(log)!r} for the reference map: dataset {str(log)!r}: its files' sha256 differ "
        "from the run's; the dataset changed since the run"
    )
