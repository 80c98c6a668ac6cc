"""Landmark surfaces (thesis 3.1.4): long enough and with a stable endpoint.

Endpoint labels (set during view construction, which sees the raw beams):

* ``OCCLUDING``: a cluster end whose next beam with a return, looking
  outward, is farther away: the surface is in front and its end is a real
  edge (Figure 3.7's p3, p6).
* ``CORNER``: a point shared by two pieces of one cluster that turn by at
  least the corner angle (p1, p2).
* ``OCCLUDED``: a cluster end with a nearer return beside it: the end is
  where something else hides the surface, and moves as the robot moves.
* ``UNSTABLE``: anything else: an end on the outermost beam or followed by
  no-return beams only up to the edge of the field of view, or a bend
  smaller than the corner angle.

Only occluding and corner endpoints are *stable*: they are the reference
points for recognition and localisation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from albot1.methods.albot1.perception.kernels import CORNER, OCCLUDED, OCCLUDING, UNSTABLE
from albot1.methods.albot1.perception.view import View

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

__all__ = ["CORNER", "OCCLUDED", "OCCLUDING", "UNSTABLE", "Landmarks", "find_landmarks", "stable"]


def stable(kinds: IntArray) -> NDArray[np.bool_]:
    """Mask of endpoint labels that can serve as reference points."""
    return (kinds == OCCLUDING) | (kinds == CORNER)


@dataclass(frozen=True, slots=True)
class Landmarks:
    """Landmark surfaces of one view: ``index`` into the view, their geometry and labels."""

    index: IntArray
    surfaces: FloatArray
    kinds: IntArray

    def __len__(self) -> int:
        return int(self.index.shape[0])


def find_landmarks(view: View, min_length: float) -> Landmarks:
    """``findLandmark``: surfaces at least ``min_length`` long with an occluding or corner end."""
    keep = (view.lengths >= min_length) & stable(view.kinds).any(axis=1)
    idx = np.flatnonzero(keep)
    return Landmarks(idx, view.surfaces[idx], view.kinds[idx])
