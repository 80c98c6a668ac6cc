"""Every method's run folder holds map.geojson (and a point map also map.npz with the same values)."""

from __future__ import annotations

import gc
import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import shapely.geometry
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from albot1.contract import MapData
from albot1.data.open import open_sequence
from albot1.methods.registry import method_registry
from albot1.records import json_value
from albot1.runs.execute import run_method
from albot1.runs.folder import read_run, write_run
from albot1.runs.map_files import map_geojson, map_text, write_map


def test_segments_are_linestrings_with_their_properties() -> None:
    data = MapData(segments=np.array([[0.0, 0.0, 1.0, 0.5]]), segment_properties=[{"id": 3}])
    assert map_geojson(data) == {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {"id": 3},
                "geometry": {"type": "LineString", "coordinates": [[0.0, 0.0], [1.0, 0.5]]},
            }
        ],
    }


def test_points_are_one_multipoint_of_the_stored_float32_values(tmp_path: Path) -> None:
    points = np.array([[0.1, -2.3], [1e-3, 4.0]])
    assert write_map(tmp_path, MapData(points=points)) == "map.npz"
    collection = json.loads((tmp_path / "map.geojson").read_text())
    (feature,) = collection["features"]
    assert feature["properties"] == {"kind": "points"}
    assert feature["geometry"]["coordinates"] == [[0.1, -2.3], [0.001, 4.0]]  # shortest form of the float32 values
    with np.load(tmp_path / "map.npz") as npz:
        np.testing.assert_array_equal(np.asarray(feature["geometry"]["coordinates"], dtype=np.float32), npz["points"])
    assert write_map(tmp_path, MapData(points=np.empty((0, 2)))) == "map.npz"
    assert json.loads((tmp_path / "map.geojson").read_text())["features"] == []


@pytest.mark.slow  # the Albot1 kernels compile on a code version's first run
@pytest.mark.parametrize("method", method_registry().names())
def test_every_method_writes_map_geojson(method: str, tmp_path: Path) -> None:
    spec = method_registry().get(method)
    if not spec.available():
        pytest.skip(f"{method} is not installed here: {spec.unavailable_reason()}")
    result = run_method(method, open_sequence("synthetic-office-loop[:40]"))
    run_dir = write_run(result, tmp_path)
    collection = json.loads((run_dir / "map.geojson").read_text())
    geometries = [shapely.geometry.shape(f["geometry"]) for f in collection["features"]]
    assert geometries, f"{method}: empty map.geojson"
    stored = read_run(run_dir).load_map()
    if result.map.segments is not None:
        assert not (run_dir / "map.npz").exists()
        assert [g.geom_type for g in geometries] == ["LineString"] * len(result.map.segments)
    else:
        assert [g.geom_type for g in geometries] == ["MultiPoint"]
        assert stored.points is not None
        assert len(geometries[0].geoms) == len(stored.points)
        np.testing.assert_allclose(np.array([(p.x, p.y) for p in geometries[0].geoms]), stored.points, atol=1e-6)


def _reference_text(data: MapData) -> str:
    """The writer before the fast path: ``json.dumps`` of :func:`map_geojson` (non-finite values as null)."""
    return json.dumps(json_value(map_geojson(data)), separators=(",", ":")) + "\n"


@given(
    arrays(
        np.float32,
        st.tuples(st.integers(0, 40), st.just(2)),
        elements=st.floats(width=32, allow_nan=True, allow_infinity=True, allow_subnormal=True),
    )
)
@settings(max_examples=200, deadline=None)
def test_point_map_text_is_the_dictionary_dumped(points: np.ndarray) -> None:
    data = MapData(points=points)
    assert map_text(data) == _reference_text(data)


@pytest.mark.parametrize(
    "value",
    [
        0.0,
        -0.0,
        1e-4,
        9.999999e-5,
        1e-5,
        1.5e-45,
        3.4028235e38,
        1e6,
        999999.9,
        1234567.0,
        1e8,
        99999990.0,
        1e16,
        123456789.0,
        0.1,
        -2.3,
    ],
)
def test_point_map_text_at_the_notation_boundaries(value: float) -> None:
    data = MapData(points=np.array([[value, -value], [np.float32(value) / 3, 1.0]], dtype=np.float32))
    assert map_text(data) == _reference_text(data)


def test_every_float32_exponent_is_written_as_the_dictionary_dumped() -> None:
    """64 random mantissas per binary exponent and sign (inf and NaN among them): every float32 magnitude."""
    rng = np.random.default_rng(7)
    bits = (np.arange(256, dtype=np.uint32).repeat(64) << 23) | rng.integers(0, 1 << 23, 256 * 64, dtype=np.uint32)
    values = bits.view(np.float32)
    values = np.concatenate([values, -values])
    with np.errstate(invalid="ignore"):  # signalling NaN bit patterns among them
        data = MapData(points=values.reshape(-1, 2).astype(np.float64))  # exact; stored as float32 again
    assert map_text(data) == _reference_text(data)


def test_segment_map_text_is_the_dictionary_dumped() -> None:
    data = MapData(segments=np.array([[0.1, 0.2, 1e-7, 3.0]]), segment_properties=[{"id": 1}], points=np.ones((2, 2)))
    assert map_text(data) == _reference_text(data)


@given(
    arrays(np.float64, st.tuples(st.integers(0, 6), st.just(4)), elements=st.floats(allow_infinity=True)),
    st.none() | arrays(np.float64, st.tuples(st.integers(0, 3), st.just(2)), elements=st.floats(allow_nan=True)),
)
@settings(max_examples=200, deadline=None)
def test_segment_map_text_is_the_dictionary_dumped_non_finite_included(
    segments: np.ndarray, points: np.ndarray | None
) -> None:
    data = MapData(segments=segments, segment_properties=[{"n": float(i)} for i in range(len(segments))], points=points)
    assert map_text(data) == _reference_text(data)


def test_the_point_map_file_is_closed_by_the_writer_not_left_to_the_collector(tmp_path: Path) -> None:
    # The .npz was written through a handle nobody closed: flushed only when the interpreter freed it.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ResourceWarning)
        assert write_map(tmp_path, MapData(points=np.array([[0.5, 1.5]]))) == "map.npz"
        gc.collect()
    assert [str(w.message) for w in caught if issubclass(w.category, ResourceWarning)] == []
    with np.load(tmp_path / "map.npz") as npz:
        assert npz["points"].tolist() == [[0.5, 1.5]]


def test_the_point_map_file_is_stored_not_deflated_and_reads_back_the_same_array(tmp_path: Path) -> None:
    """``map.npz`` holds one ``points.npy`` member, stored: float32 coordinates deflate by ~10 % for ~15x the CPU
    of storing them (session 24); ``np.load`` reads back exactly the float32 values written."""
    import zipfile

    points = np.random.default_rng(3).uniform(-40, 40, (5000, 2)).astype(np.float32)
    assert write_map(tmp_path, MapData(points=points)) == "map.npz"
    with zipfile.ZipFile(tmp_path / "map.npz") as archive:
        assert [(m.filename, m.compress_type) for m in archive.infolist()] == [("points.npy", zipfile.ZIP_STORED)]
    with np.load(tmp_path / "map.npz", allow_pickle=False) as npz:
        assert npz["points"].dtype == np.float32
        np.testing.assert_array_equal(npz["points"], points)


def test_geometry_points_are_the_bits_of_one_linspace_per_segment() -> None:
    """MapData.geometry_points samples every segment at once: the same points, bit for bit, as a loop of linspace."""
    import numpy as np

    from albot1.contract import MapData

    def by_loop(segments: np.ndarray, spacing: float = 0.05) -> np.ndarray:
        lengths = np.hypot(segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1])
        counts = np.maximum(2, np.ceil(lengths / spacing).astype(int) + 1)
        return np.concatenate(
            [s[:2] + np.linspace(0.0, 1.0, n)[:, None] * (s[2:] - s[:2]) for s, n in zip(segments, counts)]
        )

    rng = np.random.default_rng(11)
    for scale in (0.001, 0.03, 1.0, 40.0):
        segments = rng.normal(scale=scale, size=(500, 4)) + rng.normal(scale=80.0, size=(1, 4))
        segments[:50, 2:] = segments[:50, :2]  # zero-length segments: two points each
        got = MapData(segments=segments).geometry_points()
        assert got.shape == by_loop(segments).shape
        assert got.tobytes() == by_loop(segments).tobytes()
    points = rng.normal(size=(7, 2))
    both = MapData(segments=segments[:3], points=points).geometry_points()
    assert both.tobytes() == np.concatenate([by_loop(segments[:3]), points]).tobytes()
