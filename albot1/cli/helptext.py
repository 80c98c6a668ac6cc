"""How every command's ``--help`` is laid out: prose reflowed to the terminal, flags without a type.

Typer's Rich help keeps a docstring's single line breaks after its first
paragraph, so prose wrapped at 100 columns in the source shows as ragged
lines at 80 or 140 columns; and it labels every option with its Python type,
so a plain flag reads ``--json <bool>`` as if it took a value. The classes
here fix both for every command and group of ``albot1`` (installed by
:func:`install` in :mod:`albot1.cli.app`), so no command can forget it:

- a prose paragraph's lines are joined into one (Rich wraps it to the
  terminal's width); an indented paragraph (an example command) keeps its
  lines, and consecutive indented paragraphs make one block;
- a flag (``--json``, ``--plots/--no-plots``, ``--help``) shows no type.
"""

from __future__ import annotations

import inspect
from typing import Any

import typer
from typer.core import TyperCommand, TyperGroup, TyperOption


def reflow(text: str | None) -> str | None:
    """``text`` with each prose paragraph on one line and indented (example) paragraphs kept as written."""
    if text is None:
        return None
    blocks: list[tuple[bool, list[str]]] = []  # (verbatim, lines)
    for paragraph in inspect.cleandoc(text).split("\n\n"):
        lines = [line.rstrip() for line in paragraph.split("\n") if line.strip()]
        if not lines:
            continue
        verbatim = all(line[:1].isspace() for line in lines)
        if verbatim and blocks and blocks[-1][0]:
            blocks[-1][1].extend(lines)  # one example block, not one paragraph per example
        elif verbatim:
            blocks.append((True, lines))
        else:
            blocks.append((False, [" ".join(line.strip() for line in lines)]))
    paragraphs = ["\n".join(lines) for _, lines in blocks]
    if len(paragraphs) < 2:
        return "\n\n".join(paragraphs)
    # Typer dedents the text after the first paragraph as a docstring (its first line not counted): an
    # empty first line there makes the dedent see the unindented "Examples:" and keep the examples' indent.
    return paragraphs[0] + "\n\n\n" + "\n\n".join(paragraphs[1:])


def _tidy(command: Any, ctx: Any) -> None:
    """Reflow the help of ``command`` and clear the type label of its flags (idempotent)."""
    command.help = reflow(command.help)
    for param in command.get_params(ctx):
        if isinstance(param, TyperOption) and param.is_flag:
            param.metavar = ""  # Rich shows the metavar in the type column instead of <bool>


class HelpCommand(TyperCommand):
    """A command whose help is reflowed and whose flags carry no type label."""

    def format_help(self, ctx: Any, formatter: Any) -> None:
        _tidy(self, ctx)
        super().format_help(ctx, formatter)


class HelpGroup(TyperGroup):
    """A command group (``albot1``, ``albot1 datasets``) laid out like :class:`HelpCommand`."""

    def format_help(self, ctx: Any, formatter: Any) -> None:
        _tidy(self, ctx)
        super().format_help(ctx, formatter)


def install(app: typer.Typer) -> None:
    """Give every command and group of ``app`` (recursively) the help layout above.

    Typer gives a command without a class its plain ``TyperCommand``; a
    command with its own class (``RegistryHelpCommand``) derives from
    :class:`HelpCommand` and keeps it.
    """
    if not (isinstance(app.info.cls, type) and issubclass(app.info.cls, HelpGroup)):
        app.info.cls = HelpGroup
    for command in app.registered_commands:
        if not (isinstance(command.cls, type) and issubclass(command.cls, HelpCommand)):
            command.cls = HelpCommand
    for group in app.registered_groups:
        if group.typer_instance is not None:
            install(group.typer_instance)
