"""Errors of the wrapped baselines."""

from __future__ import annotations

from albot1.errors import Albot1Error


class BaselineError(Albot1Error):
    """A baseline raised, diverged or timed out; the message names method, dataset and cause."""
