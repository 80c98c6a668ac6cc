"""Errors of running a method (contract violations, unknown methods)."""

from __future__ import annotations

from albot1.errors import Albot1Error
from albot1.methods.errors import UnknownMethodError

__all__ = ["RunError", "UnknownMethodError"]


class RunError(Albot1Error):
    """A run could not be made or its result breaks the result contract."""


class OutputFolderError(RunError):
    """A folder a command writes into (``--out``, ``--results``) is a file, missing or not writable."""
