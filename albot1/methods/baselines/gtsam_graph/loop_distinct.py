"""Is a loop match's pose the distinct best alignment around it? (Issue 21; off by default.)

ICP converges to the nearest minimum of its cost. Where a room repeats
along a corridor, or the submap holds a second wall close to the first, the
nearest minimum can be the wrong one, and it still passes every loop test:
inlier fraction, RMS, conditioning and even the confirmation (the next node
sees the same scene and falls into the same minimum). On seattle with
perfect odometry the two wrong closures the default accepts (0.40 and
0.21 m off) are such minima: a correlative search of +-2 m around the ICP
pose finds its best alignment 1.8 and 1.2 m away (docs/baselines.md,
gtsam-graph, "which closures are wrong with perfect odometry").

The check scores the likelihood-field alignment of the scan against the
candidate's submap on a grid around the ICP pose
(:func:`~albot1.methods.baselines.gtsam_graph.correlative.correlative_search`)
and refuses the match when the grid's best pose lies farther than the
search's ambiguity radius from the ICP pose (a distinct alignment scores
better: ICP sits in a local minimum), or when the best pose is ICP's but a
pose beyond that radius scores more than ``max_ambiguity`` of it (the ratio
test of the correlative seed, applied to every match).

Measured and left off: it also refuses right closures (orebro, edmonton,
intel and the synthetic office loop got worse; docs/baselines.md).
"""

from __future__ import annotations

import math

from albot1.geometry.types import FloatArray
from albot1.methods.baselines.gtsam_graph.correlative import SearchWindow, correlative_search


def distinct_alignment(
    target: FloatArray, source: FloatArray, pose: FloatArray, window: SearchWindow, max_ambiguity: float
) -> str:
    """``""`` when ``pose`` (source in the target frame) is the distinct best alignment of ``window``, else the reason.

    ``max_ambiguity`` = 1 leaves only the local-minimum test (the ratio of
    a rival to the best score never exceeds 1).
    """
    found = correlative_search(target, source, pose, window)
    offset_m = math.hypot(float(found.pose[0] - pose[0]), float(found.pose[1] - pose[1]))
    if offset_m > window.ambiguity_radius_m:
        return f"local minimum (a pose {offset_m:.1f} m away fits better)"
    if found.ambiguity > max_ambiguity:
        return f"indistinct ({found.ambiguity:.2f})"
    return ""
