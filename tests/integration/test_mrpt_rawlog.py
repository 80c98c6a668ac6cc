"""Rawlogs written by the project, parsed by MRPT's own rawlog-edit (skipped without MRPT).

Checks what MRPT reads back: object counts and layout (``--info``), and per
object the sensor pose, the aperture, the invalid beams and the odometry
increments (``--describe``), on synthetic frames with known geometry and on
a prefix of a real log.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from albot1.data.loaders.rawlog.writer import RawlogWriter
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata

pytestmark = pytest.mark.skipif(
    shutil.which("rawlog-edit") is None, reason="MRPT's rawlog-edit is not installed (make mrpt)"
)


def _rawlog_edit(*args: str) -> str:
    done = subprocess.run(["rawlog-edit", *args], capture_output=True, text=True, timeout=120, check=True)
    return done.stdout + done.stderr


def _info(path: Path) -> dict[str, str]:
    out = {}
    for line in _rawlog_edit("--info", "-i", str(path)).splitlines():
        key, sep, value = line.partition(" : ")
        if sep:
            out[key.strip()] = value.strip()
    return out


def _sequence() -> Sequence:
    angles = np.radians(np.arange(-90.0, 90.0, 1.0))  # 180 beams, -90..+89 deg
    odometry = [(0.0, 0.0, 0.0), (0.5, 0.0, 0.0), (0.5, 0.0, math.radians(30.0))]
    frames = []
    for i, pose in enumerate(odometry):
        ranges = np.full(180, 2.0 + i)
        ranges[:3] = np.nan
        frames.append(Frame(i, Scan(ranges, angles, 1000.0 + 0.25 * i, 40.0), np.asarray(pose)))
    return Sequence.from_frames("synthetic", frames, SequenceMetadata(sensor_offset=(0.22, -0.05, 0.0)))


@pytest.mark.parametrize("layout", ["actions", "observations"])
def test_rawlog_edit_reads_both_layouts(tmp_path: Path, layout: str) -> None:
    path = tmp_path / f"{layout}.rawlog.gz"
    RawlogWriter(layout).write(_sequence(), path)  # type: ignore[arg-type]
    info = _info(path)
    assert info["Overall number of objects"] == "6"
    assert info["Actions/SensoryFrame format"] == ("Yes" if layout == "actions" else "No")
    assert info["Observations format"] == ("No" if layout == "actions" else "Yes")
    assert info["Earliest timestamp"].startswith("1000.000000")
    assert info["Latest timestamp"].startswith("1000.500000")
    labels = "LASER" if layout == "actions" else "LASER, ODOMETRY"
    assert info["All sensor labels"] == labels


def test_rawlog_edit_describes_the_geometry_and_the_increments(tmp_path: Path) -> None:
    path = tmp_path / "a.rawlog"
    RawlogWriter("actions").write(_sequence(), path)
    text = _rawlog_edit("--describe", "-i", str(path))
    poses = re.findall(r"\(x,y,z,yaw,pitch,roll\)=\(([^)]*)\)", text)
    assert poses and all(p.startswith("0.2200,-0.0500,0.0000,-0.50deg") for p in poses)
    assert re.findall(r'aperture"\): ([0-9.]+) deg', text) == ["179.0"] * 3
    assert re.findall(r"Invalid points in the scan: (\d+)", text) == ["3"] * 3
    increments = re.findall(r"Actual odometry increment reading: \(([^)]*)\)", text)
    assert increments == ["0.000,0.000,0.00deg", "0.500,0.000,0.00deg", "0.000,0.000,30.00deg"]


def test_a_real_log_prefix_keeps_its_scans(tmp_path: Path, data_file: Callable[[str], Path]) -> None:
    from albot1.data.loaders.registry import load
    from albot1.data.transforms import head

    sequence = head(load(data_file("radish/mit-csail.clf.bz2")), 50)
    path = tmp_path / "mit.rawlog"
    writer = RawlogWriter("observations")
    writer.write(sequence, path)
    assert _info(path)["Overall number of objects"] == "100"
    summary = _rawlog_edit("--info", "-i", str(path))
    assert re.search(r"LASER /\s+50 /", summary) and re.search(r"ODOMETRY /\s+50 /", summary)
    text = _rawlog_edit("--describe", "-i", str(path), "--from-index", "1", "--to-index", "1")
    assert "Points in the scan: 361" in text and 'aperture"): 180.0 deg' in text
    assert writer.stats.scans == 50
