"""Graph-based SLAM with GTSAM (Grisetti et al. 2010), behind the mapper protocol.

Modules: :mod:`.mapper` (:class:`GtsamGraphMapper`, the thin composition
of the four parts below), :mod:`.frontend` (scan tracking and sequential
edges), :mod:`.loop_closer` (loop closures near the estimate, and the book of
every closure), :mod:`.place_recognition` (branch-and-bound search over the
region the drift allows), :mod:`.backend` (the graph, node estimates and
scans, final optimisation, scan poses and map projection); the maths they
use: :mod:`.registration` (2D point-to-line ICP), :mod:`.correlative`
(coarse correlative and branch-and-bound search), :mod:`.loop_closure`
(candidate search and acceptance tests), :mod:`.refine` (non-node scan
poses), :mod:`.graph` (GTSAM factors, ISAM2, final Levenberg-Marquardt),
:mod:`.config` and :mod:`.errors`. GTSAM itself is imported only when a graph is
built; docs/baselines.md has the design and the measurements.
"""

from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.mapper import GtsamGraphMapper

__all__ = ["GtsamGraphConfig", "GtsamGraphMapper"]
