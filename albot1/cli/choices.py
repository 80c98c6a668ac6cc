"""Help text generated from the method registry and the presets, so that ``--help`` cannot drift from them.

Typer fixes a parameter's help when the command is defined, and the
registry (with its plugins) and the presets are not imported at start-up
(see :mod:`albot1.cli.app`). :class:`RegistryHelpCommand` therefore fills
the ``method`` and ``preset`` help when ``--help`` is asked for, from
:func:`method_choices` and :func:`preset_choices`.
"""

from __future__ import annotations

from typing import Any

from typer.core import TyperArgument, TyperOption

from albot1.cli.helptext import HelpCommand
from albot1.errors import Albot1Error

#: Shown until ``--help`` fills in the names (never seen by a user).
METHOD_HELP = "a registered method (`albot1 methods`)"
PRESET_HELP = "config preset of the method (`albot1 methods --presets`)"


def method_choices() -> str:
    """``odometry | albot1 | ...``: every registered method, built in or an installed plugin."""
    from albot1.methods.registry import method_registry

    return " | ".join(method_registry().names())


def preset_choices() -> str:
    """``albot1: default | thesis | ...; kiss-icp: default | ...``: each method's presets.

    Read from the presets files alone (:func:`~albot1.config.presets.preset_names`): showing help imports no
    mapper and no numerical library. A plugin's presets are its class's, so help points to the listing.
    """
    from albot1.config.presets import preset_names
    from albot1.methods.registry import method_registry

    parts = []
    for spec in method_registry():
        if spec.plugin is not None:
            parts.append(f"{spec.name}: `albot1 methods --presets {spec.name}`")
            continue
        try:
            parts.append(f"{spec.name}: {' | '.join(preset_names(spec.name))}")
        except Albot1Error:  # a broken presets file: help still shows, running the method says why
            parts.append(f"{spec.name}: (its presets file cannot be read, see `albot1 methods --presets`)")
    return "; ".join(parts)


class RegistryHelpCommand(HelpCommand):
    """A command whose ``method`` / ``preset`` help lists the registry's names when help is shown."""

    def format_help(self, ctx: Any, formatter: Any) -> None:
        for param in self.params:
            if param.name == "method" and isinstance(param, TyperArgument):
                param.help = f"{method_choices()} (see `albot1 methods`)"
            elif param.name == "preset" and isinstance(param, TyperOption):
                param.help = f"config preset; {preset_choices()} (see `albot1 methods --presets`)"
        super().format_help(ctx, formatter)
