"""A plugin method's distribution and version are recorded with its runs and are part of their keys.

Why: the code version is a digest of this package alone, so a run of a plugin recorded nothing of the plugin's
code, and a plugin upgraded since its cells ran kept the older version's results ("already complete (kept)").
"""

from __future__ import annotations

import importlib
import json
import re
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict

from albot1.bench.plan import plan_suite
from albot1.bench.suite import load_suite
from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame
from albot1.data.open import open_sequence
from albot1.methods.errors import PluginError
from albot1.methods.registry import method_registry
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run
from albot1.settings import Settings
from conftest import PluginInstaller

WORLD = "synthetic-office-startstop"


class StillConfig(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class StillMapper:
    """A plugin mapper: reports the odometry it was given as its poses."""

    name: ClassVar[str] = "still"
    config_model: ClassVar[type[BaseModel]] = StillConfig
    presets: ClassVar[dict[str, dict[str, Any]]] = {"default": {}}

    def __init__(self, config: StillConfig, seed: int = 0) -> None:
        self.poses: list[Any] = []

    def process(self, frame: Frame) -> None:
        self.poses.append(frame.odometry)

    def finish(self) -> MapperOutput:
        n = len(self.poses)
        return MapperOutput(np.asarray(self.poses), MapData(points=np.zeros((1, 2))), {"views": n, "updates": n})


def _upgrade(site: Path, version: str) -> None:
    """The installed plugin distribution, now at ``version`` (its metadata rewritten, as an upgrade does)."""
    [info] = site.glob("*.dist-info")
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: albot1-test-plugin\nVersion: {version}\n")
    importlib.invalidate_caches()
    method_registry.cache_clear()


def _key(tmp_path: Path) -> str:
    suite = tmp_path / "suite.toml"
    suite.write_text(f'[[methods]]\nname = "still"\n\n[[datasets]]\nname = "{WORLD}[:5]"\nsweep = false\n')
    [cell] = plan_suite(load_suite(suite), Settings(data_dir=None, cache_dir=tmp_path / "cache")).cells
    return cell.key


def test_an_upgraded_plugin_plans_another_key(install_method_plugin: PluginInstaller, tmp_path: Path) -> None:
    site = install_method_plugin({"still": f"{__name__}:StillMapper"})
    first = _key(tmp_path)
    assert _key(tmp_path) == first
    _upgrade(site, "0.2")
    assert _key(tmp_path) != first


def test_a_plugin_run_records_its_distribution_and_is_stored_under_the_planned_key(
    install_method_plugin: PluginInstaller, tmp_path: Path
) -> None:
    _upgrade(install_method_plugin({"still": f"{__name__}:StillMapper"}), "0.3")
    planned = _key(tmp_path)
    result = run_method("still", open_sequence(f"{WORLD}[:5]"), dataset_name=f"{WORLD}[:5]")
    folder = write_run(result, tmp_path / "runs")
    assert folder.name == planned
    versions = json.loads((folder / "result.json").read_text())["versions"]
    assert versions["plugin"] == "albot1-test-plugin 0.3"


def test_a_built_in_run_records_no_plugin(tmp_path: Path) -> None:
    result = run_method("odometry", open_sequence(f"{WORLD}[:3]"))
    assert "plugin" not in result.versions


@pytest.mark.parametrize("name", ["my slam", "odometry:fast", "-x", "a/b"])
def test_a_plugin_name_that_is_no_method_name_is_one_line(install_method_plugin: PluginInstaller, name: str) -> None:
    """``odometry:fast`` would read in every report as the built-in odometry under a preset "fast"."""
    install_method_plugin({name: f"{__name__}:StillMapper"})
    with pytest.raises(
        PluginError, match=rf"entry point {re.escape(repr(name))} of albot1-test-plugin 0.1 .*a method name"
    ):
        method_registry()
