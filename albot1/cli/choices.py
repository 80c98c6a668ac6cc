"""Help text generated from the method registry and the presets, so that ``--help`` cannot drift from them.

Typer fixes a parameter's help when the command is defined, and the
registry (with its plugins) and the presets are not imported at start-up
(see :mod:`albot1.cli.app`). :class:`RegistryHelpCommand` therefore fills
the ``method`` and ``preset`` help when ``--help`` is asked for, from
:func:`method_choices` and :func:`preset_choices`.
"""

from __future__ import annotations

from typing import Any

from typer.core import TyperArgument, TyperCommand, TyperOption

from albot1.errors import Albot1Error

#: Shown until ``--help`` fills in the names (never seen by a user).
METHOD_HELP = "a registered method (`albot1 methods`)"
PRESET_HELP = "config preset of the method (`albot1 methods --presets`)"


def method_choices() -> str:
    """``odometry | albot1 | ...``: every registered method, built in or an installed plugin."""
    from albot1.methods.registry import method_registry

    return " | ".join(method_registry().names())


def preset_choices() -> str:
    """``albot1: default | thesis | ...; kiss-icp: default | ...``: each installed method's presets."""
    from albot1.methods.registry import method_registry

    parts = []
    for spec in method_registry():
        if not spec.available():
            parts.append(f"{spec.name}: (not installed)")
            continue
        try:
            parts.append(f"{spec.name}: {' | '.join(spec.load_class().presets)}")
        except Albot1Error:  # a broken plugin: help still shows, running it says why
            parts.append(f"{spec.name}: (cannot be loaded, see `albot1 methods`)")
    return "; ".join(parts)


class RegistryHelpCommand(TyperCommand):
    """A command whose ``method`` / ``preset`` help lists the registry's names when help is shown."""

    def format_help(self, ctx: Any, formatter: Any) -> None:
        for param in self.params:
            if param.name == "method" and isinstance(param, TyperArgument):
                param.help = f"{method_choices()} (see `albot1 methods`)"
            elif param.name == "preset" and isinstance(param, TyperOption):
                param.help = f"config preset; {preset_choices()} (see `albot1 methods --presets`)"
        super().format_help(ctx, formatter)
