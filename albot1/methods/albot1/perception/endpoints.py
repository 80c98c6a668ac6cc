"""Surface endpoint labels (thesis 3.1.4) and the one rule for which of them are stable.

View construction labels both ends of every surface (it is the only step
that sees the raw beams):

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
points of recognition and localisation. :data:`STABLE` is that rule as a
table indexed by label, so the compiled recognition kernel
(:func:`is_stable`), localisation (:func:`is_stable`) and landmark selection
(``STABLE[kinds]`` on arrays) read the same definition.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from albot1.methods.albot1.compiled import jitable

UNSTABLE = 0
OCCLUDING = 1
CORNER = 2
OCCLUDED = 3

#: ``STABLE[kind]``: whether an endpoint with that label is a reference point.
STABLE: NDArray[np.bool_] = np.zeros(4, dtype=np.bool_)
STABLE[[OCCLUDING, CORNER]] = True


@jitable
def is_stable(kind: int) -> bool:
    """Whether an endpoint labelled ``kind`` is stable (compiled into the recognition kernel)."""
    return bool(STABLE[kind])
