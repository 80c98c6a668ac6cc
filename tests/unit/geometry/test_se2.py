"""SE(2) helpers: exact cases and algebraic identities."""

from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.geometry import se2


def test_compose_known_case() -> None:
    a = np.array([1.0, 2.0, math.pi / 2])
    b = np.array([1.0, 0.0, 0.0])
    np.testing.assert_allclose(se2.compose(a, b), [1.0, 3.0, math.pi / 2], atol=1e-12)


def test_between_is_inverse_compose() -> None:
    a = np.array([1.0, -2.0, 0.3])
    b = np.array([4.0, 1.0, -2.9])
    np.testing.assert_allclose(se2.compose(a, se2.between(a, b)), b, atol=1e-12)
    np.testing.assert_allclose(se2.compose(se2.inverse(a), a), [0, 0, 0], atol=1e-12)


def test_matrix_round_trip() -> None:
    poses = np.array([[1.0, 2.0, 3.0], [-1.0, 0.5, -0.2]])
    np.testing.assert_allclose(se2.from_matrix(se2.to_matrix(poses)), poses, atol=1e-12)
    m = se2.to_matrix(poses[0]) @ se2.to_matrix(poses[1])
    np.testing.assert_allclose(se2.from_matrix(m), se2.compose(poses[0], poses[1]), atol=1e-12)


def test_transform_points_matches_matrix() -> None:
    pose = np.array([2.0, -1.0, 0.7])
    pts = np.array([[1.0, 0.0], [0.0, 2.0], [-3.0, 1.5]])
    homo = np.column_stack([pts, np.ones(3)]) @ se2.to_matrix(pose).T
    np.testing.assert_allclose(se2.transform_points(pose, pts), homo[:, :2], atol=1e-12)


def test_steps_round_trip() -> None:
    poses = np.array([[0, 0, 0], [1, 0, 0.1], [1.5, 0.4, 0.9], [1.0, 1.0, 3.1]], dtype=float)
    rebuilt = se2.integrate_steps(poses[0], se2.relative_steps(poses))
    np.testing.assert_allclose(rebuilt, poses, atol=1e-12)


def test_integrate_steps_equals_composing_step_by_step() -> None:
    rng = np.random.default_rng(9)
    steps = np.column_stack([rng.normal(0.3, 0.2, 300), rng.normal(0, 0.1, 300), rng.normal(0, 0.5, 300)])
    start = np.array([3.0, -1.0, 2.5])
    composed = [start]
    for step in steps:
        composed.append(se2.compose(composed[-1], step))
    got = se2.integrate_steps(start, steps)
    assert got.shape == (301, 3)
    np.testing.assert_allclose(got, np.array(composed), atol=1e-9)
    np.testing.assert_array_equal(se2.integrate_steps(start, np.empty((0, 3))), start[None, :])


def test_interpolate_is_interpolate_unwrapped_of_the_unwrapped_track() -> None:
    t = np.array([0.0, 1.0, 2.5, 4.0])
    poses = np.array([[0.0, 0.0, 3.0], [1.0, 2.0, -3.0], [2.0, 2.0, 2.9], [0.5, 1.0, -0.2]])
    query = np.array([0.3, 1.0, 1.7, 3.9])
    unwrapped = se2.unwrap_headings(poses)
    assert np.all(np.abs(np.diff(unwrapped[:, 2])) <= math.pi)
    assert np.array_equal(se2.interpolate(t, poses, query), se2.interpolate_unwrapped(t, unwrapped, query))


def test_interpolate_across_the_angle_seam() -> None:
    t = np.array([0.0, 1.0])
    poses = np.array([[0.0, 0.0, math.pi - 0.1], [2.0, 0.0, -math.pi + 0.1]])
    mid = se2.interpolate(t, poses, [0.5])[0]
    assert mid[0] == pytest.approx(1.0)
    assert abs(abs(mid[2]) - math.pi) < 1e-9


def test_wrap_range() -> None:
    wrapped = se2.wrap(np.linspace(-20, 20, 1001))
    assert wrapped.min() >= -math.pi and wrapped.max() < math.pi


def test_path_length() -> None:
    assert se2.path_length(np.array([[0, 0, 0], [3, 4, 1], [3, 5, 2]], dtype=float)) == pytest.approx(6.0)


def test_bad_shape_is_rejected() -> None:
    with pytest.raises(ValueError, match="last axis of length 3"):
        se2.compose(np.zeros(2), np.zeros(3))


def test_single_poses_take_the_fast_path_with_the_batch_s_bits(monkeypatch: pytest.MonkeyPatch) -> None:
    """``compose`` / ``between`` of two (3,) float64 poses: no ``np.stack`` (the fast path), the batch's bits.

    Headings cover the wrap's edges (pi, -pi, 2 pi, signed zeros, tiny and huge angles), where a different
    operation order or modulo would show.
    """
    rng = np.random.default_rng(12)
    n = 20_000
    a, b = rng.normal(0.0, 40.0, (n, 3)), rng.normal(0.0, 40.0, (n, 3))
    a[:, 2], b[:, 2] = rng.uniform(-8.0, 8.0, n), rng.uniform(-8.0, 8.0, n)
    edges = np.array([math.pi, -math.pi, 2 * math.pi, 0.0, -0.0, 1e-300, -1e-300, 1e10, math.nextafter(math.pi, 0.0)])
    a[: len(edges) ** 2, 2], b[: len(edges) ** 2, 2] = np.repeat(edges, len(edges)), np.tile(edges, len(edges))
    batch = {"compose": se2.compose(a, b), "between": se2.between(a, b)}

    def no_stack(*args: object, **kwargs: object) -> None:
        raise AssertionError("np.stack called for single poses: the fast path was not taken")

    monkeypatch.setattr(se2.np, "stack", no_stack)
    for name, fn in (("compose", se2.compose), ("between", se2.between)):
        single = np.array([fn(p, q) for p, q in zip(a, b, strict=True)])
        assert single.dtype == np.float64 and single.shape == (n, 3)
        assert single.tobytes() == batch[name].tobytes(), name


def test_scale_motion_follows_the_increment_s_arc_for_a_multiple_of_its_time() -> None:
    quarter = np.array([1.0, 0.0, math.pi / 2])
    # twice the time: the increment twice (the heading a half turn, wrapped to -pi)
    assert np.allclose(se2.scale_motion(quarter, 2.0), [1.0, 1.0, -math.pi], atol=1e-15)
    # half the time: half the arc, whose square is the increment again
    half = se2.scale_motion(quarter, 0.5)
    assert np.allclose(half, [0.5, -(math.sqrt(2.0) - 1.0) / 2.0, math.pi / 4], atol=1e-15)
    assert np.allclose(se2.compose(half, half), quarter, atol=1e-15)
    step = np.array([0.3, -0.1, 0.2])
    assert np.allclose(se2.scale_motion(step, 3.0), se2.compose(step, se2.compose(step, step)), atol=1e-15)
    assert np.allclose(se2.scale_motion(step, 3.0), [0.92914704, -0.11368646, 0.6], atol=1e-8)
    assert np.array_equal(se2.scale_motion(step, 0.0), [0.0, 0.0, 0.0])


def test_scale_motion_is_exact_at_ratio_one_and_continuous_through_a_straight_increment() -> None:
    step = np.array([0.3, -0.1, 0.2])
    assert se2.scale_motion(step, 1.0).tobytes() == step.tobytes()  # no rounding: the setting's "no change"
    assert np.array_equal(se2.scale_motion(np.array([0.3, 0.1, 0.0]), 2.5), [0.75, 0.25, 0.0])
    # a turn of 1e-12 rad scales like the straight step (half-angle sines: no cancellation)
    assert np.allclose(se2.scale_motion(np.array([0.3, 0.1, 1e-12]), 2.5), [0.75, 0.25, 2.5e-12], atol=1e-14)
    # a half turn either side of the seam: finite, and twice it is a whole turn
    assert np.allclose(se2.scale_motion(np.array([0.0, 1.0, -math.pi]), 2.0), [0.0, 0.0, 0.0], atol=1e-15)
