"""What `import albot1.cli.app` and `albot1 [COMMAND] --help` load: the CLI layer, not the package.

Typer imports every command module to build the help, so a command module that imports its work at
module level (the data, runs, bench or report layers, and with them numpy, pydantic, matplotlib, ...)
makes every `albot1` invocation pay for all of them (`albot1 --help` took more than twice as long).
The command functions import their work when they run (`albot1/cli/app.py`). This checks which
modules a fresh interpreter has loaded, rather than timing anything.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

#: Libraries `import albot1` must never load at import (docs/architecture.md: imported where used).
HEAVY_OPTIONAL = (
    "matplotlib",
    "pandas",
    "scipy",
    "numba",
    "gtsam",
    "kiss_icp",
    "rosbags",
    "mcap",
    "dask",
    "distributed",
    "evo",
    "shapely",
)
#: Core libraries that only a command's work needs (Typer itself loads pydantic to parse a command's
#: arguments and to render a command's help, but not for `albot1 --help`).
WORK_LIBRARIES = ("numpy", "pydantic", "pydantic_settings")
#: The package modules below the CLI that its modules may import at module level: cheap, no library.
CHEAP_MODULES = {
    "albot1",
    "albot1.errors",
    "albot1.settings",
    "albot1.methods",
    "albot1.methods.errors",
    "albot1.runs",
    "albot1.runs.errors",
    "albot1.runs.output",
}

#: What `albot1 run --help` may load besides: the method registry and the presets files it lists from
#: (help generated from them, albot1.cli.choices), never a mapper or a numerical library.
REGISTRY_HELP_MODULES = {
    "albot1.methods.registry",
    "albot1.methods.plugins",
    "albot1.config",
    "albot1.config.env",
    "albot1.config.keyvalue",
    "albot1.config.known_limits",
    "albot1.config.numbers",
    "albot1.config.presets",
    "albot1.config.resolve",
    "albot1.config.suggest",
    "albot1.config.targets",
    "albot1.config.validation",
    "albot1.resources",
}

PROBE = """
import json, sys
from albot1.cli.app import app
args = json.loads(sys.argv[1])
code = None
if args is not None:
    try:
        app(args, prog_name="albot1")
    except SystemExit as exc:
        code = exc.code
with open(sys.argv[2], "w") as out:
    json.dump({"exit": code, "modules": sorted(sys.modules)}, out)
"""


def loaded(tmp_path: Path, args: list[str] | None) -> set[str]:
    """The modules a fresh interpreter holds after importing the app (and running it with ``args``)."""
    report = tmp_path / "modules.json"
    done = subprocess.run(
        [sys.executable, "-c", PROBE, json.dumps(args), str(report)], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    found = json.loads(report.read_text())
    if args is not None:
        assert found["exit"] == 0, f"albot1 {' '.join(args)}: exit {found['exit']}: {done.stderr}"
        assert "Usage: albot1" in done.stdout, done.stdout  # the help was rendered, not skipped
    return set(found["modules"])


def top_level(modules: set[str]) -> set[str]:
    return {name.split(".")[0] for name in modules}


def package_below_cli(modules: set[str]) -> set[str]:
    """albot1 modules outside the CLI layer and the cheap base modules."""
    return {m for m in modules if m.split(".")[0] == "albot1" and not m.startswith("albot1.cli")} - CHEAP_MODULES


@pytest.mark.parametrize("args", [None, ["--help"]], ids=["import", "help"])
def test_importing_the_app_and_its_help_load_neither_the_package_nor_its_libraries(
    tmp_path: Path, args: list[str] | None
) -> None:
    modules = loaded(tmp_path, args)
    assert "albot1.cli.run" in modules and "albot1.cli.bench" in modules  # every command module was imported
    assert top_level(modules) & set(HEAVY_OPTIONAL) == set()
    assert top_level(modules) & set(WORK_LIBRARIES) == set()
    assert package_below_cli(modules) == set(), "import these inside the command function that uses them"


@pytest.mark.parametrize(
    "command",
    [["run"], ["evaluate"], ["bench"], ["report"], ["runs"], ["methods"], ["convert"], ["datasets", "info"]],
    ids=" ".join,
)
def test_a_commands_help_loads_none_of_its_work(tmp_path: Path, command: list[str]) -> None:
    modules = loaded(tmp_path, [*command, "--help"])
    assert top_level(modules) & {*HEAVY_OPTIONAL, "numpy"} == set()
    allowed = REGISTRY_HELP_MODULES if command == ["run"] else set()
    assert package_below_cli(modules) - allowed == set(), "import these inside the command function that uses them"
