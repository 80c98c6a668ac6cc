"""Listings aligned on their widest cell: `albot1 methods` with a long plugin name, `albot1 datasets list`."""

from __future__ import annotations

from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.cli.columns import aligned
from conftest import PluginInstaller

runner = CliRunner()


def test_columns_are_as_wide_as_their_widest_cell() -> None:
    assert aligned([("a", "bb", "last one"), ("cccc", "d", "x")]) == ["a     bb  last one", "cccc  d   x"]
    assert aligned([("a", "", ""), ("bb", "c", "d")]) == ["a", "bb  c  d"]
    assert aligned([]) == []


def test_methods_listing_aligns_a_long_plugin_name(install_method_plugin: PluginInstaller) -> None:
    long_name = "a-plugin-method-with-a-long-name"
    install_method_plugin({long_name: "tests_no_such_module:Mapper"})
    result = runner.invoke(app, ["methods"])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    rows = [line for line in lines if not line.startswith(" ")]
    assert rows[-1].startswith(f"{long_name}  unavailable  ")
    starts = {line.index("available") - (2 if "unavailable" in line else 0) for line in rows}
    assert starts == {len(long_name) + 2}
    # the unavailability reason sits in the description column
    reason = lines[lines.index(rows[-1]) + 1]
    assert reason.startswith(" " * (len(long_name) + 2 + len("unavailable") + 2) + "-> ")


def test_datasets_list_aligns_every_row() -> None:
    result = runner.invoke(app, ["datasets", "list"])
    assert result.exit_code == 0, result.output
    rows = [line for line in result.output.splitlines() if not line.startswith("searched: ")]
    names = [row.split()[0] for row in rows]
    width = max(len(name) for name in names)
    assert "synthetic-office-startstop-10deg" in names
    for row, name in zip(rows, names):
        assert row[: width + 2] == name.ljust(width + 2) and row[width + 2] != " ", row
