"""`albot1 warm-up [METHOD...]`: every preset's kernels compiled (or loaded) before any run, failures one per line."""

from __future__ import annotations

import subprocess
import sys

import pytest
from typer.testing import CliRunner

from albot1.cli.app import app

runner = CliRunner()


@pytest.fixture
def warmed(monkeypatch: pytest.MonkeyPatch) -> list[list[str]]:
    """The method lists handed to ``warm_up_methods`` (which does nothing here and fails nothing)."""
    calls: list[list[str]] = []

    def warm_up_methods(methods: list[str], registry: object = None, announce: object = None) -> list[str]:
        calls.append(list(methods))
        return []

    monkeypatch.setattr("albot1.methods.warm_ups.warm_up_methods", warm_up_methods)
    return calls


def test_by_default_every_available_method_with_a_start_up_step_is_warmed_up(warmed: list[list[str]]) -> None:
    result = runner.invoke(app, ["warm-up"])
    assert result.exit_code == 0, result.output
    assert warmed == [["albot1", "albot1-places"]]  # odometry, kiss-icp, gtsam-graph... have no warm_up
    assert result.output.startswith("albot1 warm-up: albot1, albot1-places: every preset ready in ")


def test_a_method_without_a_start_up_step_has_nothing_to_do(warmed: list[list[str]]) -> None:
    result = runner.invoke(app, ["warm-up", "odometry"])
    assert result.exit_code == 0, result.output
    assert warmed == []
    assert result.output == "albot1 warm-up: none of these methods has a start-up step; nothing to do\n"


def test_each_failure_is_one_line_and_the_exit_is_non_zero(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(
        "albot1.methods.warm_ups.warm_up_methods",
        lambda methods, registry=None, announce=None: ["method albot1: warm-up: TypingError: bad kernel"],
    )
    result = runner.invoke(app, ["warm-up", "albot1"])
    assert result.exit_code == 1
    assert result.output == "albot1: error: warm-up: method albot1: warm-up: TypingError: bad kernel\n"


def test_an_unknown_method_is_one_line_and_exit_1() -> None:
    done = subprocess.run(
        [sys.executable, "-c", "from albot1.cli.app import main; main()", "warm-up", "no-such-method"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 1
    assert done.stderr.startswith("albot1: error: unknown method 'no-such-method'; expected one of: ")
    assert done.stderr.count("\n") == 1
