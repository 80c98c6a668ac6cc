"""The known limit a method's preset file records for a dataset, for the pages that show its failed rows.

Read when the report is built, like the held-in marks
(:mod:`albot1.report.tuning`): the finding describes the method's values,
not one run. A method whose class cannot be loaded, or whose file records
nothing for that dataset, has none (the page then shows the failure's own
reason alone).
"""

from __future__ import annotations

from functools import cache

from albot1.config.known_limits import known_limit
from albot1.config.presets import load_known_limits
from albot1.errors import Albot1Error
from albot1.methods.registry import load_mapper_class, method_registry
from albot1.report.tuning import dataset_name


@cache
def known_limit_of(method: str, preset: str, dataset: str) -> str | None:
    """What ``method``'s preset file says about ``dataset`` (a catalog reference; its slice/options ignored)."""
    registry = method_registry()
    if method not in registry:
        return None
    try:
        cls = load_mapper_class(registry.get(method).target)
        table = load_known_limits(cls.name)
    except (Albot1Error, ImportError):
        return None
    return known_limit(table, preset, dataset_name(dataset))
