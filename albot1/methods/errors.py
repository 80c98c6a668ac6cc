"""Errors of the method registry (the methods' own run-time errors live beside each method)."""

from __future__ import annotations

from albot1.errors import ConfigError


class UnknownMethodError(ConfigError):
    """A method name is not registered, or its dependencies are missing."""
