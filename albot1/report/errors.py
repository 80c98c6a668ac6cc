"""The report area's exception class."""

from __future__ import annotations

from albot1.errors import Albot1Error


class ReportError(Albot1Error):
    """A report or one of its figures cannot be made from the stored results (the message says why)."""
