"""Imports made by name from strings obey the layer contract that import-linter checks for ``import`` lines.

import-linter sees only import statements; a ``"module:Class"`` string
resolved at run time is invisible to it. Every such string the package
holds is listed here with the module that holds it, and checked against the
same contract (read from ``pyproject.toml``): a module may import by name
what it could import by statement (a lower layer, its own top-level package,
or a third-party library), never a higher layer or an independent sibling.
"""

from __future__ import annotations

import pkgutil
import tomllib
from pathlib import Path

import pytest

from albot1.bench.cells import renderer_target
from albot1.data.loaders.registry import FORMATS, WRITE_ONLY_FORMATS
from albot1.methods.registry import MethodRegistry, MethodSpec, method_registry
from albot1.metrics import measures
from albot1.metrics.registry import MEASURES
from albot1.report.preview import render_preview

PYPROJECT = Path(__file__).resolve().parents[3] / "pyproject.toml"


def _layers() -> list[list[str]]:
    config = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["tool"]["importlinter"]["contracts"]
    contract = next(c for c in config if c["type"] == "layers")
    return [[part.strip() for part in layer.split("|")] for layer in contract["layers"]]


def _position(module: str, layers: list[list[str]]) -> tuple[int, str] | None:
    """(layer index, top-level package of the contract) of ``module``; None outside the contract."""
    for index, layer in enumerate(layers):
        for package in layer:
            if module == package or module.startswith(package + "."):
                return index, package
    return None


def allowed(importer: str, imported: str, layers: list[list[str]]) -> bool:
    """Whether ``importer`` may import ``imported`` under the layers contract (higher layers import lower ones)."""
    target = _position(imported, layers)
    if target is None:
        return True  # a third-party library, or a part of the package the contract does not constrain
    source = _position(importer, layers)
    assert source is not None, f"{importer} is in no layer of the contract"
    if source[1] == target[1]:
        return True  # inside one package (its own sibling rules are import-linter's acyclic_siblings)
    return target[0] > source[0]


def _module(target: str) -> str:
    return target.partition(":")[0]


def by_name_imports(registry: MethodRegistry) -> list[tuple[str, str, str]]:
    """(module holding the string, module it names, what it is) for every by-name import of the package."""
    out = []
    for spec in registry:
        names = [("target", spec.target), ("error_class", spec.error_class)]
        out += [("albot1.methods.registry", _module(t), f"method {spec.name} {what}") for what, t in names]
    for loader, writer in FORMATS.values():
        out += [("albot1.data.loaders.registry", _module(t), "format") for t in (loader, writer) if t]
    out += [("albot1.data.loaders.registry", _module(t), "format") for t in WRITE_ONLY_FORMATS.values()]
    # Imported here, not at collection: importing the preload module preloads every method (its purpose in the
    # forkserver), a cost every xdist worker would pay while collecting.
    from albot1.bench import preload

    out += [("albot1.bench.preload", name, "preload") for name in preload.MODULES]
    # The metric registry imports every module of its measures package by name (pkgutil).
    out += [
        ("albot1.metrics.registry", f"{MEASURES}.{m.name}", "metric") for m in pkgutil.iter_modules(measures.__path__)
    ]
    # The preview renderer travels to the cells by name, but the name is made by whoever hands the renderer to
    # the runner (the CLI, the report): it is theirs, checked here for the CLI.
    out.append(("albot1.cli.bench", _module(renderer_target(render_preview)), "preview renderer"))
    return out


def test_the_contract_rule_itself() -> None:
    layers = _layers()
    assert allowed("albot1.bench.preload", "albot1.runs.execute", layers)
    assert allowed("albot1.bench.preload", "numpy", layers)
    assert allowed("albot1.methods.registry", "albot1.methods.baselines.odometry", layers)
    assert not allowed("albot1.bench.preload", "albot1.report.preview", layers)  # upward
    assert not allowed("albot1.methods.registry", "albot1.metrics.places", layers)  # independent siblings
    assert allowed("albot1.metrics.registry", "albot1.metrics.measures.ate", layers)
    assert not allowed("albot1.data.loaders.registry", "albot1.runs.folder", layers)


def test_every_by_name_import_obeys_the_layer_contract() -> None:
    layers = _layers()
    found = by_name_imports(method_registry())
    assert len(found) > 20  # the lists above are read, not empty
    broken = [(holder, imported, what) for holder, imported, what in found if not allowed(holder, imported, layers)]
    assert not broken, f"by-name imports against the layer contract: {broken}"


def test_a_registry_entry_naming_a_higher_layer_is_caught() -> None:
    bad = method_registry().with_methods(MethodSpec("bad", "albot1.bench.cells:Cell"))
    layers = _layers()
    broken = [i for h, i, _ in by_name_imports(bad) if not allowed(h, i, layers)]
    assert "albot1.bench.cells" in broken


@pytest.mark.parametrize("module", ["albot1.report.preview", "albot1.cli.app"])
def test_preload_naming_a_higher_layer_is_caught(module: str) -> None:
    assert not allowed("albot1.bench.preload", module, _layers())
