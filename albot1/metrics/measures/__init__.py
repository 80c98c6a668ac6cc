"""One module per metric of ``metrics.json``: each binds ``METRIC`` (:class:`albot1.metrics.unit.Metric`).

The registry (:mod:`albot1.metrics.registry`) finds them; ``docs/metrics.md``
("Adding a metric") says what a module holds.
"""
