"""`albot1 warm-up [METHOD...]`: every preset's kernels compiled (or loaded) before any run, failures one per line."""

from __future__ import annotations

import subprocess
import sys

import pytest
from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.methods.warm_ups import WarmUpOutcome

runner = CliRunner()


def with_warm_up() -> list[str]:
    """The available methods with a start-up step: Albot1's two, and gtsam-graph (its grid search) with GTSAM."""
    from albot1.methods.registry import method_registry

    return ["albot1", "albot1-places", *(["gtsam-graph"] if method_registry().get("gtsam-graph").available() else [])]


@pytest.fixture
def warmed(monkeypatch: pytest.MonkeyPatch) -> list[list[str]]:
    """The method lists handed to ``warm_up_methods`` (which does nothing here and fails nothing)."""
    calls: list[list[str]] = []

    def warm_up_methods(methods: list[str], registry: object = None, announce: object = None) -> WarmUpOutcome:
        calls.append(list(methods))
        return WarmUpOutcome()

    monkeypatch.setattr("albot1.methods.warm_ups.warm_up_methods", warm_up_methods)
    return calls


def test_by_default_every_available_method_with_a_start_up_step_is_warmed_up(warmed: list[list[str]]) -> None:
    result = runner.invoke(app, ["warm-up"])
    assert result.exit_code == 0, result.output
    assert warmed == [with_warm_up()]  # odometry, kiss-icp, mrpt... have no warm_up
    assert result.output.startswith(f"albot1 warm-up: {', '.join(with_warm_up())}: every preset ready in ")


def test_a_method_without_a_start_up_step_has_nothing_to_do(warmed: list[list[str]]) -> None:
    result = runner.invoke(app, ["warm-up", "odometry"])
    assert result.exit_code == 0, result.output
    assert warmed == []
    assert result.output == "albot1 warm-up: none of these methods has a start-up step; nothing to do\n"


def test_each_failure_is_one_line_and_the_exit_is_non_zero(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(
        "albot1.methods.warm_ups.warm_up_methods",
        lambda methods, registry=None, announce=None: WarmUpOutcome(
            failures=["method albot1: warm-up: TypingError: bad kernel"]
        ),
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


def test_a_method_named_twice_is_warmed_up_once(warmed: list[list[str]]) -> None:
    result = runner.invoke(app, ["warm-up", "albot1", "albot1"])
    assert result.exit_code == 0, result.output
    assert warmed == [["albot1"]]
    assert result.output.startswith("albot1 warm-up: albot1: every preset ready in ")


def test_a_method_that_cannot_be_loaded_is_one_line_and_the_others_still_warm_up(
    warmed: list[list[str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    """By default every available method is loaded; one whose import fails must not stop Albot1's compile."""
    from albot1.config.targets import TargetError
    from albot1.methods.registry import MethodSpec

    real = MethodSpec.load_class

    def load_class(self: MethodSpec) -> type:
        if self.name == "kiss-icp":
            raise TargetError("kiss_icp: broken install")
        return real(self)

    monkeypatch.setattr(MethodSpec, "load_class", load_class)
    result = runner.invoke(app, ["warm-up"])
    assert result.exit_code == 1
    assert warmed == [with_warm_up()]
    errors = [line for line in result.output.splitlines() if line.startswith("albot1: error:")]
    assert len(errors) == 1 and errors[0].startswith("albot1: error: warm-up: method kiss-icp (")
    assert errors[0].endswith("TargetError: kiss_icp: broken install")


def test_a_failure_of_the_joint_pass_alone_is_a_warning_not_an_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each method's warm-up alone succeeded, so every kernel is ready: said on one line, exit 0."""
    joint = "methods albot1: warm-up together: RuntimeError: helper lost (each method's warm-up alone then succeeded)"
    monkeypatch.setattr(
        "albot1.methods.warm_ups.warm_up_methods",
        lambda methods, registry=None, announce=None: WarmUpOutcome(joint_failure=joint),
    )
    result = runner.invoke(app, ["warm-up", "albot1"])
    assert result.exit_code == 0, result.output
    assert f"albot1 warm-up: warning: {joint}\n" in result.output
    assert "every preset ready in" in result.output


def test_the_help_names_every_method_warmed_up_by_default(warmed: list[list[str]]) -> None:
    """`albot1 warm-up --help` said "every preset of albot1 and albot1-places" while gtsam-graph was warmed too."""
    runner.invoke(app, ["warm-up"])
    help_text = " ".join(runner.invoke(app, ["warm-up", "--help"], terminal_width=400).output.split())
    for name in warmed[0]:
        assert f"{name}," in help_text or f"{name} " in help_text, name
    assert "gtsam-graph" in help_text
