"""The presets of ``albot1-places``: each chapter-3 preset with the chapter-4 fields on top.

``albot1-places`` runs the chapter-3 mapper inside, so its presets are the
chapter-3 presets (``albot1/methods/albot1/presets.toml``: ``thesis``,
``exact``, ``literal``, and whatever is added there later) plus the places
fields, whose values live in ``albot1/methods/albot1/places/presets.toml``
(its ``[presets.default]`` sets every places field; another table changes
places fields for the preset of that name). Composing them at load time,
rather than copying the chapter-3 values into the places file, means a
chapter-3 preset or field added later is a places preset or field at once,
with the same value: the two methods cannot drift apart.

Same mechanism as every method (:class:`~albot1.config.presets.TomlPresets`):
read on first use, each merged preset validated against the full config,
errors naming the files, the preset and the field.
"""

from __future__ import annotations

from importlib.resources import files
from typing import Any

from pydantic import ValidationError

from albot1.config.presets import (
    PACKAGE_PRESETS,
    PresetTable,
    TomlPresets,
    TunedOnTable,
    load_package_presets,
    tuned_on_table,
)
from albot1.config.validation import describe_errors
from albot1.errors import ConfigError

PLACES_PACKAGE = "albot1.methods.albot1.places"
CHAPTER3_PACKAGE = "albot1.methods.albot1"


class PlacesPresets(TomlPresets):
    """Class attribute: the chapter-3 presets with the places presets merged onto those of the same name."""

    def __init__(self) -> None:
        super().__init__(package=PLACES_PACKAGE)

    def __get__(self, instance: object, owner: type) -> PresetTable:
        table = self._cache.get(owner)
        if table is None:
            from albot1.methods.albot1.mapping.mapper import Albot1Mapper
            from albot1.methods.albot1.places.config import PlacesFields

            base = Albot1Mapper.presets
            own = load_package_presets(PLACES_PACKAGE, PlacesFields)
            unknown = sorted(set(own) - set(base))
            table = {}
            for name in [*base, *unknown]:
                values: dict[str, Any] = {**base.get(name, base["default"]), **own.get(name, own["default"])}
                try:
                    owner.config_model.model_validate(values)  # type: ignore[attr-defined]
                except ValidationError as exc:
                    raise ConfigError(
                        f"{self.location(owner)}: preset {name!r} is not a valid "
                        f"{owner.config_model.__name__}: {describe_errors(exc)}"  # type: ignore[attr-defined]
                    ) from None
                table[name] = values
            self._cache[owner] = table
        return table

    def location(self, owner: type) -> str:
        return (
            f"{files(CHAPTER3_PACKAGE).joinpath(PACKAGE_PRESETS)} + {files(PLACES_PACKAGE).joinpath(PACKAGE_PRESETS)}"
        )

    def tuned_on(self, owner: type) -> TunedOnTable | None:
        """Per preset, the chapter-3 preset's held-in datasets plus those of the places file."""
        from albot1.methods.albot1.mapping.mapper import Albot1Mapper

        own = super().tuned_on(owner)
        base = tuned_on_table(Albot1Mapper)
        if own is None or base is None:
            return None
        return {
            name: tuple(dict.fromkeys([*base.get(name, base["default"]), *own.get(name, own["default"])]))
            for name in [*base, *(n for n in own if n not in base)]
        }
