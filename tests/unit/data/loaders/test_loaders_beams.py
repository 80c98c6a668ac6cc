from __future__ import annotations

import math

import numpy as np
import pytest

from albot1.data.loaders.beams import even_spacing


def test_even_spacing_accepts_uniform_and_rejects_irregular_beams() -> None:
    uniform = np.deg2rad(np.arange(-90.0, 90.0, 1.0))
    first, step = even_spacing(uniform)  # type: ignore[misc]
    assert first == uniform[0] and step == pytest.approx(math.radians(1.0), rel=1e-14)
    irregular = uniform.copy()
    irregular[10] += 1e-3
    assert even_spacing(irregular) is None
    assert even_spacing(np.array([0.3])) == (0.3, 0.0)


def test_even_spacing_refuses_non_finite_and_empty_angles() -> None:
    assert even_spacing(np.array([])) is None
    assert even_spacing(np.array([0.0, math.nan, 0.2])) is None
