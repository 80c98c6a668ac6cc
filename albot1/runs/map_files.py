"""A run's map on disk: ``map.geojson`` for every method, ``map.npz`` beside it for point maps.

Every method writes ``map.geojson`` (the README promises it for every run,
and GIS tools, QGIS or shapely read it): line surfaces (Albot1) are one
``LineString`` feature each, with the surface's properties; a point map (the
scan-projecting baselines' grid-thinned points, see
:mod:`albot1.methods.baselines.point_map`) is one ``MultiPoint`` feature with
``kind = "points"``. A point map also keeps ``map.npz`` (compact, and the
file its ``result.json`` names and the metrics read), so existing results
read the same numbers; the GeoJSON coordinates are those very float32
values, written in their shortest decimal form. This is the one writer of
GeoJSON maps in the project.

:func:`map_geojson` defines the file's content. :func:`write_map` writes a
finite point map's text directly (:func:`points_text`) rather than through
``json.dumps`` of that dictionary: the same bytes (a property test compares
the two over all float32 values) in about half the time, and every
``albot1 bench`` cell of a point-map method pays it (``docs/benchmarking.md``,
"Cell start-up and the rest of a cell").
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from numpy.dtypes import StringDType

from albot1.atomic import atomic_write
from albot1.contract import MapData
from albot1.records import json_value
from albot1.runs.float32_text import FIELD, float32_fields

GEOJSON = "map.geojson"
NPZ = "map.npz"
_SEPARATORS = (",", ":")
#: Points of a map whose text is made at once (a block's rows take ~70 bytes a point while it is made).
_BLOCK_POINTS = 65_536
#: Maps smaller than this are written value by value by :func:`numpy_texts` (~0.5 ms of fixed cost saved).
_SMALL_MAP_POINTS = 2_048


def map_geojson(data: MapData) -> dict[str, Any]:
    """The GeoJSON FeatureCollection of ``data``: a LineString per segment, one MultiPoint of the points."""
    features: list[dict[str, Any]] = []
    if data.segments is not None:
        props = data.segment_properties or [{} for _ in range(len(data.segments))]
        for seg, prop in zip(np.asarray(data.segments, dtype=float).tolist(), props):
            features.append(
                {
                    "type": "Feature",
                    "properties": json_value(prop),
                    "geometry": {"type": "LineString", "coordinates": [[seg[0], seg[1]], [seg[2], seg[3]]]},
                }
            )
        points = np.asarray(data.points, dtype=float).reshape(-1, 2) if data.points is not None else None
    else:
        # a point map is stored as float32 (map.npz); the GeoJSON holds the same values
        points = _stored_points(data)
        points = points.astype(str).astype(np.float64)  # each float32's shortest decimal form, as a float64
    if points is not None and len(points):
        features.append(_points_feature(points.tolist()))
    return {"type": "FeatureCollection", "features": features}


def _points_feature(coordinates: Any) -> dict[str, Any]:
    return {
        "type": "Feature",
        "properties": {"kind": "points"},
        "geometry": {"type": "MultiPoint", "coordinates": coordinates},
    }


def points_text(points: np.ndarray) -> str:
    """``[[x,y],...]``: finite float32 ``points`` (n, 2) as ``json.dumps`` writes ``map_geojson``'s coordinates.

    Each coordinate's digits are numpy's float32-to-text (Dragon4, shortest round-trip digits), written for
    zero and 1e-4 < |x| < 1e6 by :mod:`albot1.runs.float32_text` (the same text, without Dragon4's ~0.5 us a
    value) and by :func:`numpy_texts` for the others. The rows are joined as bytes in blocks of
    :data:`_BLOCK_POINTS` points (one compress of NUL-padded rows each), not as a Python string per value.
    """
    points = np.asarray(points, dtype=np.float32).reshape(-1, 2)
    if len(points) < _SMALL_MAP_POINTS:  # a few numpy calls per decimal count cost more than Dragon4 saves here
        strings = numpy_texts(points.reshape(-1))
        return "[[" + "],[".join(f"{x},{y}" for x, y in zip(strings[0::2], strings[1::2], strict=True)) + "]]"
    blocks = []
    for start in range(0, len(points), _BLOCK_POINTS):
        fields = float32_fields(points[start : start + _BLOCK_POINTS].reshape(-1), numpy_texts)
        rows = np.zeros((len(fields) // 2, 2 * FIELD + 4), dtype=np.uint8)
        rows[:, :FIELD] = fields[0::2]
        rows[:, FIELD] = ord(",")
        rows[:, FIELD + 1 : 2 * FIELD + 1] = fields[1::2]
        rows[:, 2 * FIELD + 1 :] = np.frombuffer(b"],[", dtype=np.uint8)
        blocks.append(rows[rows != 0].tobytes())
    return "[[" + b"".join(blocks).decode("ascii")[:-3] + "]]"


def numpy_texts(values: np.ndarray) -> list[str]:
    """float32 ``values`` as ``json.dumps`` writes ``map_geojson``'s coordinates, one by one (the general path).

    numpy's float32-to-text (Dragon4, shortest round-trip digits) gives the
    digits; Python's ``repr`` of the float64 nearest to such a decimal (at most
    9 significant digits) has the same digits, so only the notation can
    differ: numpy switches to an exponent outside about [1e-4, 1e6), Python
    outside [1e-4, 1e16), and those few values are written by ``repr``.
    """
    strings: list[str] = np.asarray(values, dtype=np.float32).astype(StringDType()).tolist()
    return [repr(float(s)) if "e" in s else s for s in strings]


def _stored_points(data: MapData) -> np.ndarray:
    return np.asarray(data.points if data.points is not None else np.empty((0, 2)), dtype=np.float32).reshape(-1, 2)


def map_text(data: MapData) -> str:
    """The text of ``map.geojson`` for ``data``: ``map_geojson`` as compact JSON, one line."""
    if data.segments is None:
        points = _stored_points(data)
        if np.isfinite(points).all():
            if not len(points):
                return json.dumps({"type": "FeatureCollection", "features": []}, separators=_SEPARATORS) + "\n"
            frame = json.dumps({"type": "FeatureCollection", "features": [_points_feature([])]}, separators=_SEPARATORS)
            head, tail = frame.split('"coordinates":[]')
            return head + '"coordinates":' + points_text(points) + tail + "\n"
    collection = map_geojson(data)
    # Coordinates are Python floats already (``tolist``); only a non-finite one needs json_value's null. Walking
    # a 145,000-point map value by value cost 0.7 s per run folder (odometry on aces), so it is done only then;
    # whether it is needed is read from the arrays the features were made of.
    finite = all(np.isfinite(np.asarray(a, dtype=float)).all() for a in (data.segments, data.points) if a is not None)
    return json.dumps(collection if finite else json_value(collection), separators=_SEPARATORS) + "\n"


def write_map(run_dir: Path, data: MapData) -> str:
    """Write the map files of ``data`` into ``run_dir``; the name of the one ``result.json`` points to."""
    text = map_text(data)
    atomic_write(run_dir / GEOJSON, lambda p: p.write_text(text, encoding="utf-8"))
    if data.segments is not None:
        return GEOJSON
    points = _stored_points(data)
    atomic_write(run_dir / NPZ, lambda p: _write_npz(p, points))
    return NPZ


def _write_npz(path: Path, points: np.ndarray) -> None:
    """``points`` into ``path`` as an uncompressed ``.npz`` (``np.savez``), closed here.

    Closed before :func:`atomic_write` syncs and renames it, not by the
    collector. Stored, not deflated (``np.savez_compressed`` until session
    24): these float32 coordinates deflate by only ~10 %, and zlib spent
    ~9 ms of CPU on each point-map cell's file where storing them takes
    ~0.6 ms; ``np.load`` reads the same array from either
    (docs/benchmarking.md, "Session 24").
    """
    with path.open("wb") as handle:
        np.savez(handle, points=points)
