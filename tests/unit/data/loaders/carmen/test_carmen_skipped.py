"""Message kinds the CARMEN loader does not read are skipped, never silently: a warning at load, a line of
``albot1 datasets info`` and ``metadata.extra["skipped_messages"]``, all with counts and first lines."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest

from albot1.data.loaders.carmen.loader import CarmenLoader

# 181 readings: a SICK LMS 2xx's, so the only warning is what the tests are about (not the default geometry's)
READINGS = " ".join(["2.0"] * 181)
FLASER = f"FLASER 181 {READINGS} 0 0 0 0 0 0 {{t}} host {{t}}"
RLASER = f"RLASER 181 {READINGS} 0 0 0 0 0 0 {{t}} host {{t}}"
SONAR = "SONAR 3 1 2 3 {t} host {t}"
NEFF = "NEFF 12.5 {t} host {t}"


def write(tmp_path: Path, *kinds: str, scans: int = 4) -> Path:
    lines = [kind.format(t=float(k)) for k in range(scans) for kind in (FLASER, *kinds)]
    path = tmp_path / "log.clf"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_rear_laser_and_sonar_are_named_with_counts_first_lines_and_the_option(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = write(tmp_path, RLASER, SONAR)
    with caplog.at_level(logging.WARNING):
        sequence = CarmenLoader().load(path)
    note = (
        "4 RLASER lines from line 2 (a laser: read it with laser=RLASER), 4 SONAR lines from line 3, counted in "
        "the first 12 lines; message kinds other than FLASER, ODOM, TRUEPOS and PARAM are not read"
    )
    assert sequence.metadata.extra["skipped_messages"] == note
    assert sequence.summary()["skipped_messages"] == note
    assert [r.getMessage() for r in caplog.records] == [f"{path}: skipped: {note}"]
    assert sequence.count_scans() == 4


def test_choosing_the_rear_laser_names_the_front_one_as_skipped(tmp_path: Path) -> None:
    sequence = CarmenLoader().load(write(tmp_path, RLASER), laser="RLASER")
    assert sequence.metadata.extra["skipped_messages"].startswith(
        "4 FLASER lines from line 1 (a laser: read it with laser=FLASER), counted in the first 8 lines; "
        "message kinds other than RLASER, "
    )


def test_kinds_without_sensor_data_are_listed_without_a_warning(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """NEFF (GMapping's particle count, after every scan of the corrected logs) would warn at every load of
    every corrected log; it is listed, not warned about."""
    with caplog.at_level(logging.WARNING):
        sequence = CarmenLoader().load(write(tmp_path, NEFF))
    assert sequence.metadata.extra["skipped_messages"].startswith("4 NEFF lines from line 2, counted in the first 8")
    assert caplog.records == []


def test_nothing_skipped_says_nothing(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING):
        sequence = CarmenLoader().load(write(tmp_path))
    assert sequence.metadata.extra["skipped_messages"] == ""
    assert caplog.records == []


def test_datasets_info_prints_what_is_skipped(tmp_path: Path) -> None:
    path = write(tmp_path, SONAR)
    done = subprocess.run(
        [sys.executable, "-c", "from albot1.cli.app import main; main()", "datasets", "info", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "ALBOT1_DECODED_CACHE": "off", "ALBOT1_CACHE_DIR": str(tmp_path / "cache")},
    )
    note = (
        "4 SONAR lines from line 2, counted in the first 8 lines; message kinds other than FLASER, ODOM, TRUEPOS "
        "and PARAM are not read"
    )
    assert done.returncode == 0, done.stderr
    assert f"  skipped: {note}\n" in done.stdout
    assert done.stderr == f"{path}: skipped: {note}\n"


def test_one_skipped_line_is_said_in_the_singular(tmp_path: Path) -> None:
    path = write(tmp_path)
    lines = path.read_text().splitlines()
    path.write_text("\n".join([lines[0], "SONAR 1 2 3", *lines[1:]]) + "\n")
    sequence = CarmenLoader().load(path)
    assert sequence.metadata.extra["skipped_messages"].startswith("1 SONAR line at line 2, counted in the first 5")
