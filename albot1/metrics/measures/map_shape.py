"""``map_shape``: agreement of the run's map with the reference map (:func:`albot1.metrics.map_shape.map_agreement`).

The reference map is every scan of the dataset projected with its reference
pose (and the sensor offset), so the dataset is reopened here (through
``MetricInputs.open_dataset``); its scans must be the run's, time for time.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from albot1.data.transforms import head
from albot1.errors import Albot1Error
from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.metrics.alignment import describe, rigid_transform
from albot1.metrics.blocks import AlignmentTransform, block_of, fmt
from albot1.metrics.errors import MetricsError
from albot1.metrics.map_shape import MAX_POINTS, VOXEL_M, map_agreement, thin
from albot1.metrics.reference_map import entry_key, reference_cloud
from albot1.metrics.unit import MAP, REFERENCE, ColumnSpec, Metric, MetricInputs
from albot1.records import Count, Fraction, NonNegative, Record

if TYPE_CHECKING:
    from albot1.data.model import Sequence


class MapShapeBlock(Record):
    """``map_shape``: agreement of the map with the reference map (fractions, m)."""

    units: dict[str, str]
    alignment: str
    alignment_transform: AlignmentTransform
    reference_map: str
    tolerance_m: NonNegative
    voxel_m: NonNegative
    map_points: Count
    reference_points: Count
    precision: Fraction
    coverage: Fraction
    map_to_reference_mean_m: NonNegative
    map_to_reference_median_m: NonNegative
    reference_to_map_mean_m: NonNegative
    reference_to_map_median_m: NonNegative


def reference_points(inputs: MetricInputs, reference: FloatArray) -> FloatArray:
    """The reference map of the run, thinned as :func:`map_agreement` thins it; MetricsError when the scans do not fit.

    Every scan of the run's dataset projected with its reference pose, built
    once per machine for the same inputs (:mod:`albot1.metrics.reference_map`).
    """
    dataset, n = inputs.dataset, int(len(inputs.poses))
    try:
        sequence = head(inputs.open_dataset(), n)
    except Albot1Error as exc:
        raise MetricsError(f"cannot reopen dataset {dataset!r} for the reference map: {exc}") from exc
    offset = np.asarray(sequence.metadata.sensor_offset, dtype=float)
    key = entry_key(
        dataset=dataset,
        checksums=sequence.metadata.checksums,
        manifest_loader=sequence.metadata.manifest_loader,
        count=n,
        reference=reference,
        timestamps=np.asarray(inputs.timestamps, dtype=float),
        sensor_offset=offset,
        voxel_m=VOXEL_M,
        max_points=MAX_POINTS,
    )
    return reference_cloud(key, lambda: thin(projected_scans(inputs, sequence, reference, offset)))


def projected_scans(inputs: MetricInputs, sequence: Sequence, reference: FloatArray, offset: FloatArray) -> FloatArray:
    """Every scan of ``sequence`` (the run's first scans) projected with its reference pose and the sensor offset."""
    dataset, n = inputs.dataset, int(len(inputs.poses))
    parts: list[FloatArray] = []
    count = 0
    for frame in sequence.frames():
        k = frame.index
        if k >= n:
            break
        if abs(frame.scan.timestamp - inputs.timestamps[k]) > 1e-3:
            raise MetricsError(
                f"dataset {dataset!r} scan {k} has time {frame.scan.timestamp:.6f} but the "
                f"run's trajectory has {inputs.timestamps[k]:.6f}; the dataset changed since the run"
            )
        sensor = se2.compose(reference[k], offset)
        parts.append(se2.transform_points(sensor, frame.scan.points()))
        count += 1
    if count != n:
        raise MetricsError(f"dataset {dataset!r} has {count} scans, the run has {n}")
    return np.concatenate(parts) if parts else np.empty((0, 2))


def compute(inputs: MetricInputs) -> MapShapeBlock:
    reference, load_map = inputs.reference, inputs.load_map
    assert reference is not None and load_map is not None  # REFERENCE and MAP are needs
    if len(inputs.poses) == 1:
        # The rigid alignment puts the one pose on the reference's, so the map is the reference map: a precision
        # and coverage of 1 would be made up.
        raise MetricsError(
            "map shape: one scan, whose map the rigid alignment puts exactly on the reference map (agreement 1 by "
            "construction); expected at least 2 scans"
        )
    points = reference_points(inputs, reference)
    transform = rigid_transform(inputs.poses, reference)
    map_points = se2.transform_points(transform, load_map().geometry_points())
    block = map_agreement(map_points, points, reference_thinned=True)
    return block_of(
        MapShapeBlock,
        {
            "units": {"distance": "m", "precision": "fraction", "coverage": "fraction"},
            "alignment": "rigid",
            "alignment_transform": describe(transform, "rigid"),
            "reference_map": "every scan projected with its reference pose (and the sensor offset)",
            **block,
        },
    )


def headline(block: MapShapeBlock) -> str:
    return f"precision {fmt(block.precision)}, coverage {fmt(block.coverage)} (within {block.tolerance_m} m)"


METRIC = Metric(
    name="map_shape",
    position=80,
    models=(MapShapeBlock,),
    needs=(REFERENCE, MAP),
    compute=compute,
    headline=headline,
    columns=(
        ColumnSpec("map_precision", "precision", "map precision"),
        ColumnSpec("map_coverage", "coverage", "map coverage"),
    ),
)
