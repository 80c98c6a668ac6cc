"""Every preset's warm-up of several methods at once: one joint compile, and each failure under its own method."""

from __future__ import annotations

import pytest

from albot1.methods import warm_ups


class _Together:
    """A class's ``warm_up_together`` that records when its block opens and closes."""

    def __init__(self, name: str, events: list[str]) -> None:
        self.name, self.events = name, events

    def __enter__(self) -> None:
        self.events.append(f"open {self.name}")

    def __exit__(self, *exc: object) -> None:
        self.events.append(f"close {self.name}")


def _fake_methods(monkeypatch: pytest.MonkeyPatch, events: list[str], failing: set[str]) -> None:
    """Methods ``a`` (with ``warm_up_together``), ``b`` (without) and ``c`` (with); a warm-up of ``failing`` raises."""
    from types import SimpleNamespace

    def load(name: str) -> object:
        if name == "b":
            return SimpleNamespace()
        return SimpleNamespace(warm_up_together=lambda: _Together(name, events))

    def warm_up(name: str, registry: object, announce: object = None) -> None:
        events.append(f"warm {name}")
        if name in failing:
            raise RuntimeError(f"{name} does not compile")

    monkeypatch.setattr(
        "albot1.methods.registry.get_method",
        lambda name, registry=None: SimpleNamespace(load_class=lambda: load(name)),
    )
    monkeypatch.setattr(warm_ups, "warm_up_method", warm_up)


def test_the_methods_warm_ups_run_inside_every_class_s_together_block(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """One cold compile for every preset of every method: the blocks close after the last warm-up."""
    events: list[str] = []
    _fake_methods(monkeypatch, events, failing=set())
    outcome = warm_ups.warm_up_methods(["a", "b", "c"])
    assert events == ["open a", "open c", "warm a", "warm b", "warm c", "close c", "close a"]
    assert outcome == warm_ups.WarmUpOutcome() and outcome.lines() == []


def test_a_failed_warm_up_together_is_reported_under_its_own_method(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The warm-ups then run again one by one, so each failure names its method and the others still warm up."""
    events: list[str] = []
    _fake_methods(monkeypatch, events, failing={"b"})
    outcome = warm_ups.warm_up_methods(["a", "b", "c"])
    assert events == ["open a", "open c", "warm a", "warm b", "close c", "close a", "warm a", "warm b", "warm c"]
    assert outcome.failures == ["method b: warm-up: RuntimeError: b does not compile"]
    assert outcome.joint_failure is None


def test_a_failure_of_the_joint_warm_up_alone_is_still_reported(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Nothing swallowed: when the one-by-one warm-ups all succeed, the joint pass's error is reported as itself."""
    events: list[str] = []
    _fake_methods(monkeypatch, events, failing=set())
    failed_once: list[str] = []

    def close_failing_once(self: _Together, *exc: object) -> None:
        self.events.append(f"close {self.name}")
        if not failed_once:
            failed_once.append(self.name)
            raise RuntimeError("helper lost")

    monkeypatch.setattr(_Together, "__exit__", close_failing_once)
    outcome = warm_ups.warm_up_methods(["a", "c"])
    assert events == ["open a", "open c", "warm a", "warm c", "close c", "close a", "warm a", "warm c"]
    joint = "methods a, c: warm-up together: RuntimeError: helper lost (each method's warm-up alone then succeeded)"
    assert outcome.failures == [] and outcome.joint_failure == joint and outcome.lines() == [joint]


def test_a_method_without_a_start_up_step_is_not_built(monkeypatch: pytest.MonkeyPatch) -> None:
    from types import SimpleNamespace

    built: list[str] = []

    class NoWarmUp:
        presets = {"default": {}}

        def __init__(self, *args: object, **kwargs: object) -> None:
            built.append("built")

    monkeypatch.setattr(
        "albot1.methods.registry.get_method", lambda name, registry=None: SimpleNamespace(load_class=lambda: NoWarmUp)
    )
    warm_ups.warm_up_method("x")
    assert built == [] and not warm_ups.has_warm_up(NoWarmUp)
