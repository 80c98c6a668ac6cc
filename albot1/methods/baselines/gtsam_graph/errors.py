"""Errors of the GTSAM graph baseline (all are :class:`BaselineError`)."""

from __future__ import annotations

from albot1.methods.baselines.errors import BaselineError


class RegistrationError(BaselineError):
    """Scan registration got unusable input (non-finite values, too few points)."""


class GraphError(BaselineError):
    """The pose graph could not be built or optimised (GTSAM raised, or the result is not finite)."""
