"""Which datasets a thesis claim is tested on: a dataset is left out only when it has no reference poses.

A dataset whose runs failed (or did not run) keeps its claim rows, "not comparable" with the failure as the
reason; leaving it out would drop the claim from the page's counts and blame the dataset for the runs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

from albot1.metrics.unit import NO_REFERENCE
from albot1.report.thesis.evidence import Evidence
from albot1.report.thesis.experiments import section_map, section_orientation
from albot1.report.thesis.experiments.common import PER_VIEW, SHAPE, STOPS, VARIANTS
from albot1.report.thesis.verdicts import HOLDS, NOT_COMPARABLE, Number

FAILED = "failed in results/thesis (exception: the mapper diverged)"


@dataclass(frozen=True)
class _Found:
    dataset: str
    record: Any = None
    store: Any = None


@dataclass
class _Evidence:
    """The few methods of :class:`Evidence` the sections call, over a table of numbers (or why there is none)."""

    values: dict[tuple[str, str], float | str]

    def datasets(self) -> list[str]:
        return list(dict.fromkeys(d for d, _ in self.values))

    def methods(self, dataset: str) -> list[str]:
        return list(VARIANTS)

    def find(self, dataset: str, method: str, degradation: str = "none") -> _Found:
        return _Found(dataset)

    def number(self, lookup: _Found, path: str, label: str, unit: str = "") -> Number:
        value = self.values.get((lookup.dataset, path), "no value")
        return Number(label, value, unit) if isinstance(value, float) else Number(label, None, unit, value)


def _evidence() -> Evidence:
    values: dict[tuple[str, str], float | str] = {
        ("synthetic-measured", SHAPE): 0.5,
        ("synthetic-measured", PER_VIEW): 0.3,
        ("synthetic-measured", STOPS): 3.0,
        ("synthetic-failed", SHAPE): FAILED,
        ("synthetic-failed", PER_VIEW): FAILED,
        ("synthetic-failed", STOPS): FAILED,
        ("raw-log", SHAPE): NO_REFERENCE,
        ("raw-log", PER_VIEW): 0.3,
        ("raw-log", STOPS): NO_REFERENCE,
    }
    return cast(Evidence, _Evidence(values))


def test_the_shape_claim_is_left_out_only_where_there_are_no_reference_poses() -> None:
    section = section_map(_evidence())
    shape = [row for row in section.claims if row.claim.startswith("the map keeps the overall shape")]
    assert [row.dataset for row in shape] == ["synthetic-measured", "synthetic-failed"]
    assert {v.word for v in shape[0].verdicts.values()} == {HOLDS}
    failed = shape[1].verdicts["albot1:thesis"]
    assert failed.word == NOT_COMPARABLE
    assert failed.reason == f"albot1:thesis median map-to-wall: {FAILED}"
    updates = [row.dataset for row in section.claims if row.claim.startswith("the map is not updated")]
    assert updates == ["synthetic-measured", "synthetic-failed", "raw-log"]
    assert section.notes == [
        "No map-shape number (no reference poses to build the true map from), so only the update claim is "
        "tested on: `raw-log`."
    ]


def test_the_orientation_claim_is_left_out_only_where_there_are_no_reference_poses() -> None:
    section = section_orientation(_evidence())
    assert [row.dataset for row in section.claims] == ["synthetic-measured", "synthetic-failed"]
    failed = section.claims[1].verdicts["albot1:plus"]
    assert failed.word == NOT_COMPARABLE
    assert FAILED in failed.reason


def test_experiment_2_says_the_thesis_exceeds_its_own_distance_bound() -> None:
    notes = section_orientation(_evidence()).notes
    assert notes == [
        "The thesis's own Table 3.1 does not keep its stated bounds of 7 deg and 3 m at every stop (stop c: "
        "3.5 deg / 3.2 m); the verdicts test the bounds as the text states them (3.2.2, text below Table 3.1)."
    ]
