"""Group laws of SE(2) on random poses (hypothesis)."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from albot1.geometry import se2

coord = st.floats(-1e3, 1e3, allow_nan=False)
angle = st.floats(-10, 10, allow_nan=False)
pose = st.tuples(coord, coord, angle).map(lambda t: np.array(t, dtype=float))


def _close(a: np.ndarray, b: np.ndarray) -> None:
    np.testing.assert_allclose(a[:2], b[:2], atol=1e-6)
    assert abs(se2.wrap(a[2] - b[2])) < 1e-9


@given(pose, pose, pose)
def test_associative(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> None:
    _close(se2.compose(se2.compose(a, b), c), se2.compose(a, se2.compose(b, c)))


@given(pose, pose)
def test_between_recovers(a: np.ndarray, b: np.ndarray) -> None:
    _close(se2.compose(a, se2.between(a, b)), b)


@given(pose, pose)
def test_relative_pose_invariant_under_common_transform(a: np.ndarray, b: np.ndarray) -> None:
    g = np.array([3.0, -7.0, 1.2])
    _close(se2.between(se2.compose(g, a), se2.compose(g, b)), se2.between(a, b))


@given(pose, pose)
def test_scalar_and_vectorised_forms_agree(a: np.ndarray, b: np.ndarray) -> None:
    for scalar, vectorised in ((se2.compose_pose, se2.compose), (se2.between_pose, se2.between)):
        got, want = np.array(scalar(tuple(a.tolist()), tuple(b.tolist()))), vectorised(a, b)
        np.testing.assert_allclose(got[:2], want[:2], rtol=1e-12, atol=1e-9)
        assert got[2] == want[2]  # one wrap: the same bits


@given(angle)
def test_wrap_angle_is_the_vectorised_wrap(a: float) -> None:
    assert se2.wrap_angle(a) == float(se2.wrap(a))
    assert -np.pi <= se2.wrap_angle(a) < np.pi
