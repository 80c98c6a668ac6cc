"""The one "module:Class" resolver (albot1.config.targets)."""

from __future__ import annotations

import pytest

from albot1.config.targets import TargetError, check_target, resolve_class, resolve_target
from albot1.data.loaders.carmen.loader import CarmenLoader

VALUE = 7


class Outer:
    class Inner:
        pass


@pytest.mark.parametrize("target", ["a:B", "a.b_c.d:E", "pkg.mod:Outer.Inner", "_x:_Y"])
def test_well_formed_targets(target: str) -> None:
    assert check_target(target) == target


@pytest.mark.parametrize("target", ["", "nocolon", "a.b.C", "a:b:c", ":C", "a:", "a.:C", "1a:B", "a b:C", "a:B "])
def test_malformed_targets(target: str) -> None:
    with pytest.raises(TargetError, match=r"^expected 'module:Class' \(a dotted module path, a colon, a class name\)"):
        check_target(target)


def test_resolution() -> None:
    assert resolve_class("albot1.data.loaders.carmen.loader:CarmenLoader") is CarmenLoader
    assert resolve_class(f"{__name__}:Outer.Inner") is Outer.Inner
    assert resolve_target(f"{__name__}:VALUE") == 7


def test_failures_name_the_target() -> None:
    with pytest.raises(TargetError, match=r"^no_such_module_xyz:C: the module no_such_module_xyz cannot be imported"):
        resolve_target("no_such_module_xyz:C")
    with pytest.raises(TargetError, match=r"has no attribute 'Nope'$"):
        resolve_target(f"{__name__}:Nope")
    with pytest.raises(TargetError, match=r":VALUE: expected a class, found int$"):
        resolve_class(f"{__name__}:VALUE")
