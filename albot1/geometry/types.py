"""The array aliases every layer shares, declared once.

`FloatArray` sits in `geometry`, the lowest layer that works with arrays, so
that loaders, methods, metrics and reports all name the same alias rather
than each declaring its own (issue 20, "one of each").
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["FloatArray"]

FloatArray = NDArray[np.float64]
"""A float64 numpy array of any shape (poses, points, ranges, maps)."""
