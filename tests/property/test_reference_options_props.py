"""Property tests of the ``views=D_M:A_DEG`` parser and the view-spacing rule."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.errors import ReferenceOptionError
from albot1.data.model import Frame, Scan, Sequence
from albot1.data.open import parse_views
from albot1.data.transforms import SPACING_SLACK, view_spacing


@given(st.text(max_size=30))
def test_parse_views_returns_two_positive_numbers_or_one_clear_error(text: str) -> None:
    try:
        distance_m, angle_deg = parse_views(text, "ref")
    except ReferenceOptionError as exc:
        assert str(exc).startswith("'ref': views=")
        return
    assert math.isfinite(distance_m) and distance_m > 0 and math.isfinite(angle_deg) and angle_deg > 0


@given(st.floats(1e-6, 1e6), st.floats(1e-6, 360.0))
def test_parse_views_round_trips_numbers(d: float, a: float) -> None:
    assert parse_views(f"{d!r}:{a!r}", "x") == (d, a)


steps = st.lists(st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(-0.4, 0.4)), min_size=1, max_size=40)


@settings(max_examples=60, deadline=None)
@given(steps, st.floats(0.05, 2.0), st.floats(0.5, 45.0))
def test_kept_views_follow_the_rule(increments: list[tuple[float, float, float]], d: float, a_deg: float) -> None:
    """Each kept view reached D or A since the previous kept one; every dropped scan had reached neither."""
    poses = np.vstack([[0.0, 0.0, 0.0], np.cumsum(np.asarray(increments), axis=0)])
    angles = np.zeros(1)
    frames = [Frame(i, Scan(np.ones(1), angles, float(i), 30.0), poses[i].copy()) for i in range(len(poses))]
    kept = [int(t) for t in view_spacing(Sequence.from_frames("p", frames), d, a_deg).timestamps]
    assert kept[0] == 0
    last = 0
    for i in range(1, len(poses)):
        moved = float(np.hypot(*(poses[i, :2] - poses[last, :2])))
        turned = abs(math.remainder(poses[i, 2] - poses[last, 2], 2 * math.pi))
        reached = moved >= d - SPACING_SLACK or turned >= math.radians(a_deg) - SPACING_SLACK
        assert (i in kept) == reached
        if reached:
            last = i
