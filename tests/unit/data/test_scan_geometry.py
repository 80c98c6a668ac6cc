"""Field of view and beam spacing in a sequence's summary and in `albot1 datasets info` (issue 23)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.cli.datasets import geometry_lines
from albot1.data.loaders.carmen.writer import CarmenWriter
from albot1.data.model import Frame, Scan, Sequence, SequenceMetadata

CARMEN = np.deg2rad(np.arange(-90.0, 90.0, 1.0))  # 180 beams, -90..+89 deg (the CARMEN Intel log)
BAG = np.linspace(-math.pi / 2, math.pi / 2, 181)  # 181 beams, -90..+90 deg (a third-party bag)


def seq(layouts: list[np.ndarray], offset: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Sequence:
    frames = [
        Frame(i, Scan(np.full(a.shape, 3.0), a, float(i), 30.0), np.array([0.1 * i, 0.0, 0.0]))
        for i, a in enumerate(layouts)
    ]
    return Sequence.from_frames("g", frames, metadata=SequenceMetadata(sensor_offset=offset))


def test_one_layout_is_reported_with_its_field_of_view_and_spacing() -> None:
    summary = seq([CARMEN] * 3).summary()
    assert summary["scan_geometry"] == [
        {"first_deg": -90.0, "last_deg": 89.0, "beams": 180, "spacing_deg": 1.0, "scans": 3}
    ]
    assert geometry_lines(summary) == [
        "field of view: -90.00..+89.00 deg (179.00 deg), 180 beams every 1 deg",
        "laser mount (x, y, yaw): (0 m, 0 m, 0 deg)",
    ]


def test_mixed_layouts_are_listed_most_frequent_first_with_their_share() -> None:
    summary = seq([BAG, CARMEN, BAG]).summary()
    assert [(g["first_deg"], g["last_deg"], g["beams"], g["scans"]) for g in summary["scan_geometry"]] == [
        (-90.0, 90.0, 181, 2),
        (-90.0, 89.0, 180, 1),
    ]
    lines = geometry_lines({**summary, "sensor_offset": [0.25, 0.0, math.pi / 2], "sensor_offset_source": "x"})
    assert lines == [
        "field of view: -90.00..+90.00 deg (180.00 deg), 181 beams every 1 deg (2 of 3 scans)",
        "field of view: -90.00..+89.00 deg (179.00 deg), 180 beams every 1 deg (1 of 3 scans)",
        "laser mount (x, y, yaw): (0.25 m, 0 m, 90 deg); x",
    ]


def test_datasets_info_prints_the_field_of_view(tmp_path: Path) -> None:
    CarmenWriter().write(seq([CARMEN] * 4), tmp_path / "x.clf")
    result = CliRunner().invoke(app, ["datasets", "info", str(tmp_path / "x.clf")])
    assert result.exit_code == 0, result.output
    assert "  field of view: -90.00..+89.00 deg (179.00 deg), 180 beams every 1 deg\n" in result.output
