"""A user's own log registered by a manifest in ALBOT1_CONFIG_DIR: an albot log, a ROS2 bag folder."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from albot1.data import catalog
from albot1.data.convert import convert
from albot1.data.errors import DataError
from albot1.data.model import Frame, Sequence
from albot1.data.open import open_sequence
from albot1.settings import Settings

WORLD = "synthetic-corridor[:5]"


#: every test here in its own config folder and checksum cache (the root conftest.py's own_project)
pytestmark = pytest.mark.usefixtures("own_project")


def register(tmp_path: Path, name: str, fmt: str, path: str, sha256: str) -> Path:
    toml = tmp_path / "project" / "datasets" / f"{name}.toml"
    toml.write_text(
        f'name = "{name}"\nformat = "{fmt}"\nlocal_only = true\n\n'
        f'[[files]]\nrole = "log"\npath = "{path}"\nsha256 = "{sha256}"\n'
    )
    return toml


def robot_log() -> Sequence:
    """Five scans as a robot records them: odometry, no reference poses."""
    return open_sequence(WORLD).with_frames(lambda frames: (Frame(f.index, f.scan, f.odometry, None) for f in frames))


def sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def same_frames(b: str, settings: Settings) -> None:
    left = list(robot_log().frames())
    right = list(open_sequence(b, settings=settings).frames())
    assert len(left) == len(right) == 5
    for x, y in zip(left, right, strict=True):
        assert x.scan.timestamp == pytest.approx(y.scan.timestamp, abs=1e-9)  # a bag keeps nanoseconds
        assert x.reference is None and y.reference is None
        np.testing.assert_allclose(x.odometry, y.odometry, atol=1e-6)
        assert np.array_equal(np.isnan(x.scan.ranges), np.isnan(y.scan.ranges))


def test_an_albot_log_without_reference_registers_and_opens(tmp_path: Path) -> None:
    log = tmp_path / "data" / "mine" / "lab.albotlog"
    convert(robot_log(), log, "albot-log")
    register(tmp_path, "mine-lab", "albot-log", "mine/lab.albotlog", sha(log))
    same_frames("mine-lab", Settings(tmp_path / "data", tmp_path / "cache"))


def test_a_ros2_bag_folder_named_by_a_manifest_is_refused_naming_the_manifest_and_its_storage_file(
    tmp_path: Path,
) -> None:
    """A bag is a folder; the manifest's sha256 is of one file. This used to be "a folder, not a regular
    file; expected a data file", naming neither the manifest nor the file to name instead."""
    bag = tmp_path / "data" / "mine" / "run.mcap"
    convert(robot_log(), bag, "ros2-mcap")
    storage = bag / "run.mcap"
    toml = register(tmp_path, "mine-bag", "ros2-mcap", "mine/run.mcap", sha(storage))
    settings = Settings(tmp_path / "data", tmp_path / "cache")
    with pytest.raises(DataError) as caught:
        open_sequence("mine-bag", settings=settings)
    assert str(caught.value) == (
        f"{bag}: a folder, but the manifest of dataset 'mine-bag' ({toml}) names it as its log file; expected a "
        f'file (sha256 is the checksum of one file); for a ROS2 bag name its storage file: path = "mine/run.mcap/'
        f'run.mcap" with sha256 of `sha256sum {storage}`'
    )
    register(tmp_path, "mine-bag", "ros2-mcap", "mine/run.mcap/run.mcap", sha(storage))  # as the message says
    catalog._manifests.cache_clear()
    same_frames("mine-bag", settings)
