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

from pydantic import BaseModel, ConfigDict


class MethodConfig(BaseModel):
    """A method's settings: unknown fields, mutation and non-finite numbers are refused."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)
