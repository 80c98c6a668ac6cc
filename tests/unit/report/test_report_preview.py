"""The run preview: a PNG of map and trajectory, written through the run folder's renderer hook."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from albot1.data.model import Frame, Scan, Sequence
from albot1.report.preview import render_preview
from albot1.runs.execute import run_method
from albot1.runs.folder import is_complete, write_run

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _sequence() -> Sequence:
    angles = np.linspace(-np.pi / 2, np.pi / 2, 7)
    frames = [
        Frame(
            i,
            Scan(np.array([1, 2, np.nan, 3, 2, 1, 1], dtype=float), angles, 100.0 + 0.5 * i, 30.0),
            np.array([0.3 * i, 0.1 * i, 0.05 * i]),
            np.array([0.3 * i, 0.1 * i, 0.05 * i]),
        )
        for i in range(8)
    ]
    return Sequence.from_frames("toy", frames)


def test_write_run_with_render_preview_stores_a_png(tmp_path: Path) -> None:
    run_dir = write_run(run_method("odometry", _sequence()), tmp_path, preview=render_preview)
    assert (run_dir / "preview.png").read_bytes()[:8] == PNG_SIGNATURE
    assert is_complete(run_dir)
