"""Errors of the Albot1 perceptual mapper."""

from __future__ import annotations

from albot1.errors import Albot1Error


class MappingError(Albot1Error):
    """The Albot1 mapper met input or a state it cannot handle (message says which scan)."""
