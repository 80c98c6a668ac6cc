"""The base of every method's config model: strict, immutable, and finite.

Why a base: a method's config is validated from preset files, environment
variables, ``--set FIELD=VALUE`` and a suite's ``set`` table, and each of
those is typed by a person. pydantic accepts ``inf`` for a float field by
default, and a bound like ``gt=0`` lets it through: ``--set map_voxel_m=inf``
would run (a map of one point) and be recorded as ``null`` in
``result.json``, since JSON has no infinity. Refusing non-finite values here,
once, covers every method and every way of setting a field. A field where
``inf`` is a meaningful setting ("no limit") says so itself with
``Field(allow_inf_nan=True)`` and a bound that still refuses NaN.
"""

from __future__ import annotations

import math
from typing import Any

from pydantic import BaseModel, ConfigDict, field_serializer


class MethodConfig(BaseModel):
    """A method's settings: unknown fields, mutation and non-finite numbers are refused."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    @field_serializer("*", when_used="json")
    def _infinity_as_text(self, value: Any) -> Any:
        """A "no limit" ``inf`` as ``"inf"`` in JSON: a run records its config in ``result.json``, where a bare
        infinity is no JSON and would be written as ``null``, which no config accepts back; the text ``"inf"``
        is read back as the same float (so the recorded config reproduces the run)."""
        if isinstance(value, float) and math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return value
