"""The room Albot1+'s localiser tests share: an update view's surfaces, a scan of them from any pose, a localiser.

A helper module, not a test module: the turn bound, view noise and consistent information tests import it
(pytest puts this folder on ``sys.path``), so the room and its scans are defined once.
"""

from __future__ import annotations

import math

import numpy as np

from albot1.geometry import se2
from albot1.geometry.segments import transform_segments
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.mapping.mapper import Albot1Mapper
from albot1.methods.albot1.mapping.plus import PlusLocaliser

KERNELS = MappingKernels(False)  # the plain functions: exactness, not speed, is tested here
NO_KINDS = (np.empty((0, 2), dtype=np.int64), np.empty((0, 2), dtype=np.int64))
# The last update view's surfaces (thesis frame, the update view at the origin facing +y): a room and a box.
ROOM = np.array([[-3.0, 5.0, 3.0, 5.0], [3.0, 5.0, 3.0, 0.5], [-3.0, 0.5, -3.0, 5.0], [-0.5, 2.0, 0.5, 2.0]])
SINCE = (0.0, 0.5, 0.0)  # the odometry since the update: 0.5 m straight ahead


def scan_from(pose: tuple[float, float, float], jitter: float = 0.0) -> np.ndarray:
    """The room's surfaces sampled every 10 cm as a view at ``pose`` sees them (``jitter``: every other point off)."""
    seen = transform_segments(se2.inverse(pose), ROOM)
    out = []
    for x1, y1, x2, y2 in seen:
        t = np.linspace(0.0, 1.0, max(2, int(math.hypot(x2 - x1, y2 - y1) / 0.1)))
        out.append(np.column_stack([x1 + t * (x2 - x1), y1 + t * (y2 - y1)]))
    points = np.vstack(out)
    if jitter:
        points[::2, 1] += jitter
        points[1::2, 1] -= jitter
    return np.ascontiguousarray(points)


def localiser(**changes: float) -> PlusLocaliser:
    """A ``plus`` localiser (with ``changes`` to its config) whose last update view is :data:`ROOM` at the origin."""
    config = Albot1Config.model_validate({**Albot1Mapper.presets["plus"], **changes})
    loc = PlusLocaliser(config.plus_params(), KERNELS, 30.0)
    loc.reset(ROOM, (0.0, 0.0, 0.0))
    return loc
