"""Errors of running a method (contract violations, unknown methods)."""

from __future__ import annotations

from albot1.errors import Albot1Error


class RunError(Albot1Error):
    """A run could not be made or its result breaks the result contract."""


class UnknownMethodError(RunError):
    """A method name is not registered, or its dependencies are missing."""
