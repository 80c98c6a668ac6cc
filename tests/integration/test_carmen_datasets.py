"""The acceptance facts of the public CARMEN logs (issue 2), loaded by name through the catalog."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from albot1.data import catalog
from albot1.data.errors import ParseError
from albot1.data.loaders.carmen.loader import CarmenLoader
from albot1.geometry import se2
from albot1.settings import Settings

DataFile = Callable[[str], Path]


def settings_for(data_file: DataFile, relative: str) -> Settings:
    path = data_file(relative)
    return Settings(data_dir=path.parents[1], cache_dir=path.parents[1] / "no-cache")


def test_intel(data_file: DataFile) -> None:
    s = catalog.open_dataset("intel", settings_for(data_file, "radish/intel.clf.bz2")).summary()
    assert (s["scans"], s["beams"], s["has_reference"]) == (13631, 180, False)
    assert s["duration_s"] == pytest.approx(2691.3, abs=0.5)
    assert s["odometry_path_m"] == pytest.approx(508.4, abs=1.0)


def test_aces_relations_match_flaser_stamps(data_file: DataFile) -> None:
    seq = catalog.open_dataset("aces", settings_for(data_file, "radish/aces.clf.bz2"))
    s = seq.summary()
    assert (s["scans"], s["beams"], s["relations"]) == (7374, 180, 1279)
    stamps = set(np.round(seq.timestamps, 6).tolist())
    assert seq.relations is not None
    assert all(round(t, 6) in stamps for t in np.r_[seq.relations.t1, seq.relations.t2])
    assert (seq.relations.repeats, seq.relations.repeats_counted) == (9, True)  # the manifest's published reading


def test_aces_relations_counted_once_on_request(data_file: DataFile) -> None:
    seq = catalog.open_dataset("aces", settings_for(data_file, "radish/aces.clf.bz2"), relations_repeats="drop")
    assert seq.relations is not None
    assert (len(seq.relations), seq.relations.repeats, seq.relations.repeats_counted) == (1270, 9, False)


def test_mit_csail_max_range_readings_are_no_return(data_file: DataFile) -> None:
    seq = catalog.open_dataset("mit-csail", settings_for(data_file, "radish/mit-csail.clf.bz2"))
    nans = sum(int(np.isnan(f.scan.ranges).sum()) for f in seq.frames())
    s = seq.summary()
    assert (s["scans"], s["beams"]) == (1988, 361)
    assert nans == 23711  # exactly the 81.91 m readings of the log
    frame = next(iter(seq))
    assert frame.scan.angles[0] == pytest.approx(-np.pi / 2) and frame.scan.angles[-1] == pytest.approx(np.pi / 2)


def test_fr_clinic_from_robotlaser1(data_file: DataFile) -> None:
    seq = catalog.open_dataset("fr-clinic", settings_for(data_file, "radish/fr-clinic_robotlaser.clf.bz2"))
    s = seq.summary()
    assert s["scans"] == 6917 and sorted(s["beams"]) == [180, 181]
    assert seq.metadata.extra["laser_message"] == "ROBOTLASER1"
    assert seq.metadata.sensor_offset[0] == pytest.approx(0.22, abs=1e-6)


def test_every_corrected_log_has_reference_poses(data_file: DataFile, corrected_name: str) -> None:
    """One case per corrected log of the catalog (``corrected_name``: the root conftest derives them)."""
    seq = catalog.open_dataset(corrected_name, settings_for(data_file, catalog.get(corrected_name).log.path))
    frames = [f for _, f in zip(range(50), seq.frames())]
    assert len(frames) == 50 and all(f.reference is not None for f in frames)


def test_corrected_odometry_steps_track_the_reference_but_drift(data_file: DataFile) -> None:
    """The documented finding: ODOM increments ~ corrected increments (cm), yet the chain drifts (m)."""
    seq = catalog.open_dataset("aces-corrected", settings_for(data_file, "radish-corrected/aces-corrected.log.gz"))
    odom, ref = seq.odometry, seq.reference
    assert ref is not None and len(odom) == 440
    diff = se2.relative_steps(odom) - se2.relative_steps(ref)
    assert np.median(np.hypot(diff[:, 0], diff[:, 1])) < 0.1
    assert np.hypot(*(odom[-1, :2] - ref[-1, :2])) > 1.0


def test_datasets_info_cli_json(data_file: DataFile, monkeypatch: pytest.MonkeyPatch) -> None:
    from albot1.cli.datasets import app

    root = data_file("radish/aces.clf.bz2").parents[1]
    result = CliRunner().invoke(app, ["info", "aces-corrected", "--json", "--data-dir", str(root)])
    assert result.exit_code == 0, result.output
    info = json.loads(result.output)
    assert {"name", "scans", "beams", "duration_s", "odometry_path_m", "has_reference", "relations"} <= set(info)
    assert (info["name"], info["scans"], info["has_reference"]) == ("aces-corrected", 440, True)
    listing = CliRunner().invoke(app, ["list", "--json", "--data-dir", str(root)])
    rows = {r["name"]: r for r in json.loads(listing.output)["datasets"]}
    assert rows["intel"]["available"] and rows["mit-killian"]["local_only"]


def test_truncated_real_bz2_is_a_parse_error(data_file: DataFile, tmp_path: Path) -> None:
    cut = tmp_path / "aces-cut.clf.bz2"
    cut.write_bytes(data_file("radish/aces.clf.bz2").read_bytes()[:300_000])
    with pytest.raises(
        ParseError, match=r"aces-cut\.clf\.bz2:\d+: the bzip2 data is truncated after this line .* 300000"
    ):
        for _ in CarmenLoader().load(cut).frames():
            pass
