"""The navigation aid (thesis 4.2.3, Algorithms 7-8): a recognised place's exits predicted in the perceptual map.

"When adding exits of P_v to the perceptual map (step 13), one uses the exit
just crossed as a reference point for calculating the coordinates of the
exits of P_v in the perceptual map. These exits are stored in a separate
list." A place's exits are kept in its own frame with the place on their
left; the exit just crossed, seen from the place being entered, is put on
the place's record of that exit: the rigid motion turning the record's
direction onto the crossed exit's and its midpoint onto the crossed exit's
midpoint is where the place's frame lies in the map *now*
(:func:`align_at_exit`). The thesis's comparison (Figure 4.8) is with the
exits where they were first learned, unaligned (Figure 4.7's filled
rectangles): each record keeps that map position.

When the next exit is crossed, the prediction nearest to it (within twice
the link distance; farther, the exit is a new one) is the one it is
compared with (:func:`nearest_prediction`): the midpoint distance of the
aligned and of the not-aligned prediction from the exit actually perceived.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from albot1.geometry.se2 import Pose, rotate, wrap_angle
from albot1.geometry.segments import transform_segments
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.places.memory import ExitRecord


@dataclass(frozen=True, slots=True)
class Prediction:
    """An exit of a recognised place brought into the perceptual map at ``scan``."""

    exit: int
    place: int
    scan: int
    aligned: FloatArray
    not_aligned: FloatArray
    leads_to: int | None


def midpoint(segment: FloatArray) -> FloatArray:
    return 0.5 * (segment[:2] + segment[2:])


def align_at_exit(record: FloatArray, crossed: FloatArray) -> Pose:
    """The place frame's pose in the map that puts its exit ``record`` (own frame) onto ``crossed`` (map frame).

    Both run with the place on their left, so the rotation is unambiguous.
    """
    theta = wrap_angle(
        math.atan2(crossed[3] - crossed[1], crossed[2] - crossed[0])
        - math.atan2(record[3] - record[1], record[2] - record[0])
    )
    rm, cm = midpoint(record), midpoint(crossed)
    rx, ry = rotate(theta, rm[0], rm[1])
    return (float(cm[0] - rx), float(cm[1] - ry), theta)


def predict(
    exits: list[ExitRecord], place: int, place_in_map: Pose, scan: int, skip: int | None = None
) -> list[Prediction]:
    """Every exit of ``place`` but ``skip`` (the one just crossed) placed in the map at ``place_in_map``."""
    out = []
    for record in exits:
        if record.id == skip:
            continue
        aligned = transform_segments(place_in_map, record.segment)[0]
        out.append(Prediction(record.id, place, scan, aligned, record.learned_map.copy(), record.leads_to))
    return out


def nearest_prediction(
    predictions: list[Prediction], perceived: FloatArray, within: float
) -> tuple[Prediction, float, float] | None:
    """The prediction whose aligned midpoint is nearest ``perceived``'s, with its aligned and not-aligned distances.

    None when no aligned prediction lies within ``within``: the exit crossed
    is one the place did not know (a new way out), not a prediction's error.
    """
    if not predictions:
        return None
    here = midpoint(perceived)
    distances = [float(np.hypot(*(midpoint(p.aligned) - here))) for p in predictions]
    best = int(np.argmin(distances))
    if distances[best] > within:
        return None
    chosen = predictions[best]
    return chosen, distances[best], float(np.hypot(*(midpoint(chosen.not_aligned) - here)))
