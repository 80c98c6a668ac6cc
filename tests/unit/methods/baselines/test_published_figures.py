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
