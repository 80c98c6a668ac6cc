"""float32 text by integer arithmetic: numpy's own strings, where a naive vectorisation would differ (session 26).

``map.geojson`` must keep its bytes: every coordinate written as numpy writes a float32 (Dragon4's shortest
round-trip digits). The values checked here are those where a shortcut goes wrong: the decimal boundaries
(0.099999994 is written 0.099999994, its neighbour above 0.1: a carry), powers of two (the float below is
nearer, so the interval is lopsided and the nearest short decimal can lie outside it), the edges of the range
written here (1e-4 and 1e6, where numpy changes notation), zeros of both signs, and every float32 of a few
whole binades. ``benchmarks/float32_text_exhaustive.py`` compares every float32 of the range (too slow here).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.dtypes import StringDType

from albot1.contract import MapData
from albot1.records import json_value
from albot1.runs.float32_text import field_texts, float32_fields, in_fast_range
from albot1.runs.map_files import map_geojson, map_text, numpy_texts, points_text


def _numpy(values: np.ndarray) -> list[str]:
    strings: list[str] = values.astype(StringDType()).tolist()
    return strings


def _around(centres: np.ndarray, ulps: int) -> np.ndarray:
    """Every float32 within ``ulps`` steps of each centre (float32), both signs."""
    bits = np.asarray(centres, dtype=np.float32).view(np.int32).astype(np.int64)
    near = (bits[:, None] + np.arange(-ulps, ulps + 1)[None, :]).reshape(-1)
    values = near.astype(np.int32).view(np.float32)
    return np.concatenate([values, -values])


def _assert_numpy_text(values: np.ndarray) -> None:
    """The fast range's values of ``values`` written by float32_fields as numpy writes them (one text, then each)."""
    fast = values[in_fast_range(values)]
    fields = float32_fields(fast, numpy_texts)
    lines = np.concatenate([fields, np.full((len(fields), 1), ord("\n"), dtype=np.uint8)], axis=1)
    if lines[lines != 0].tobytes().decode("ascii") == "".join(f"{text}\n" for text in _numpy(fast)):
        return
    wrong = [
        (repr(v), w, e) for v, w, e in zip(fast.tolist(), field_texts(fields), _numpy(fast), strict=True) if w != e
    ]
    raise AssertionError(f"{len(wrong)} values written otherwise than numpy writes them: {wrong[:10]}")


def test_decimal_boundaries_are_written_as_numpy_writes_them() -> None:
    powers = 10.0 ** np.arange(-3, 6)
    _assert_numpy_text(_around(np.concatenate([powers, 2 * powers, 5 * powers, 9.5 * powers]), 300))


def test_powers_of_two_and_their_neighbours_are_written_as_numpy_writes_them() -> None:
    _assert_numpy_text(_around(np.ldexp(np.float32(1.0), np.arange(-13, 20)).astype(np.float32), 300))


def test_every_float32_of_three_binades_is_written_as_numpy_writes_it() -> None:
    for exponent in (-13, 0, 9):  # near 1e-4, [1, 2) and [512, 1024)
        bits = (np.uint32(exponent + 127) << np.uint32(23)) + np.arange(1 << 23, dtype=np.uint32)
        _assert_numpy_text(bits.view(np.float32)[::29])  # every 29th significand: 289,262 of each binade


def test_the_range_s_edges_and_zeros() -> None:
    edges = np.array([0.0, -0.0, 1e-4, 1e6], dtype=np.float32)
    around = _around(edges[2:], 50)
    assert not in_fast_range(np.array([1e-4, -1e-4, 1e6, 1e-5, 3e38], dtype=np.float32)).any()
    assert in_fast_range(np.array([0.0, -0.0, 1.0001e-4, 999999.94], dtype=np.float32)).all()
    values = np.concatenate([edges, around, np.array([1.5e-45, -3.4e38, 1e-5], dtype=np.float32)])
    written = field_texts(float32_fields(values, numpy_texts))
    assert written == numpy_texts(values)  # the fast range's text and the general path's, one by one
    assert written[:2] == ["0.0", "-0.0"]


def test_a_large_map_is_the_dictionary_dumped() -> None:
    rng = np.random.default_rng(26)
    points = np.concatenate(
        [
            rng.uniform(-500.0, 500.0, (30_000, 2)),
            rng.uniform(-1e-3, 1e-3, (2_000, 2)),  # tiny ones: some below 1e-4, written by the general path
            _around(np.array([0.1, 1.0, 2.0, 1e5], dtype=np.float32), 500).reshape(-1, 2),
        ]
    ).astype(np.float32)
    data = MapData(points=points)
    reference = json.dumps(json_value(map_geojson(data)), separators=(",", ":")) + "\n"
    assert map_text(data) == reference


@pytest.mark.parametrize("count", [1, 2_047, 2_048, 70_000])
def test_points_text_on_both_sides_of_its_thresholds(count: int) -> None:
    rng = np.random.default_rng(count)
    points = (rng.normal(0.0, 30.0, (count, 2)) * rng.choice([1e-6, 1.0], (count, 2))).astype(np.float32)
    strings = numpy_texts(points.reshape(-1))
    expected = "[[" + "],[".join(f"{x},{y}" for x, y in zip(strings[0::2], strings[1::2], strict=True)) + "]]"
    assert points_text(points) == expected
