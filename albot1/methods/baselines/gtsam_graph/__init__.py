"""Graph-based SLAM with GTSAM (Grisetti et al. 2010), behind the mapper protocol.

Modules: :mod:`.registration` (2D point-to-line ICP), :mod:`.correlative`
(coarse correlative search seeding loop matches), :mod:`.loop_closure`
(candidate search and acceptance tests), :mod:`.graph` (GTSAM factors, ISAM2,
final Levenberg-Marquardt), :mod:`.config`, :mod:`.errors` and :mod:`.mapper`
(:class:`GtsamGraphMapper`). GTSAM itself is imported only when a graph is
built; docs/baselines.md has the design and the measurements.
"""

from albot1.methods.baselines.gtsam_graph.config import GtsamGraphConfig
from albot1.methods.baselines.gtsam_graph.mapper import GtsamGraphMapper

__all__ = ["GtsamGraphConfig", "GtsamGraphMapper"]
