"""The root of the project's exception tree.

Each area (data, mapping, baselines, metrics, bench) derives its own class
from :class:`Albot1Error`; the CLI turns any of them into one line on stderr
and a non-zero exit, while unknown exceptions keep their traceback.
"""

from __future__ import annotations


class Albot1Error(Exception):
    """Base class of every error this project raises on purpose."""


class ConfigError(Albot1Error):
    """A configuration value, preset or override is not what was expected."""
