"""Third-party methods through package entry points (group ``albot1.methods``), with a real ``*.dist-info``."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any, ClassVar

import pytest
from pydantic import BaseModel, ConfigDict
from typer.testing import CliRunner

from albot1.bench.errors import SuiteError
from albot1.bench.plan import plan_suite
from albot1.bench.suite import load_suite
from albot1.cli.app import app
from albot1.config.targets import TargetError
from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame
from albot1.methods.errors import PluginError
from albot1.methods.plugins import PLUGIN_ERROR_CLASS
from albot1.methods.registry import method_registry
from albot1.settings import Settings
from conftest import PluginInstaller

WORLD = "synthetic-office-startstop"
#: Set when this module's mapper class is imported by name (the test module itself is already imported).
IMPORTED_BY_NAME: list[str] = []


class EchoConfig(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    gain: float = 1.0


class EchoMapper:
    """A plugin mapper: reports the odometry it was given as its poses."""

    name: ClassVar[str] = "echo"
    config_model: ClassVar[type[BaseModel]] = EchoConfig
    presets: ClassVar[dict[str, dict[str, Any]]] = {"default": {"gain": 1.0}, "double": {"gain": 2.0}}

    def __init__(self, config: EchoConfig, seed: int = 0) -> None:
        self.poses: list[Any] = []

    def process(self, frame: Frame) -> None:
        self.poses.append(frame.odometry)

    def finish(self) -> MapperOutput:
        import numpy as np

        return MapperOutput(
            poses=np.asarray(self.poses),
            map=MapData(points=np.zeros((1, 2))),
            counters={"views": len(self.poses), "updates": len(self.poses)},
        )


@pytest.fixture
def echo(install_method_plugin: PluginInstaller) -> str:
    install_method_plugin({"echo": f"{__name__}:EchoMapper"})
    return "echo"


def test_an_installed_entry_point_is_a_registered_method(echo: str) -> None:
    spec = method_registry().get(echo)
    assert spec.target == f"{__name__}:EchoMapper"
    assert spec.error_class == PLUGIN_ERROR_CLASS
    assert "albot1-test-plugin 0.1" in spec.description
    assert not spec.auto_include  # a suite runs a plugin where it names it
    assert spec.load_class() is EchoMapper


def test_without_the_distribution_the_method_is_unknown() -> None:
    assert "echo" not in method_registry()


def test_a_plugin_runs_in_albot1_run(echo: str, tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["run", echo, WORLD, "--out", str(tmp_path), "--json", "--preset", "double"])
    assert result.exit_code == 0, result.output
    assert '"method": "echo"' in result.output and '"preset": "double"' in result.output


@pytest.mark.slow
def test_a_plugin_runs_in_a_bench_suite(echo: str, tmp_path: Path) -> None:
    suite = tmp_path / "plug.toml"
    suite.write_text(f'[[methods]]\nname = "{echo}"\n\n[[datasets]]\nname = "{WORLD}"\n')
    results = tmp_path / "results"
    args = ["bench", str(suite), "-j", "1", "--results", str(results), "--no-progress"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    plan = (results / "plug" / "grid.json").read_text()
    assert '"method": "echo"' in plan


def test_a_plugin_installed_after_the_cell_forkserver_started_runs_in_its_cells(
    install_method_plugin: PluginInstaller, tmp_path: Path
) -> None:
    """The forkserver forks cells from its own state: the runner's import path (and so the plugin) reaches them."""
    from albot1.bench.limits import start_forkserver

    start_forkserver()  # as an earlier grid of this process would have
    install_method_plugin({"echo": f"{__name__}:EchoMapper"})
    suite = tmp_path / "late.toml"
    suite.write_text(f'[[methods]]\nname = "echo"\n\n[[datasets]]\nname = "{WORLD}"\n')
    args = ["bench", str(suite), "-j", "1", "--results", str(tmp_path / "results"), "--no-progress"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output


def test_planning_a_suite_imports_no_module_it_names(install_method_plugin: PluginInstaller, tmp_path: Path) -> None:
    """Only the registry decides what is imported: a suite naming a method imports its registered class only."""
    install_method_plugin({"lazy": "albot1_plugin_never_imported:Mapper"})
    suite = tmp_path / "lazy.toml"
    suite.write_text(f'[[methods]]\nname = "lazy"\n\n[[datasets]]\nname = "{WORLD}"\n')
    plan = plan_suite(load_suite(suite), Settings(data_dir=None, cache_dir=tmp_path / "cache"))
    # the plugin's module is not installed: found out without importing it, the method is skipped with the reason
    assert "albot1_plugin_never_imported" not in sys.modules
    [skipped] = plan.skipped_methods
    assert skipped.name == "lazy" and "needs albot1_plugin_never_imported, which is not installed" in skipped.reason
    assert skipped.hint == "reinstall albot1-test-plugin, which declares it"


def test_a_suite_naming_an_unregistered_method_fails_with_one_line(tmp_path: Path) -> None:
    suite = tmp_path / "s.toml"
    suite.write_text(f'[[methods]]\nname = "kiss_icp"\n\n[[datasets]]\nname = "{WORLD}"\n')
    with pytest.raises(SuiteError) as caught:
        plan_suite(load_suite(suite), Settings(data_dir=None, cache_dir=tmp_path / "cache"))
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith(f"{suite}: unknown method 'kiss_icp' (did you mean 'kiss-icp'?)")
    assert "entry point group albot1.methods" in message
    result = CliRunner().invoke(app, ["bench", str(suite), "--dry-run"])  # albot1.cli.app.main prints it as one line
    assert isinstance(result.exception, SuiteError) and str(result.exception) == message


def test_a_plugin_may_not_take_a_built_in_name(install_method_plugin: PluginInstaller) -> None:
    install_method_plugin({"odometry": f"{__name__}:EchoMapper"})
    with pytest.raises(PluginError, match=r"entry point 'odometry' of albot1-test-plugin 0.1 .* built-in method"):
        method_registry()


def test_a_malformed_entry_point_is_one_line(install_method_plugin: PluginInstaller) -> None:
    install_method_plugin({"broken": "no colon here"})
    with pytest.raises(PluginError, match=r"entry point 'broken' .*expected 'module:Class'"):
        method_registry()


class DictConfigMapper(EchoMapper):
    """A plugin whose config class is no pydantic model."""

    config_model = dict  # type: ignore[assignment]


@pytest.mark.parametrize(
    ("source", "found"),
    [
        ("raise RuntimeError('no licence file')\n", "importing it raised RuntimeError: no licence file"),
        ("import sys\nsys.exit(0)\n", "importing it raised SystemExit(0) (sys.exit)"),
        ("import sys\nsys.exit('bye')\n", "importing it raised SystemExit('bye') (sys.exit)"),
        ("undefined_name.attribute\n", "importing it raised NameError: name 'undefined_name' is not defined"),
    ],
)
def test_a_plugin_module_that_fails_as_it_is_imported_is_one_line_naming_it(
    install_method_plugin: PluginInstaller, source: str, found: str
) -> None:
    """A module raising (or calling sys.exit) at import once gave a traceback, or exit 0 with nothing done."""
    site = install_method_plugin({"rogue": "rogue_plugin_module:Mapper"})
    (site / "rogue_plugin_module.py").write_text(source)
    result = CliRunner().invoke(app, ["run", "rogue", f"{WORLD}[:3]", "--out", str(site / "runs")])
    assert isinstance(result.exception, TargetError), result.output
    assert str(result.exception) == (
        "method 'rogue' (plugin of albot1-test-plugin 0.1): rogue_plugin_module:Mapper: the module "
        f"rogue_plugin_module cannot be imported: {found}"
    )
    sys.modules.pop("rogue_plugin_module", None)


def test_a_plugin_whose_config_class_is_no_pydantic_model_is_one_line(
    install_method_plugin: PluginInstaller,
) -> None:
    install_method_plugin({"rogue": f"{__name__}:DictConfigMapper"})
    with pytest.raises(TargetError) as caught:
        method_registry().get("rogue").load_class()
    assert str(caught.value) == (
        f"method 'rogue' (plugin of albot1-test-plugin 0.1): {__name__}:DictConfigMapper: its config_model is "
        "<class 'dict'>; expected a pydantic BaseModel subclass (see albot1.contract.Mapper)"
    )


class ChattyMapper(EchoMapper):
    """A plugin that prints its progress to stdout."""

    def process(self, frame: Frame) -> None:
        print(f"chatty: scan {frame.index}")
        super().process(frame)


def test_what_a_plugin_prints_goes_to_stderr_and_the_json_stays_one_object(
    install_method_plugin: PluginInstaller, tmp_path: Path
) -> None:
    install_method_plugin({"chatty": f"{__name__}:ChattyMapper"})
    result = CliRunner().invoke(app, ["run", "chatty", f"{WORLD}[:3]", "--out", str(tmp_path), "--json"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)  # stdout is the JSON object alone
    assert (summary["method"], summary["scans"]) == ("chatty", 3)
    assert result.stderr == "chatty: scan 0\nchatty: scan 1\nchatty: scan 2\n"


@pytest.mark.parametrize("name", ["kiss_icp", "KISS-ICP", "Odometry"])
def test_a_plugin_may_not_take_a_built_in_methods_variables(install_method_plugin: PluginInstaller, name: str) -> None:
    """A plugin `kiss_icp` read ALBOT1_KISS_ICP_* (the built-in kiss-icp's variables) and ran for a suite's typo."""
    install_method_plugin({name: f"{__name__}:EchoMapper"})
    builtin = "odometry" if name == "Odometry" else "kiss-icp"
    prefix = "ALBOT1_ODOMETRY_" if name == "Odometry" else "ALBOT1_KISS_ICP_"
    with pytest.raises(PluginError) as caught:
        method_registry()
    assert str(caught.value) == (
        f"entry point {name!r} of albot1-test-plugin 0.1 (group albot1.methods) takes the name {builtin!r} of a "
        f"built-in method as {prefix}* variables; the plugin must choose another name"
    )


def test_two_plugins_may_not_share_their_variables(install_method_plugin: PluginInstaller) -> None:
    install_method_plugin({"my-slam": f"{__name__}:EchoMapper", "my_slam": f"{__name__}:EchoMapper"})
    with pytest.raises(PluginError) as caught:
        method_registry()
    assert str(caught.value) == (
        "methods 'my-slam' (albot1-test-plugin 0.1) and 'my_slam' (albot1-test-plugin 0.1) of group albot1.methods "
        "would read the same ALBOT1_MY_SLAM_* variables; one must choose another name"
    )


def test_what_a_plugin_module_prints_on_import_stays_out_of_the_bench_plan_table(
    install_method_plugin: PluginInstaller, tmp_path: Path
) -> None:
    site = install_method_plugin({"banner": "banner_plugin_module:Mapper"})
    (site / "banner_plugin_module.py").write_text(
        f"print('banner plugin 1.0 loaded')\nfrom {__name__} import EchoMapper as Mapper\n"
    )
    suite = tmp_path / "banner.toml"
    suite.write_text(f'[[methods]]\nname = "banner"\n\n[[datasets]]\nname = "{WORLD}[:3]"\n')
    result = CliRunner().invoke(app, ["bench", str(suite), "--dry-run"])
    sys.modules.pop("banner_plugin_module", None)
    assert result.exit_code == 0, result.output
    assert "banner plugin" not in result.stdout and result.stdout.startswith("suite banner")
    assert result.stderr == "banner plugin 1.0 loaded\n"
