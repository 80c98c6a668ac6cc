"""Readers of MRPT's output files: exact values on small files, and errors naming file:line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.mrpt import outputs


def test_icp_path_takes_every_second_step(tmp_path: Path) -> None:
    (tmp_path / "log_estimated_path.txt").write_text("0 0 0 0\n1 1 2 0.5\n2 1 2 0.5\n3 3 4 1.0\n")
    np.testing.assert_array_equal(outputs.icp_poses(tmp_path, 2), [[1, 2, 0.5], [3, 4, 1.0]])
    with pytest.raises(BaselineError, match=r"4 steps; expected 6 .*3 scans"):
        outputs.icp_poses(tmp_path, 3)
    (tmp_path / "log_estimated_path.txt").write_text("0 0 0 0\n2 1 2 0.5\n")
    with pytest.raises(BaselineError, match=r"not numbered 0\.\.1"):
        outputs.icp_poses(tmp_path, 1)


def test_malformed_lines_name_file_and_line(tmp_path: Path) -> None:
    (tmp_path / "log_estimated_path.txt").write_text("0 0 0 0\n1 x 0 0\n")
    with pytest.raises(BaselineError, match=r"log_estimated_path.txt:2: non-numeric field"):
        outputs.icp_poses(tmp_path, 1)
    (tmp_path / "log_estimated_path.txt").write_text("% header\n0 0 0\n")
    with pytest.raises(BaselineError, match=r"log_estimated_path.txt:2: 3 fields; expected 4"):
        outputs.icp_poses(tmp_path, 1)
    with pytest.raises(BaselineError, match=r"most_likely_path.txt: missing; MRPT did not write"):
        outputs.rbpf_best_path(tmp_path, 0)


def test_rbpf_steps_need_one_row_per_scan_and_a_first_insertion(tmp_path: Path) -> None:
    path = tmp_path / "log_times.txt"
    path.write_text("% h\n% h\n0 12.5 1 1\n1 0.01 1 0\n2 9.0 2 1\n")
    steps = outputs.rbpf_steps(tmp_path, 3)
    assert steps.updated.tolist() == [True, False, True] and steps.time_ms.tolist() == [12.5, 0.01, 9.0]
    path.write_text("0 12.5 1 0\n")
    with pytest.raises(BaselineError, match="first scan was not inserted"):
        outputs.rbpf_steps(tmp_path, 1)
    path.write_text("0 12.5 1 2\n")
    with pytest.raises(BaselineError, match="other than 0 and 1"):
        outputs.rbpf_steps(tmp_path, 1)


def test_poses_between_updates_compose_the_odometry_since_the_last_update() -> None:
    updated = np.array([True, False, False, True, False])
    odometry = np.array([[0, 0, 0], [1, 0, 0], [1, 0, np.pi / 2], [1, 1, np.pi / 2], [1, 2, np.pi / 2]], float)
    # Initial pose, then the filter's poses at scans 0 and 3 (the second one 0.1 m off the odometry).
    best = np.array([[0, 0, 0], [0, 0, 0], [1.1, 1, np.pi / 2]], float)
    poses = outputs.poses_between_updates(best, updated, odometry)
    np.testing.assert_allclose(
        poses, [[0, 0, 0], [1, 0, 0], [1, 0, np.pi / 2], [1.1, 1, np.pi / 2], [1.1, 2, np.pi / 2]], atol=1e-12
    )
    with pytest.raises(BaselineError, match="3 path poses for 1 filter updates"):
        outputs.poses_between_updates(best, np.array([True, False, False, False, False]), odometry)


def test_grid_cells_become_points_at_their_centres(tmp_path: Path) -> None:
    from matplotlib import image

    free = np.full((2, 3), 0.5)
    free[0, 2] = 0.2  # occupancy 0.8, top right
    free[1, 0] = 0.4  # occupancy 0.6: below the threshold
    image.imsave(tmp_path / outputs.GRID_IMAGE, free, cmap="gray", vmin=0, vmax=1)
    (tmp_path / outputs.GRID_LIMITS).write_text("% limits\n0 0.3 -0.1 0.1\n")
    grid = outputs.grid_map(tmp_path, 0.1)
    np.testing.assert_allclose(grid.occupied_points(0.65), [[0.25, 0.05]], atol=1e-9)
    assert grid.summary()["width_cells"] == 3 and grid.summary()["height_cells"] == 2


def test_log_text_helpers() -> None:
    assert outputs.total_time_s("x\n[..] ----------- **END** (total time: 89.342 sec) ---------\n") == 89.342
    assert outputs.total_time_s("no end") is None
    text = "progress\n==== MRPT exception ====\nMessage:  Assert condition failed: x\nCall stack\n"
    assert outputs.last_error_line(text) == "Message:  Assert condition failed: x"
    assert outputs.last_error_line("a\nlast words\n\n") == "last words"
    assert outputs.last_error_line("") == "(no output)"
