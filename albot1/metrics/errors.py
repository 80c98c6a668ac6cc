"""The metrics area's one exception class."""

from __future__ import annotations

from albot1.errors import Albot1Error


class MetricsError(Albot1Error):
    """Inputs of a metric do not fit together (lengths, timestamps, relation lines, ...)."""
