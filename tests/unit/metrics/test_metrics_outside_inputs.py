"""Inputs the metrics had not seen (an outsider's check, metric49): signed errors, non-finite steps, non-loops.

Each test pins a defect found by feeding the metrics such inputs: a paired comparison of signed errors called
"better" with a negative ratio, and an RPE step of NaN or infinity escaped as a bare ValueError / OverflowError.
"""

from __future__ import annotations

import numpy as np
import pytest

from albot1.metrics.errors import MetricsError
from albot1.metrics.paired import NEGATIVE_ERROR, NOT_APPLICABLE, compare
from albot1.metrics.rpe import pair_indices, rpe


@pytest.mark.parametrize("power", [1, 2])
def test_signed_errors_are_not_compared(power: int) -> None:
    """A negative error is no magnitude: n/a with the reason, both ways (was ``better -1 [-1–-1]`` at power 1)."""
    a = np.linspace(0.1, 1.0, 30)
    for pairs in ([(-a, a)], [(a, -a)], [(a, a), (np.r_[a[:-1], -0.5], a)]):
        found = compare(pairs, power=power, resamples=20)
        assert (found.verdict, found.reason, found.text()) == (
            NOT_APPLICABLE,
            NEGATIVE_ERROR,
            f"n/a ({NEGATIVE_ERROR})",
        )
        assert found.mirrored().reason == NEGATIVE_ERROR
    assert compare([(a, a)], power=power, resamples=20).text() == "1 [1–1]"  # magnitudes still compare


@pytest.mark.parametrize("delta", [float("nan"), float("inf"), -float("inf")])
@pytest.mark.parametrize("unit", ["frames", "m"])
def test_a_non_finite_rpe_step_is_refused_in_words(delta: float, unit: str) -> None:
    ref = np.column_stack([np.arange(20) * 0.5, np.zeros(20), np.zeros(20)])
    with pytest.raises(MetricsError, match="expected a positive finite delta"):
        pair_indices(ref, delta, unit)  # type: ignore[arg-type]
    with pytest.raises(MetricsError, match="expected a positive finite delta"):
        rpe(ref, ref, delta, unit)  # type: ignore[arg-type]
