"""The forkserver preload: a failed import is reported once, by name, never swallowed."""

from __future__ import annotations

import logging

import pytest

from albot1.bench import preload


def test_a_failed_import_is_returned_with_module_and_reason() -> None:
    failures = preload.warm(["json", "albot1_no_such_module_xyz"])
    assert [f for f in failures if "albot1_no_such_module_xyz" in f] == [
        "module albot1_no_such_module_xyz: ModuleNotFoundError: No module named 'albot1_no_such_module_xyz'"
    ]
    assert not any(f.startswith("module json") for f in failures)


def test_the_shipped_list_imports_cleanly() -> None:
    assert [f for f in preload.warm() if f.startswith("module ")] == []


def test_failures_are_logged_once_each(monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture) -> None:
    monkeypatch.setattr(preload, "warm", lambda: ["module x: ImportError: boom"])
    monkeypatch.setattr(preload, "_warm_matplotlib", lambda: None)
    with caplog.at_level(logging.WARNING, logger=preload.__name__):
        preload._warm()
    assert [r.getMessage() for r in caplog.records] == [
        "albot1 bench: preloading module x: ImportError: boom (each cell that needs it will fail with this reason)"
    ]
