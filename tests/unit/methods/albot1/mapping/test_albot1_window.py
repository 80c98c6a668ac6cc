"""Albot1+'s window test (``window_updates``): the odometry since an older update view, against that view."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry.se2 import compose_pose
from albot1.geometry.segments import transform_segments
from albot1.methods.albot1.mapping.ambiguity import threshold
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import PlusLocaliser
from albot1.methods.albot1.mapping.start_poses import start_poses
from albot1.methods.albot1.mapping.window import WINDOW_HISTORY, OdometryWindow, UpdateRecord

KERNELS = MappingKernels(False)
SIGMAS = (0.05, 0.1, 0.05, 2.0, 0.5)  # line, point, scan sigma, Huber (sigmas), gate: the plus preset's
ROOM = np.array([[-2.0, 5.0, 2.0, 5.0], [3.0, 4.0, 3.0, 1.0], [-3.0, 1.0, -3.0, 4.0]])  # thesis frame, facing +y
Pose3 = tuple[float, float, float]


def room_points(pose: Pose3, per_wall: int = 31, noise: float = 0.02, seed: int = 3) -> np.ndarray:
    """The room's walls seen from ``pose`` (thesis frame), with seeded noise."""
    t = np.linspace(0.0, 1.0, per_wall)
    world = np.vstack([np.column_stack([x1 + t * (x2 - x1), y1 + t * (y2 - y1)]) for x1, y1, x2, y2 in ROOM])
    c, s = math.cos(pose[2]), math.sin(pose[2])
    d = world - np.array(pose[:2])
    local = np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]])
    return np.ascontiguousarray(local + np.random.default_rng(seed).normal(0.0, noise, local.shape))


def rep(thesis_motion: Pose3) -> Pose3:
    """The REP-103 odometry whose ``exact`` motion from the origin is ``thesis_motion`` (thesis (-dy, dx, dth))."""
    return (thesis_motion[1], -thesis_motion[0], thesis_motion[2])


def window_with(records: int, size: int = 4) -> OdometryWindow:
    """A window whose update views all sit at the map's origin with odometry zero and see the room as it is."""
    window = OdometryWindow(size, "exact")
    for _ in range(records):
        window.add(UpdateRecord((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), ROOM))
    return window


def run(window: OdometryWindow, truth: Pose3, odometry_motion: Pose3, measured: Pose3 | None = None) -> object:
    points = room_points(truth)
    return window.test(
        rep(odometry_motion),
        measured or truth,
        points,
        KERNELS.refine_pose,
        KERNELS.measurement_costs,
        SIGMAS,
        8,
        threshold(0.5),
    )


def test_odometry_that_explains_the_old_view_is_kept_and_is_the_window_prediction() -> None:
    truth = (0.2, 0.5, math.radians(3.0))
    outcome = run(window_with(2), truth, truth)
    assert outcome is not None and outcome.kept and outcome.matched == 1.0
    assert outcome.prediction == pytest.approx(truth, abs=1e-12)


def test_odometry_three_degrees_off_over_the_window_is_refuted() -> None:
    truth = (0.2, 0.5, math.radians(3.0))
    drifted = (0.2, 0.5, math.radians(6.0))
    outcome = run(window_with(2), truth, drifted)
    assert outcome is not None and not outcome.kept and outcome.test.statistic > 10.0 * outcome.test.threshold


def test_no_window_before_two_update_views_or_without_points() -> None:
    assert run(window_with(1), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)) is None
    kernels = (KERNELS.refine_pose, KERNELS.measurement_costs)
    no_points = np.empty((0, 2))
    assert window_with(2).test((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), no_points, *kernels, SIGMAS, 8, 1.0) is None


def test_too_little_overlap_with_the_old_view_is_not_agreement() -> None:
    """Points far from every surface of the old view: the test says nothing, so the odometry is not kept."""
    window = window_with(2)
    far = np.ascontiguousarray(room_points((0.0, 0.0, 0.0)) + np.array([0.0, 20.0]))
    outcome = window.test(
        (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), far, KERNELS.refine_pose, KERNELS.measurement_costs, SIGMAS, 8,
        threshold(0.5),
    )  # fmt: skip
    assert outcome is not None and outcome.matched == 0.0 and not outcome.kept


def test_the_oldest_view_is_the_anchor_and_leaves_when_the_window_is_full() -> None:
    window = OdometryWindow(2, "exact")
    window.add(UpdateRecord((5.0, 0.0, 0.0), (0.0, 0.0, 0.0), ROOM))
    window.add(UpdateRecord((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), ROOM))
    first = run(window, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert first is not None and first.prediction == (5.0, 0.0, 0.0)  # the oldest view, not the last
    window.add(UpdateRecord((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), ROOM))
    second = run(window, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert second is not None and second.prediction == (0.0, 0.0, 0.0) and second.kept


def test_one_refuted_view_among_agreeing_ones_keeps_the_odometry() -> None:
    """The running median of the last WINDOW_HISTORY statistics: a lone false alarm does not end the trust."""
    window = window_with(2)
    truth = (0.1, 0.3, math.radians(1.0))
    for _ in range(WINDOW_HISTORY):
        assert run(window, truth, truth).kept
    lone = run(window, truth, (0.1, 0.3, math.radians(4.0)))
    assert lone is not None and not lone.test.ambiguous and lone.kept
    # Refuted again and again: the median rises above the limit and the odometry is no longer kept.
    for _ in range(WINDOW_HISTORY // 2):
        run(window, truth, (0.1, 0.3, math.radians(4.0)))
    assert not run(window, truth, (0.1, 0.3, math.radians(4.0))).kept


def test_the_localiser_keeps_the_windows_odometry_and_counts_it() -> None:
    params = Albot1Config.model_validate(
        {**Albot1Mapper.presets["plus"], "window_updates": 4, "window_probability": 0.5}
    ).plus_params()
    loc = PlusLocaliser(params, KERNELS, 30.0)
    assert loc.window is not None
    # Two update views (the window needs two): the older one is the anchor; both saw the room from the origin.
    loc.reset(ROOM, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    loc.reset(transform_segments((0.0, 0.0, 0.0), ROOM), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    truth = (0.2, 0.5, math.radians(3.0))
    empty_kinds = (np.empty((0, 2), dtype=np.int64), np.empty((0, 2), dtype=np.int64))
    pose = loc.pose(
        start_poses(truth, None, None), np.empty((0, 4)), np.empty((0, 4)), empty_kinds, room_points(truth), truth,
        rep(truth),
    )  # fmt: skip
    assert pose == pytest.approx(compose_pose((0.0, 0.0, 0.0), truth), abs=1e-12)
    assert loc.window_views == 1 and loc.ambiguous_views == 0


def test_the_window_is_off_in_every_thesis_preset_and_without_the_ambiguity_test() -> None:
    for name in ("default", "thesis", "exact", "literal"):
        config = Albot1Config.model_validate({**Albot1Mapper.presets["default"], **Albot1Mapper.presets[name]})
        assert config.window_updates == 0
        assert PlusLocaliser(config.plus_params(), KERNELS, 30.0).window is None
    params = Albot1Config.model_validate(
        {**Albot1Mapper.presets["plus"], "window_updates": 4, "ambiguity_probability": 0.0}
    ).plus_params()
    assert PlusLocaliser(params, KERNELS, 30.0).window is None
