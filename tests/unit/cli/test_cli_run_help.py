"""`albot1 run --help` lists every registered method and every preset, from the registry itself."""

from __future__ import annotations

from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.methods.registry import method_registry
from conftest import PluginInstaller

runner = CliRunner()


def test_help_lists_every_method_and_every_preset_of_the_installed_methods() -> None:
    result = runner.invoke(app, ["run", "--help"], env={"COLUMNS": "400"})
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.replace("│", " ").split())
    for spec in method_registry():
        assert spec.name in text
        if spec.available():
            assert f"{spec.name}: {' | '.join(spec.load_class().presets)}" in text
    assert "plus" in text and "literal" in text


def test_help_follows_a_registry_with_a_plugin(install_method_plugin: PluginInstaller) -> None:
    install_method_plugin({"my-slam": "tests_no_such_module:Mapper"})
    result = runner.invoke(app, ["run", "--help"], env={"COLUMNS": "400"})
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.replace("│", " ").split())
    assert "my-slam" in text and "my-slam: `albot1 methods --presets my-slam`" in text
