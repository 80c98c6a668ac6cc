"""Ground truth never reaches a method: every registered method runs on a world whose reference is a trap.

While a mapper's ``process`` or ``finish`` runs, reading ``Frame.reference``
of any frame raises; the runner itself (before and after those calls) reads
it for the evaluation. Each method must run to the end, get frames without a
reference, and the result must still carry the reference poses.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame
from albot1.data.open import open_sequence
from albot1.methods.registry import MethodSpec, method_registry
from albot1.runs import execute

WORLD = "synthetic-office-startstop[:25]"


class GroundTruthAccess(Exception):
    """A mapper read a frame's reference pose."""


class _Trap:
    """Stands for ``Frame.reference`` (a slot): any read while :attr:`armed` raises."""

    armed = False

    def __init__(self, slot: Any) -> None:
        self.slot = slot

    def __get__(self, frame: Frame | None, owner: type | None = None) -> Any:
        if frame is None:
            return self
        if _Trap.armed:
            raise GroundTruthAccess("a mapper read Frame.reference (ground truth)")
        return self.slot.__get__(frame, owner)

    def __set__(self, frame: Frame, value: Any) -> None:
        self.slot.__set__(frame, value)


class _Spec:
    """A registry entry whose class is ``cls`` (everything else is the real entry's)."""

    def __init__(self, spec: MethodSpec, cls: type) -> None:
        self._spec, self._cls = spec, cls

    def __getattr__(self, name: str) -> Any:
        return getattr(self._spec, name)

    def load_class(self) -> type:
        return self._cls


def _trapped(cls: type, seen: list[Frame]) -> type:
    """``cls`` with its calls run under the armed trap; records the frames it is given."""

    class Trapped(cls):  # type: ignore[misc, valid-type]
        def process(self, frame: Frame) -> Any:
            seen.append(frame)
            _Trap.armed = True
            try:
                return super().process(frame)
            finally:
                _Trap.armed = False

        def finish(self) -> Any:
            _Trap.armed = True
            try:
                return super().finish()
            finally:
                _Trap.armed = False

    return Trapped


@pytest.fixture
def trap(monkeypatch: pytest.MonkeyPatch) -> list[Frame]:
    """Arm-able trap on ``Frame.reference``; every method the runner loads is wrapped. Returns the frames given."""
    seen: list[Frame] = []
    monkeypatch.setattr(Frame, "reference", _Trap(Frame.__dict__["reference"]))
    real = execute.get_method

    def get_method(name: str, registry: Any = None) -> Any:
        spec = real(name, registry)
        return _Spec(spec, _trapped(spec.load_class(), seen))

    monkeypatch.setattr(execute, "get_method", get_method)
    return seen


@pytest.mark.parametrize("method", method_registry().names())
def test_every_method_runs_without_ever_reading_ground_truth(method: str, trap: list[Frame]) -> None:
    spec = method_registry().get(method)
    if not spec.available():
        pytest.skip(f"{method} unavailable: {spec.unavailable_reason()}")
    sequence = open_sequence(WORLD)
    result = execute.run_method(method, sequence, seed=0)
    assert len(trap) == 25 and all(frame.reference is None for frame in trap)
    assert result.reference is not None and result.reference.shape == (25, 3)
    assert np.isfinite(result.reference).all()


class _Cheat:
    """A mapper that uses the reference poses: what the trap exists to catch."""

    def __init__(self, config: Any, seed: int = 0) -> None:
        self.poses: list[Any] = []

    def process(self, frame: Frame) -> None:
        self.poses.append(frame.reference if frame.reference is not None else frame.odometry)

    def finish(self) -> MapperOutput:
        return MapperOutput(poses=np.asarray(self.poses), map=MapData(), counters={"views": 0, "updates": 0})


def test_a_mapper_that_reads_ground_truth_fails_loudly(trap: list[Frame], monkeypatch: pytest.MonkeyPatch) -> None:
    spec = method_registry().get("odometry")
    monkeypatch.setattr(execute, "get_method", lambda name, registry=None: _Spec(spec, _trapped(_Cheat, trap)))
    with pytest.raises(
        Exception, match=r"odometry on synthetic-office-startstop.* failed at scan 0: GroundTruthAccess"
    ):
        execute.run_method("odometry", open_sequence(WORLD), seed=0)


def test_the_runner_hands_a_method_the_scan_and_odometry_only() -> None:
    scan = open_sequence(WORLD).frames().__next__().scan
    frame = Frame(3, scan, np.array([1.0, 2.0, 0.5]), np.array([1.1, 2.1, 0.4]))
    blind = execute.withhold_ground_truth(frame)
    assert (blind.index, blind.reference) == (3, None)
    assert np.array_equal(blind.odometry, frame.odometry) and np.array_equal(blind.scan.ranges, scan.ranges)
    assert blind.scan.timestamp == scan.timestamp and blind.scan.max_range == scan.max_range
    # the method's own arrays (a write stays with it); the shared read-only beam angles are handed as they are
    assert blind.odometry is not frame.odometry and blind.scan.ranges is not scan.ranges
    assert blind.scan.angles is scan.angles
    assert frame.reference is not None  # the runner's own frame keeps it for the evaluation


@pytest.mark.parametrize("method", method_registry().names())
def test_albot1_run_on_the_command_line_never_hands_ground_truth_to_a_method(
    method: str, trap: list[Frame], tmp_path: Path
) -> None:
    """The user's path (`albot1 run METHOD WORLD`): the method runs blind, the run folder is scored on the reference."""
    from typer.testing import CliRunner

    from albot1.cli.app import app

    spec = method_registry().get(method)
    if not spec.available():
        pytest.skip(f"{method} unavailable: {spec.unavailable_reason()}")
    ran = CliRunner().invoke(app, ["run", method, WORLD, "--out", str(tmp_path), "--json"], catch_exceptions=False)
    assert ran.exit_code == 0, ran.output
    assert len(trap) == 25 and all(frame.reference is None for frame in trap)
    run_dir = Path(json.loads(ran.stdout)["run_dir"])
    evaluated = CliRunner().invoke(app, ["evaluate", str(run_dir), "--json"], catch_exceptions=False)
    assert evaluated.exit_code == 0, evaluated.output
    assert json.loads(evaluated.stdout)["ate"]["n"] == 25  # the reference reached the evaluation
