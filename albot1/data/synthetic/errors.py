"""Errors of the synthetic-world generator.

A bad floor plan, route, sensor or odometry parameter is a programming or
configuration mistake in a world definition; the message names the world
element (doorway id, waypoint index, parameter) and what was expected.
"""

from __future__ import annotations

from albot1.data.errors import DataError, DatasetNotFoundError


class SyntheticWorldError(DataError):
    """A synthetic world, floor plan, route or sensor model is not valid."""


class UnknownWorldError(SyntheticWorldError, DatasetNotFoundError):
    """No embedded synthetic world has the requested name."""


class WorldOptionError(SyntheticWorldError, DatasetNotFoundError):
    """A loader option a synthetic world does not take (``start=``, ``laps=`` are the ones some take)."""
