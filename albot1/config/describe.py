"""What a method's config fields mean and what each preset changes, for listings.

``albot1 methods --presets`` prints this; it is derived, never written by
hand: the unit comes from the field name's suffix (the project's convention,
``_m`` metres, ``_deg`` degrees, ``_s`` seconds, ...), the meaning from the
field's description in the config model, the values from the presets.
"""

from __future__ import annotations

import typing
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

#: Field-name suffix -> unit, longest first so ``_ms`` is not read as ``_s``.
UNIT_SUFFIXES: tuple[tuple[str, str], ...] = (
    ("_deg", "deg"),
    ("_mb", "MiB"),
    ("_ms", "ms"),
    ("_m", "m"),
    ("_s", "s"),
)


def field_unit(name: str) -> str:
    """``"voxel_size_m"`` -> ``"m"``; ``""`` when the name carries no unit (counts, ratios, switches)."""
    for suffix, unit in UNIT_SUFFIXES:
        if name.endswith(suffix):
            return unit
    return ""


def type_name(annotation: Any) -> str:
    """``float`` -> ``"float"``; ``Literal["a", "b"]`` -> ``"a|b"``."""
    if typing.get_origin(annotation) is typing.Literal:
        return "|".join(str(choice) for choice in typing.get_args(annotation))
    return getattr(annotation, "__name__", str(annotation))


@dataclass(frozen=True)
class FieldRow:
    """One config field: its name, type, unit, value in the ``default`` preset, and meaning.

    ``required`` is True (and ``default`` None) when neither the model nor the
    ``default`` preset gives the field a value.
    """

    name: str
    type: str
    unit: str
    default: Any
    description: str
    required: bool = False


@dataclass(frozen=True)
class PresetsDescription:
    """A method's fields and, per preset, the fields whose value differs from ``default``."""

    fields: list[FieldRow]
    changes: dict[str, dict[str, Any]]


def effective_presets(model: type[BaseModel], presets: Mapping[str, Mapping[str, Any]]) -> dict[str, dict[str, Any]]:
    """Every preset as a full field -> value table: model defaults < ``default`` preset < the preset.

    A field the model requires and no preset sets is left out.
    """
    base = {
        name: info.get_default(call_default_factory=True)
        for name, info in model.model_fields.items()
        if info.get_default() is not PydanticUndefined or info.default_factory is not None
    }
    default = {**base, **presets.get("default", {})}
    return {name: {**default, **values} for name, values in presets.items()}


def describe_presets(model: type[BaseModel], presets: Mapping[str, Mapping[str, Any]]) -> PresetsDescription:
    """The table ``albot1 methods --presets`` prints for one method."""
    full = effective_presets(model, presets)
    default = full.get("default", {})
    rows = [
        FieldRow(
            name=name,
            type=type_name(info.annotation),
            unit=field_unit(name),
            default=default.get(name),
            description=info.description or "",
            required=name not in default,
        )
        for name, info in model.model_fields.items()
    ]
    changes = {
        preset: {name: value for name, value in values.items() if name not in default or default[name] != value}
        for preset, values in full.items()
    }
    return PresetsDescription(fields=rows, changes=changes)
