"""Errors of the method registry (the methods' own run-time errors live beside each method)."""

from __future__ import annotations

from albot1.errors import Albot1Error, ConfigError, InstallError


class UnknownMethodError(ConfigError):
    """A method name is not registered, or its dependencies are missing."""


class MethodUnavailableError(UnknownMethodError, InstallError):
    """A registered method's imports or programs are not installed here (an install's failure: ``InstallError``)."""


class PluginError(ConfigError):
    """An installed entry point of group ``albot1.methods`` does not declare a usable method."""


class PluginMethodError(Albot1Error):
    """A plugin method failed while running (the runner wraps the plugin's own exception in it)."""
