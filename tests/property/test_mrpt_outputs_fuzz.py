"""Random text in MRPT's output files: the readers return well-shaped arrays or raise BaselineError, nothing else."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.mrpt import outputs

TOKENS = st.sampled_from(["0", "1", "2", "-1", "0.5", "1e308", "nan", "inf", "x", "%", "% h", "", "1 2", "\t"])
LINES = st.lists(st.lists(TOKENS, max_size=9).map(" ".join), max_size=12)


def _write(folder: Path, name: str, lines: list[str]) -> None:
    (folder / name).write_text("\n".join(lines) + "\n", encoding="ascii")


@settings(max_examples=150, deadline=None)
@given(lines=LINES, scans=st.integers(0, 4))
def test_icp_path_reader(lines: list[str], scans: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        _write(Path(tmp), "log_estimated_path.txt", lines)
        try:
            poses = outputs.icp_poses(Path(tmp), scans)
        except BaselineError:
            return
        assert poses.shape == (scans, 3)


@settings(max_examples=150, deadline=None)
@given(times=LINES, path=LINES, scans=st.integers(0, 4))
def test_rbpf_readers(times: list[str], path: list[str], scans: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        _write(folder, "log_times.txt", times)
        _write(folder, "most_likely_path.txt", path)
        try:
            steps = outputs.rbpf_steps(folder, scans)
            best = outputs.rbpf_best_path(folder, int(steps.updated.sum()))
        except BaselineError:
            return
        assert steps.updated.shape == (scans,) and best.shape == (int(steps.updated.sum()) + 1, 3)
        odometry = np.zeros((scans, 3))
        assert outputs.poses_between_updates(best, steps.updated, odometry).shape == (scans, 3)
