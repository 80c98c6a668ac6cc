"""``relations``: the Kuemmerle et al. (2009) relation metric (:func:`albot1.metrics.relations.relation_metric`).

A run folder keeps every relation of its dataset, whether from ``albot1 run``
or a bench cell; the ones the run's scans cannot score (a slice: a prefix,
every n-th scan) are left out here, by the one rule
(:func:`albot1.data.relations.relations_in_run`), and counted in the block
(``relations_outside_run``).
"""

from __future__ import annotations

from albot1.metrics.blocks import Stats, block_of, fmt
from albot1.metrics.relations import relation_metric
from albot1.metrics.unit import RELATIONS, ColumnSpec, Metric, MetricInputs
from albot1.records import Count, Record


class RelationLoops(Record):
    """``relations.loops``: the same statistics over the relations spanning more than ``min_dt_s``."""

    min_dt_s: float
    translation_m: Stats
    rotation_deg: Stats
    translation_squared_m2: Stats
    rotation_squared_deg2: Stats


class RelationsBlock(Record):
    """``relations``: the Kuemmerle et al. (2009) metric (sample std), with how many relations the run covered.

    ``relations_total`` counts the dataset's relations, ``relations_used`` those scored and
    ``relations_outside_run`` those left out because an end names a scan without a pose (a slice of
    the log; :func:`albot1.data.relations.relations_in_run`), so a slice never drops relations silently.
    ``relations_repeated_lines`` counts the lines of the relations file that repeat an earlier line
    identically, and ``relations_repeats_counted`` says whether they were counted as listed (the
    published evaluator's reading) or once (:mod:`albot1.data.relations`); files written before these
    fields existed read as 0 and false.
    """

    alignment: str
    error: str
    std_ddof: Count
    relations_total: Count
    relations_used: Count
    relations_outside_run: Count
    relations_repeated_lines: Count = 0
    relations_repeats_counted: bool = False
    max_time_gap_s: float
    translation_m: Stats
    rotation_deg: Stats
    translation_squared_m2: Stats
    rotation_squared_deg2: Stats
    loops: RelationLoops


def compute(inputs: MetricInputs) -> RelationsBlock:
    assert inputs.relations is not None  # RELATIONS is a need
    data = relation_metric(
        inputs.relation_timestamps,
        inputs.relation_poses,
        inputs.relations,
        outside="exclude",
        source=inputs.relations_source,
    )
    return block_of(RelationsBlock, data)


def headline(block: RelationsBlock) -> str:
    t, r = block.translation_m, block.rotation_deg
    outside, total = block.relations_outside_run, block.relations_total
    left_out = (
        f" ({outside} of {total} relations left out: they name scans without a pose in this trajectory)"
        if outside
        else ""
    )
    repeats = block.relations_repeated_lines
    if repeats:
        reading = "counted as listed, the published reading" if block.relations_repeats_counted else "counted once"
        left_out += f" ({repeats} repeated line(s) of the relations file {reading})"
    return f"{fmt(t.mean)} +/- {fmt(t.std)} m, {fmt(r.mean, '.2f')} +/- {fmt(r.std, '.2f')} deg, N = {t.n}{left_out}"


METRIC = Metric(
    name="relations",
    position=70,
    models=(RelationsBlock,),
    needs=(RELATIONS,),
    compute=compute,
    headline=headline,
    columns=(
        ColumnSpec("relation_m", "translation_m.mean", "relation trans. (m)"),
        ColumnSpec("relation_deg", "rotation_deg.mean", "relation rot. (deg)"),
        ColumnSpec("relation_loops_m", "loops.translation_m.mean", "relation >30 s trans. (m)"),
    ),
)
