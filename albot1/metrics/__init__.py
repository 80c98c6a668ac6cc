"""Metrics: pure functions of trajectories, maps and the dataset's reference.

Nothing in this package reads or writes files or opens datasets: that is the
job of :mod:`albot1.runs.evaluate`, which turns a run folder into
``metrics.json`` with these functions. Every metric states its units
and its alignment, and a metric that cannot be computed is reported as
``null`` with a reason (see :mod:`albot1.runs.evaluate`), never as a number
made up to fill the slot.
"""
