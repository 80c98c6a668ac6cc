"""Experiment 6's table of published relation errors: each figure as its source prints it, with its spread."""

from __future__ import annotations

from albot1.report.thesis.experiments.published import published_relations


def test_published_relation_errors_read_as_printed_with_their_spread() -> None:
    """``:g`` turned Kuemmerle's 0.220 m into 0.22 m and left out every ± std the source gives."""
    table = published_relations(["intel", "fr-clinic"])
    assert table is not None
    lines = table.splitlines()
    assert any("| `intel` | SM (Kuemmerle et al. 2009) | 0.220 ± 0.296 m | – |" in line for line in lines)
    assert any(
        "| `fr-clinic` | GM (Kuemmerle et al. 2009) | 0.143 ± 0.180 m | 0.9 ± 2.2 deg |" in line for line in lines
    )
    assert published_relations(["synthetic-office-loop"]) is None
