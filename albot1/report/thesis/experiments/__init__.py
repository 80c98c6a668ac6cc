"""One module per experiment of the thesis: its claim and numbers, ours, and the computed verdicts.

Each ``section_*`` function reads the stores (:class:`~albot1.report.thesis.evidence.Evidence`) and
returns a :class:`~.common.Section`: the claims as rows of verdicts (one per Albot1 variant: the literal
reading, the thesis preset, Albot1+), Markdown tables of the measured numbers with the thesis's numbers in
their own columns labelled "thesis", and the figures to draw.

Modules: :mod:`.exp1_map`, :mod:`.exp2_orientation`, :mod:`.exp3_error_tolerance`, :mod:`.exp45_spacing`,
:mod:`.exp6_public`, :mod:`.ch4_places` (one per experiment), :mod:`.stand_ins` (the table of what stands in
for the thesis's data), and what they share: :mod:`.common` (the section model, method labels, metric paths,
number and table helpers), :mod:`.datasets` (the experiments' datasets, read by tag from the thesis suite
file ``benchmarks/thesis.toml``) and :mod:`.published` (published-only systems and figures).
"""

from __future__ import annotations

from albot1.report.thesis.evidence import Evidence
from albot1.report.thesis.experiments.ch4_places import section_places
from albot1.report.thesis.experiments.common import ClaimRow, FigureRequest, Section
from albot1.report.thesis.experiments.datasets import ThesisDatasets, thesis_datasets
from albot1.report.thesis.experiments.exp1_map import section_map
from albot1.report.thesis.experiments.exp2_orientation import section_orientation
from albot1.report.thesis.experiments.exp3_error_tolerance import section_error_tolerance
from albot1.report.thesis.experiments.exp6_public import section_public
from albot1.report.thesis.experiments.exp45_spacing import section_spacing
from albot1.report.thesis.experiments.stand_ins import stand_ins

__all__ = [
    "ClaimRow",
    "FigureRequest",
    "Section",
    "ThesisDatasets",
    "all_sections",
    "section_error_tolerance",
    "section_map",
    "section_orientation",
    "section_places",
    "section_public",
    "section_spacing",
    "stand_ins",
    "thesis_datasets",
]


def all_sections(ev: Evidence) -> list[Section]:
    """Every experiment in the thesis's order."""
    return [
        section_map(ev),
        section_orientation(ev),
        section_error_tolerance(ev),
        section_spacing(ev),
        section_public(ev),
        section_places(ev),
    ]
