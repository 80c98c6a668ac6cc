"""Published figures of systems not run here: DP-SLAM's entry says what was searched and lists no number."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from albot1.methods.baselines.published import PublishedFigure, published_systems


def test_dp_slam_entry_is_a_cited_finding_without_made_up_numbers() -> None:
    systems = {s.name: s for s in published_systems()}
    dp = systems["dp-slam"]
    assert "Eliazar" in dp.citation and "IJCAI 2003" in dp.citation
    assert dp.figures == () and "No verifiable figure" in dp.searched


def test_a_figure_needs_a_known_metric_and_a_source() -> None:
    figure = PublishedFigure(log="intel", metric="relation_translation_m", mean=0.07, std=0.08, source="Table 2")
    assert figure.std == 0.08
    with pytest.raises(ValidationError):
        PublishedFigure(log="intel", metric="ate_m", mean=0.1, source="x")  # type: ignore[arg-type]
    with pytest.raises(ValidationError):
        PublishedFigure(log="intel", metric="relation_translation_m", mean=0.1, source="")


@pytest.mark.parametrize(
    ("name", "log", "metric", "printed"),
    [
        ("kuemmerle-sm", "intel", "relation_translation_m", "0.220 ± 0.296"),
        ("kuemmerle-rbpf", "aces", "relation_translation_m", "0.060 ± 0.049"),
        ("kuemmerle-gm", "aces", "relation_rotation_deg", "0.4 ± 0.4"),
        ("kuemmerle-gm", "mit-csail", "relation_translation_m", "0.004 ± 0.009"),
        ("kuemmerle-gm", "mit-csail", "relation_rotation_deg", "0.05 ± 0.08"),
        ("kuemmerle-gm", "fr-clinic", "relation_translation_m", "0.143 ± 0.180"),
        ("cartographer", "aces", "relation_translation_m", "0.0375 ± 0.0426"),
        ("cartographer", "fr-clinic", "relation_rotation_deg", "0.747 ± 2.047"),
        ("cartographer", "intel", "wall_clock_s", "179"),
        ("graph-flirt", "fr-clinic", "relation_rotation_deg", "0.9 ± 2.0"),
    ],
)
def test_a_figure_reads_as_its_source_prints_it(name: str, log: str, metric: str, printed: str) -> None:
    """The text of the shared datasets' README and of Hess et al. 2016: no digit added (0.4, not 0.400) or lost
    (0.220, not 0.22, which TOML's float keeps as 0.22: the std's three decimals restore it)."""
    system = next(s for s in published_systems() if s.name == name)
    figure = next(f for f in system.figures if (f.log, f.metric) == (log, metric))
    assert figure.text() == printed


def test_a_figure_refuses_a_negative_or_infinite_value() -> None:
    for bad in ({"mean": -0.1}, {"mean": float("inf")}, {"mean": 0.1, "std": float("nan")}, {"mean": 0.1, "std": -1}):
        with pytest.raises(ValidationError):
            PublishedFigure(log="intel", metric="relation_translation_m", source="x", **bad)  # type: ignore[arg-type]


def test_a_figure_whose_numbers_both_end_in_a_printed_zero_says_its_decimals() -> None:
    """0.10 ± 0.20 reads back from TOML as 0.1 and 0.2: only ``printed_decimals`` can keep the printed text."""
    fields = {"log": "intel", "metric": "relation_translation_m", "source": "x", "mean": 0.1, "std": 0.2}
    assert PublishedFigure(**fields).text() == "0.1 ± 0.2"  # type: ignore[arg-type]
    assert PublishedFigure(**fields, printed_decimals=2).text() == "0.10 ± 0.20"  # type: ignore[arg-type]
    with pytest.raises(ValidationError):
        PublishedFigure(**fields, printed_decimals=-1)  # type: ignore[arg-type]
