"""Landmark surfaces (thesis 3.1.4): long enough and with a stable endpoint.

The endpoint labels and the rule for which are stable live in
:mod:`albot1.methods.albot1.perception.endpoints` (set during view
construction, which sees the raw beams); they are re-exported here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from albot1.geometry.types import FloatArray
from albot1.methods.albot1.perception.endpoints import CORNER, OCCLUDED, OCCLUDING, STABLE, UNSTABLE
from albot1.methods.albot1.perception.kernels import PerceptionKernels
from albot1.methods.albot1.perception.view import View

IntArray = NDArray[np.int64]

__all__ = ["CORNER", "OCCLUDED", "OCCLUDING", "UNSTABLE", "Landmarks", "find_landmarks", "stable"]


def stable(kinds: IntArray) -> NDArray[np.bool_]:
    """Mask of endpoint labels that can serve as reference points."""
    return STABLE[kinds]


@dataclass(frozen=True, slots=True)
class Landmarks:
    """Landmark surfaces of one view: ``index`` into the view, their geometry and labels."""

    index: IntArray
    surfaces: FloatArray
    kinds: IntArray

    def __len__(self) -> int:
        return int(self.index.shape[0])


def find_landmarks(view: View, min_length: float, kernels: PerceptionKernels | None = None) -> Landmarks:
    """``findLandmark``: surfaces at least ``min_length`` long with an occluding or corner end (one kernel call)."""
    k = kernels or PerceptionKernels()
    return Landmarks(*k.landmark_rows(view.surfaces, view.kinds, min_length))
