"""The real unreadable ROS1 bags of ``bad-inputs/`` (see the datasets README): one line saying what is
wrong with the file and which bag format is supported, through the CLI as a user runs it."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from albot1.data.errors import ParseError
from albot1.data.loaders.registry import load

pytestmark = pytest.mark.integration

CASES = {
    "old-rosbag-laser_scan_matcher-demo.bag": (
        r"damaged ROS1 bag: the index data record at byte 792650 declares 5560 data bytes for 278 entries, "
        r"expected 3336 .*expected a consistent ROS1 bag format 2\.0"
    ),
    "old-rosbag-laser_scan_sparsifier-demo.bag": (
        r"\.bag:1: ROS1 bag format 1\.2 \(ROS 0\.5 to 1\.0, before 2010\); expected ROS1 bag format 2\.0"
    ),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_old_bags_say_what_is_wrong_and_what_is_supported(data_file: Callable[[str], Path], name: str) -> None:
    path = data_file(f"bad-inputs/{name}")
    with pytest.raises(ParseError, match=CASES[name]):
        load(path)
    albot1 = Path(sys.executable).with_name("albot1")  # the console script, as a user runs it
    done = subprocess.run([str(albot1), "datasets", "info", str(path)], capture_output=True, text=True, check=False)
    assert done.returncode == 1
    assert "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"albot1: error: {path}")
