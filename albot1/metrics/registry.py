"""The metric registry: every :class:`~albot1.metrics.unit.Metric` of :mod:`albot1.metrics.measures`, built once.

Why discovery: adding a metric is one new module in ``albot1/metrics/measures/``
(its block, needs, ``compute``, ``headline`` and columns); no list elsewhere
names it. The modules are found inside this one package only, so the import
stays within the metrics layer the layer contract checks, and a module that
does not declare its metric fails here, loudly (:class:`MetricRegistryError`),
never skipped: each module must bind ``METRIC`` to a :class:`Metric` whose
``name`` is the module's name.

Readers: :func:`albot1.runs.evaluate.score` (what to compute), the metrics
record (:mod:`albot1.metrics.record`: the keys and blocks of ``metrics.json``),
``albot1 evaluate``'s summary lines and the report's columns
(:mod:`albot1.report.collect`).
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache
from typing import Any

from albot1.metrics.errors import MetricsError
from albot1.metrics.unit import Metric

#: The package whose modules are the metrics.
MEASURES = "albot1.metrics.measures"


class MetricRegistryError(MetricsError):
    """A metric module does not declare a well-formed metric (a developer's error, found at start-up)."""


@dataclass(frozen=True)
class MetricRegistry:
    """The metrics in ``metrics.json`` order (by ``position``)."""

    metrics: tuple[Metric[Any], ...]

    @property
    def names(self) -> tuple[str, ...]:
        """The metrics' keys in file order."""
        return tuple(m.name for m in self.metrics)

    def __iter__(self) -> Iterator[Metric[Any]]:
        return iter(self.metrics)

    def __len__(self) -> int:
        return len(self.metrics)

    def get(self, name: str) -> Metric[Any]:
        """The metric called ``name``; KeyError naming the known ones."""
        for metric in self.metrics:
            if metric.name == name:
                return metric
        raise KeyError(f"no metric {name!r}; known: {', '.join(self.names)}")


def build_registry(package: str = MEASURES) -> MetricRegistry:
    """Import every module of ``package`` and collect its ``METRIC``; MetricRegistryError on a malformed one."""
    root = importlib.import_module(package)
    found: list[Metric[Any]] = []
    for info in sorted(pkgutil.iter_modules(root.__path__), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{package}.{info.name}")
        where = f"{package}.{info.name} ({module.__file__})"
        metric = getattr(module, "METRIC", None)
        if not isinstance(metric, Metric):
            raise MetricRegistryError(f"{where}: expected METRIC = Metric(...) declaring the metric, found {metric!r}")
        _check(metric, info.name, where)
        found.append(metric)
    for attribute, values in (("name", [m.name for m in found]), ("position", [str(m.position) for m in found])):
        repeated = sorted({v for v in values if values.count(v) > 1})
        if repeated:
            raise MetricRegistryError(f"{package}: metrics share a {attribute}: {', '.join(repeated)}")
    return MetricRegistry(tuple(sorted(found, key=lambda m: m.position)))


def _check(metric: Metric[Any], module_name: str, where: str) -> None:
    if metric.name != module_name:
        raise MetricRegistryError(f"{where}: METRIC.name is {metric.name!r}; expected the module's name")
    if not metric.models:
        raise MetricRegistryError(f"{where}: the metric names no block model")
    for part in ("compute", "headline"):
        if not callable(getattr(metric, part)):
            raise MetricRegistryError(f"{where}: METRIC.{part} is not callable")
    keys = [c.key for c in metric.columns]
    if len(set(keys)) != len(keys):
        raise MetricRegistryError(f"{where}: column keys repeat: {keys}")


@cache
def metric_registry() -> MetricRegistry:
    """The project's metrics, built once per process."""
    return build_registry()
