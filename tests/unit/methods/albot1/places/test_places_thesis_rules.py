"""Chapter 4's rules at their boundaries: each threshold strict or not as 4.1.2 and Algorithm 6 word it.

4.1.2: "it is considered surfaces with a length > 40cm and two surfaces are
considered the same if they are not separated by a gap > 40cm and the angle
between them is < 5 deg"; the trigger fires on "more than n co-locating
surfaces"; Algorithm 6 line 11 confirms when "Matched_Surfaces > 4 and they
are located on both sides of the robot's current position". Each test puts a
case exactly on the threshold (the value the code itself computes there, so
floating point cannot blur it), so turning a strict comparison into a
non-strict one, or the other way round, fails a test. docs/places.md,
"Chapter 4 rule by rule", lists the rules and these tests.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from albot1.geometry.se2 import wrap_angle
from albot1.methods.albot1.mapping.mapper import UpdateEvent
from albot1.methods.albot1.mapping.update import UpdateOutcome
from albot1.methods.albot1.places import match_kernels
from albot1.methods.albot1.places.config import Albot1PlacesConfig, PlacesFields
from albot1.methods.albot1.places.kernels import PlacesKernels
from albot1.methods.albot1.places.mapper import Albot1PlacesMapper
from albot1.methods.albot1.places.matcher import centre, robot_sides, structural, trigger_threshold
from albot1.methods.albot1.places.memory import same_surfaces

KERNELS = [PlacesKernels(False), PlacesKernels(True)]
PARAMS = Albot1PlacesConfig().match_params()

#: The direction of (0, -0.5) -> (10, 0.5) against a surface along +x, as the kernels compute it: the boundary angle.
TILT = abs(wrap_angle(math.atan2(1.0, 10.0) - 0.0))


def test_the_thesis_values_are_the_defaults_in_metres_and_radians() -> None:
    """40 cm, 40 cm, 5 deg and "> 4" (4.1.2, Algorithm 6 line 11), converted once from the config's units."""
    assert (PARAMS.min_surface, PARAMS.gap, PARAMS.min_matches) == (0.4, 0.4, 5)
    assert PARAMS.angle == pytest.approx(math.radians(5.0))


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_a_place_is_described_by_surfaces_longer_than_40_cm_only(kernels) -> None:
    """4.1.2 "length > 40cm": a surface exactly 40 cm long is not part of a place's structure."""
    surfaces = np.array([[0.0, 0.0, 0.4, 0.0], [0.0, 2.0, 0.5, 2.0], [0.0, 4.0, 0.4, 4.0]])
    kept = structural(surfaces, PARAMS, kernels)
    np.testing.assert_array_equal(kept, [[0.0, 2.0, 0.5, 2.0]])


def count(current: list[list[float]], remembered: list[list[float]], sides: list[int], angle: float, gap: float):
    """Algorithm 6 lines 5-10 for the identity hypothesis: (matches, a match left, a match right)."""
    cur, rem = np.array(current, dtype=float), np.array(remembered, dtype=float)
    dir_j = np.arctan2(cur[:, 3] - cur[:, 1], cur[:, 2] - cur[:, 0])
    dir_k = np.arctan2(rem[:, 3] - rem[:, 1], rem[:, 2] - rem[:, 0])
    partner = np.empty(len(rem), dtype=np.int64)
    side = np.array(sides, dtype=np.int64)
    return match_kernels._count_matches(cur, dir_j, side, rem, dir_k, 0.0, 0.0, 0.0, angle, gap, partner)


def test_surfaces_at_exactly_the_angle_threshold_do_not_match() -> None:
    """4.1.2 "the angle between them is < 5 deg": strict (here with the threshold set to the pair's own angle)."""
    wall = [[0.0, 0.0, 10.0, 0.0]]
    tilted = [[0.0, -0.5, 10.0, 0.5]]  # across the wall's midpoint: the angle alone differs
    assert count(wall, tilted, [1], TILT, 0.4)[0] == 0
    assert count(wall, tilted, [1], math.nextafter(TILT, 1.0), 0.4)[0] == 1
    # directions are directed (chapter 3's reading): the other face of a wall is not the same surface
    assert count(wall, [[10.0, 0.0, 0.0, 0.0]], [1], PARAMS.angle, 0.4)[0] == 0


def test_surfaces_separated_by_exactly_40_cm_match() -> None:
    """4.1.2 "not separated by a gap > 40cm": a gap of exactly 40 cm is still the same surface."""
    wall = [[0.0, 0.0, 4.0, 0.0]]
    assert count(wall, [[1.0, 0.4, 3.0, 0.4]], [1], PARAMS.angle, 0.4)[0] == 1
    assert count(wall, [[1.0, 0.41, 3.0, 0.41]], [1], PARAMS.angle, 0.4)[0] == 0
    # the same when the current surface is the shorter one
    assert count([[1.0, 0.4, 3.0, 0.4]], wall, [1], PARAMS.angle, 0.4)[0] == 1
    assert count([[1.0, 0.41, 3.0, 0.41]], wall, [1], PARAMS.angle, 0.4)[0] == 0


def test_same_surfaces_when_combining_places_uses_the_same_thresholds() -> None:
    """Algorithm 5 line 11's combining (and merging) treats "the same" as 4.1.2 does: < 5 deg, gap <= 40 cm."""
    wall = np.array([[0.0, 0.0, 10.0, 0.0]])
    others = np.array([[0.0, 0.4, 10.0, 0.4], [0.0, 0.41, 10.0, 0.41], [0.0, 0.0, 10.0, 1.0]])
    expected = [[True, False, False]]
    assert same_surfaces(wall, others, TILT, 0.4).tolist() == expected
    for kernels in KERNELS:
        _, found = kernels.same_any(wall, others, TILT, 0.4)
        assert [found.tolist()] == expected
    assert same_surfaces(wall, others[2:], math.nextafter(TILT, 1.0), 0.4).tolist() == [[True]]


def test_a_match_on_the_robots_heading_line_is_on_neither_side() -> None:
    """Line 11 "on both sides of the robot's current position": left and right of its heading; on it, neither."""
    pose = (0.0, 0.0, 0.0)  # thesis frame: facing +y, left is -x
    surfaces = np.array([[-2.0, 1.0, -1.0, 1.0], [1.0, 1.0, 2.0, 1.0], [-0.5, 3.0, 0.5, 3.0]])
    assert robot_sides(surfaces, pose).tolist() == [-1, 1, 0]
    walls = [[-2.0, 1.0, -1.0, 1.0], [-0.5, 3.0, 0.5, 3.0]]
    assert count(walls, walls, [-1, 0], PARAMS.angle, 0.4)[1:] == (True, False)
    assert count(walls, walls, [0, 1], PARAMS.angle, 0.4)[1:] == (False, True)


# Five walls of a room (own frame = map frame here), three left of the robot at the origin and two right.
FIVE = np.array(
    [
        [-3.0, -2.0, -3.0, 4.0],
        [-2.0, 5.0, -1.0, 5.0],
        [-2.5, 1.0, -1.5, 2.0],
        [3.0, 4.0, 3.0, -2.0],
        [1.0, 5.0, 2.0, 5.0],
    ]
)


def confirms(current: np.ndarray, sides: list[int], kernels: PlacesKernels) -> tuple[bool, int]:
    found, matches, *_ = kernels.match_structure(
        current,
        np.array(sides, dtype=np.int64),
        FIVE,
        PARAMS.angle,
        PARAMS.gap,
        PARAMS.min_matches,
        PARAMS.anchors,
        np.empty((0, 2)),
        np.zeros(1, dtype=np.int64),
        PARAMS.max_conflicts,
        np.zeros(3),
        centre(FIVE),
        PARAMS.max_turn,
        PARAMS.max_shift,
    )
    return bool(found), int(matches)


@pytest.mark.parametrize("kernels", KERNELS, ids=["plain", "jit"])
def test_more_than_four_matches_on_both_sides_confirm(kernels) -> None:
    """Line 11: five matches with some left and some right confirm; four, or five on one side, do not."""
    assert confirms(FIVE, [-1, -1, -1, 1, 1], kernels) == (True, 5)
    assert confirms(FIVE[:4], [-1, -1, -1, 1], kernels) == (False, 4)
    assert confirms(FIVE, [-1, -1, -1, -1, -1], kernels) == (False, 5)
    assert confirms(FIVE, [-1, -1, -1, 0, 0], kernels) == (False, 5)  # on the heading line: no side


def test_more_than_n_co_locating_surfaces_trigger_a_check() -> None:
    """4.1.2 "finds there are more than n co-locating surfaces": n of them are not enough, n + 1 trigger it."""
    mapper = Albot1PlacesMapper(Albot1PlacesConfig(accelerate=False))
    network = mapper.network
    kernels = PlacesKernels(False)
    door = np.array([5.0, 1.0, 5.0, 2.0])
    room = np.array(
        [[0.0, 0.0, 5.0, 0.0], [5.0, 3.0, 0.0, 3.0], [0.0, 3.0, 0.0, 0.0], [1.0, 0.5, 2.0, 1.5], [3.0, 2.5, 4.0, 2.0]]
    )
    for scan in (0, 10):  # place 0 (the room), then place 1 (just left: never a candidate)
        visit = network.start_visit(scan, (0.0, 0.0, 0.0))
        network.close(visit, room, door, scan + 10)
    network.start_visit(20, (0.0, 0.0, 0.0))
    n = trigger_threshold(len(structural(room, mapper._match, kernels)), mapper._match)
    assert n == 4
    mapper._evidence = {0: set(range(n))}
    mapper._recognise((1.0, 1.0, 0.0), 30)
    assert mapper._counts.match_attempts == 0
    mapper._evidence = {0: set(range(n + 1))}
    mapper._recognise((1.0, 1.0, 0.0), 30)
    assert mapper._counts.match_attempts == 1


def test_the_literal_trigger_counts_only_surfaces_longer_than_40_cm() -> None:
    """4.1.2 "it is considered surfaces with a length > 40cm" holds for the co-locating surfaces too.

    ``revisit_evidence = "perceptual_map"`` (the literal preset) counts the map surfaces an update deletes or
    edits by the places they were marked with; a piece 40 cm long or shorter is no evidence. (On
    synthetic-places-loop 15 of the 101 surfaces it used to count were such pieces.)
    """
    mapper = Albot1PlacesMapper(Albot1PlacesConfig(revisit_evidence="perceptual_map", accelerate=False))
    network = mapper.network
    for scan in (0, 10):
        visit = network.start_visit(scan, (0.0, 0.0, 0.0))
        network.close(visit, np.empty((0, 4)), np.array([5.0, 1.0, 5.0, 2.0]), scan + 10)
    network.start_visit(20, (0.0, 0.0, 0.0))
    ids = mapper.inner.map.add(np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.4, 1.0], [0.0, 2.0, 0.3, 2.0]]), 5)
    mapper._labels = [{0} for _ in ids]  # marked by visit 0, now place 0
    none = np.empty(0, dtype=np.int64)
    outcome = UpdateOutcome(view_ids=none, deleted=ids[:2], extended=ids[2:], trimmed=none, added=none)
    mapper._map_evidence(UpdateEvent(30, "current", 30, (3.0, 3.0, 0.0), outcome, np.empty((0, 4))))
    assert mapper._evidence == {0: {int(ids[0])}}


#: Chapter 4's words the config's field descriptions quote, from albot1-thesis.md without its math marks (4.1.1,
#: Algorithms 6-7, 4.2.3). A description that quotes anything else quotes words the thesis does not have.
THESIS_WORDS = (
    "an office-like environment with well-defined exits (i.e. doorway, a gap whose typical size is about 1 meter",
    "Matched_Surfaces > 4 and they are located on both sides of the robot's current position",
    "Transform S_k onto the metric map of P_c centering on S_j",
    "the robot should find an exit in its perceptual map that co-locates with the physical exit encountered",
)


def test_the_field_descriptions_quote_only_words_the_thesis_has() -> None:
    """``albot1 methods --presets`` shows these descriptions: a quotation in them must be the thesis's own."""
    quoted = re.compile(r"(?<![A-Za-z])'([^']+?)'(?![A-Za-z])")
    for name, field in PlacesFields.model_fields.items():
        for words in quoted.findall(field.description or ""):
            assert any(words in text for text in THESIS_WORDS), f"{name}: {words!r} is not the thesis's"
