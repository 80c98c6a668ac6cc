"""The forkserver preload: a failed import is reported once, by name, never swallowed."""

from __future__ import annotations

import logging
from types import ModuleType

import pytest


@pytest.fixture
def preload() -> ModuleType:
    """The preload module, imported when a test runs rather than at collection (importing it preloads every method)."""
    from albot1.bench import preload

    return preload


def test_a_failed_import_is_returned_with_module_and_reason(preload: ModuleType) -> None:
    failures = preload.warm(["json", "albot1_no_such_module_xyz"])
    assert [f for f in failures if "albot1_no_such_module_xyz" in f] == [
        "module albot1_no_such_module_xyz: ModuleNotFoundError: No module named 'albot1_no_such_module_xyz'"
    ]
    assert not any(f.startswith("module json") for f in failures)


def test_the_shipped_list_imports_cleanly(preload: ModuleType) -> None:
    assert [f for f in preload.warm() if f.startswith("module ")] == []


def test_failures_are_logged_once_each(
    preload: ModuleType, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    monkeypatch.setattr(preload, "warm", lambda: ["module x: ImportError: boom"])
    monkeypatch.setattr(preload, "_warm_matplotlib", lambda: None)
    with caplog.at_level(logging.WARNING, logger=preload.__name__):
        preload._warm()
    assert [r.getMessage() for r in caplog.records] == [
        "albot1 bench: preloading module x: ImportError: boom (each cell that needs it will fail with this reason)"
    ]


_FORKED_CELL = """
import json
import albot1.bench.preload  # what the forkserver imports before it forks any cell
from albot1.methods.registry import get_method, resolve_config
from albot1.methods.albot1.warm_up import kernel_names

mapper = get_method("albot1").load_class()(resolve_config("albot1", "plus", None))
print(json.dumps({name: len(getattr(k, name).signatures) for k in mapper.kernels for name in kernel_names(k)}))
"""


@pytest.mark.slow
def test_the_forkserver_compiles_every_kernel_before_any_cell_is_forked() -> None:
    """A cell forked after the preload finds every Albot1 kernel compiled: its start-up compiles nothing."""
    import json
    import os
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-c", _FORKED_CELL], env=dict(os.environ), capture_output=True, text=True, timeout=900
    )
    assert out.returncode == 0, out.stderr
    counts = json.loads(out.stdout)
    assert counts and all(n >= 1 for n in counts.values()), counts
