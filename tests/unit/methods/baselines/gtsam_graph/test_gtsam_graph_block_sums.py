"""Place recognition's compiled block sums give numpy's bits: its pairwise row sums, clipped lookups, the warm-up."""

from __future__ import annotations

import numpy as np
import pytest

from albot1.data import open_sequence
from albot1.methods.albot1.compiled import as_written
from albot1.methods.baselines.gtsam_graph import block_sums
from albot1.methods.baselines.gtsam_graph.block_sums import block_sums as block_sums_kernel
from albot1.runs.execute import run_method


def _row_sums(values: np.ndarray, fn: object = block_sums_kernel) -> np.ndarray:
    """``values.sum(axis=1)`` through the kernel: the table is the rows, each node one row's cells in order."""
    rows, n = values.shape
    base = np.stack([np.zeros((rows, n), dtype=np.int64), np.tile(np.arange(n), (rows, 1))], axis=-1)
    base[:, :, 0] = np.arange(rows)[:, None]
    out = np.empty(rows)
    fn(np.ascontiguousarray(values), base, np.arange(rows), np.zeros((rows, 2), dtype=np.int64), out)  # type: ignore[operator]
    return out


@pytest.mark.parametrize("scale", [1.0, 1e-3, 1e3])
def test_row_sums_of_every_length_are_numpy_s_bit_for_bit(scale: float) -> None:
    """numpy's pairwise summation: fewer than 8 values, up to 128 (eight running sums), longer (split in halves).

    Values of mixed magnitudes and many zeros, as a pooled likelihood field holds, so a different order of the
    additions shows in the last bits (a plain left-to-right sum differs on most of these rows).
    """
    rng = np.random.default_rng(3)
    plain_differs = 0
    for n in [*range(1, 301), 511, 1000, 5003]:
        values = rng.random((4, n)) * rng.choice([1e-4, scale, 1e4], size=(4, n))
        values[rng.random(values.shape) < 0.3] = 0.0
        assert _row_sums(values).tobytes() == values.sum(axis=1).tobytes(), n
        plain_differs += sum(float(sum(row.tolist())) != s for row, s in zip(values, values.sum(axis=1), strict=True))
    assert plain_differs > 100  # the order matters on these rows: the test can tell numpy's order from another


def test_clipped_block_sums_are_the_numpy_lookups_bit_for_bit_compiled_or_not() -> None:
    """Nodes whose lookups fall off every side of the table (clipped to its edge), at rows longer than 128."""
    rng = np.random.default_rng(5)
    table = rng.random((37, 53)) * 10.0
    base = rng.integers(-12, 66, size=(6, 200, 2))
    rot = rng.integers(0, 6, size=700)
    origin = rng.integers(-9, 9, size=(700, 2))
    idx = np.clip(base[rot] + origin[:, None, :], 0, np.array(table.shape) - 1)
    expected = table[idx[..., 0], idx[..., 1]].sum(axis=1)
    for axis, last in enumerate((36, 52)):  # every edge was reached
        assert (idx[..., axis] == 0).any() and (idx[..., axis] == last).any()
    for fn in (block_sums_kernel, as_written(block_sums_kernel)):
        out = np.empty(len(rot))
        fn(table, base, rot, origin, out)
        assert out.tobytes() == expected.tobytes()


def test_nodes_without_points_sum_to_zero_as_numpy_s_empty_rows() -> None:
    out = np.full(3, np.nan)
    block_sums_kernel(np.ones((4, 4)), np.empty((2, 0, 2), dtype=np.int64), np.zeros(3, dtype=np.int64),
                      np.zeros((3, 2), dtype=np.int64), out)  # fmt: skip
    assert out.tobytes() == np.zeros((3, 0)).sum(axis=1).tobytes()


def test_after_the_warm_up_a_run_compiles_nothing_and_a_cached_warm_up_says_nothing() -> None:
    said: list[str] = []
    block_sums.warm_up()
    block_sums.warm_up(said.append)
    assert said == []
    before = len(block_sums_kernel.signatures)  # type: ignore[attr-defined]
    run_method("gtsam-graph", open_sequence("synthetic-office-loop[:200]"))
    assert len(block_sums_kernel.signatures) == before  # type: ignore[attr-defined]
