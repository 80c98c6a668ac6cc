"""The run preview: a PNG of map and trajectory, written through the run folder's renderer hook."""

from __future__ import annotations

import subprocess
import sys
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


# One run's preview drawn in a fresh interpreter: "plain" with the tick memo left out, "memo" as shipped. Printed:
# the PNG's sha256 and how many times matplotlib's own tick update ran (the memo, when installed, wraps it).
_DRAW_PREVIEW = """
import hashlib, sys, tempfile
from pathlib import Path
import numpy as np
from matplotlib.axis import Axis
if sys.argv[1] == "plain":
    import albot1.report.tick_memo as memo
    memo.share_tick_updates = lambda: False  # imported by name below: the preview installs nothing
update = Axis._update_ticks
calls = [0]
def counted(self):
    calls[0] += 1
    return update(self)
Axis._update_ticks = counted
from albot1.data.model import Frame, Scan, Sequence
from albot1.report.preview import render_preview
from albot1.runs.execute import run_method
angles = np.linspace(-np.pi / 2, np.pi / 2, 31)
rng = np.random.default_rng(5)
frames = [
    Frame(i, Scan(rng.uniform(1, 8, 31), angles, 10.0 + 0.5 * i, 30.0),
          np.array([0.4 * i, 0.15 * i, 0.03 * i]), np.array([0.41 * i, 0.14 * i, 0.031 * i]))
    for i in range(40)
]
result = run_method("odometry", Sequence.from_frames("toy", frames))
path = Path(tempfile.mkdtemp()) / "preview.png"
render_preview(result, path)
print(hashlib.sha256(path.read_bytes()).hexdigest(), calls[0])
"""


def _draw_preview(mode: str) -> tuple[str, int]:
    out = subprocess.run(
        [sys.executable, "-c", _DRAW_PREVIEW, mode], check=True, capture_output=True, text=True, timeout=300
    )
    digest, calls = out.stdout.split()
    return digest, int(calls)


def test_a_preview_works_out_each_axis_s_ticks_once_and_keeps_its_bytes() -> None:
    """Every bench cell draws a preview (issue 24): the tick memo cuts matplotlib's repeated tick updates, same PNG."""
    (plain, plain_calls), (memo, memo_calls) = _draw_preview("plain"), _draw_preview("memo")
    assert memo == plain  # the same PNG, byte for byte
    assert memo_calls == 2 < plain_calls  # x and y once each, in the one draw; several times each without it
