"""``albot1 methods``: the registered methods, and with ``--presets`` their config fields and presets."""

from __future__ import annotations

import inspect
import json
from typing import TYPE_CHECKING, Annotated, Any

import typer

from albot1.cli.columns import aligned

if TYPE_CHECKING:
    from albot1.methods.registry import MethodSpec


def register(app: typer.Typer) -> None:
    app.command("methods")(methods)


def methods(
    method: Annotated[
        str | None, typer.Argument(help="show only this method (and its presets; see `albot1 methods`)")
    ] = None,
    presets: Annotated[
        bool, typer.Option("--presets", help="list every config field (unit, default) and what each preset changes")
    ] = False,
    as_json: Annotated[bool, typer.Option("--json", help="print one JSON object")] = False,
) -> None:
    """List the registered methods and whether their dependencies are installed.

    With --presets (or a METHOD), also each method's config fields with their
    unit (from the field name's suffix: _m metres, _deg degrees, _s seconds),
    type, value in the `default` preset and meaning, and which fields each
    preset changes. Values come from the presets files (baselines/<method>.toml,
    every method's; a file in $ALBOT1_CONFIG_DIR/baselines/ replaces it); override them per run with
    `--set FIELD=VALUE` or ALBOT1_<METHOD>_<FIELD>.

    Examples:\n
      albot1 methods\n
      albot1 methods --presets\n
      albot1 methods kiss-icp --json
    """
    # The registry is imported by the command, not by this module: see albot1.cli.app.
    from albot1.methods.registry import method_registry

    registry = method_registry()
    specs = [registry.get(method)] if method is not None else list(registry)
    detail = presets or method is not None
    records = [_record(spec, detail) for spec in specs]
    if as_json:
        typer.echo(json.dumps({"methods": records}, indent=2, default=str))
        return
    if not detail:
        rows: list[tuple[str, ...]] = []
        for record in records:
            state = "available" if record["available"] else "unavailable"
            rows.append((record["name"], state, record["description"]))
            if not record["available"]:
                rows.append(("", "", f"-> {record['unavailable']}"))
        typer.echo("\n".join(aligned(rows)))
        return
    typer.echo("\n\n".join(_human(record) for record in records))


def _record(spec: MethodSpec, detail: bool) -> dict[str, Any]:
    """One method as JSON-able data; with ``detail`` its fields and presets (when installed)."""
    record: dict[str, Any] = {
        "name": spec.name,
        "available": spec.available(),
        "requires": list(spec.requires),
        "description": spec.description,
        "env_prefix": spec.env_prefix,
    }
    if spec.executables:
        record["executables"] = list(spec.executables)
    if not record["available"]:
        hint = spec.install_command()
        record["unavailable"] = f"{spec.unavailable_reason()}" + (f" (install: {hint})" if hint else "")
    if not detail or not record["available"]:
        return record
    from albot1.config.describe import describe_presets
    from albot1.config.presets import TomlPresets

    cls = spec.load_class()
    source = inspect.getattr_static(cls, "presets")
    description = describe_presets(cls.config_model, cls.presets)
    record["config_model"] = f"{cls.config_model.__module__}.{cls.config_model.__name__}"
    record["presets_file"] = source.location(cls) if isinstance(source, TomlPresets) else None
    record["fields"] = [
        {
            "name": row.name,
            "unit": row.unit,
            "type": row.type,
            "default": row.default,
            "required": row.required,
            "description": row.description,
        }
        for row in description.fields
    ]
    record["presets"] = description.changes
    return record


def _value(value: Any) -> str:
    """A value as it would be written in the presets file or after ``--set``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def _human(record: dict[str, Any]) -> str:
    head = f"{record['name']}: {record['description']}"
    if not record["available"]:
        return f"{head}\n  unavailable: {record['unavailable']}; its presets cannot be listed"
    lines = [head, f"  config model {record['config_model']}; environment prefix {record['env_prefix']}"]
    if record["presets_file"]:
        lines.append(f"  presets file {record['presets_file']}")
    rows = [("field", "unit", "type", "default", "meaning")]
    for field in record["fields"]:
        default = "(required)" if field["required"] else _value(field["default"])
        rows.append((field["name"], field["unit"] or "-", field["type"], default, field["description"]))
    widths = [max(len(row[i]) for row in rows) for i in range(4)]
    lines.append("")
    for row in rows:
        lines.append("  " + "  ".join(cell.ljust(width) for cell, width in zip(row, widths)) + "  " + row[4])
    lines.append("")
    lines.append("  presets (fields that differ from default):")
    name_width = max(len(name) for name in record["presets"])
    units = {field["name"]: field["unit"] for field in record["fields"]}
    for name, changes in record["presets"].items():
        text = ", ".join(
            f"{field} = {_value(value)}{' ' + units[field] if units.get(field) else ''}"
            for field, value in changes.items()
        )
        if name == "default":
            text = "the default column above"
        lines.append(f"    {name.ljust(name_width)}  {text or '(same as default)'}")
    return "\n".join(line.rstrip() for line in lines)
