"""The runner's contract: config resolution, timing, result checks, error wrapping."""

from __future__ import annotations

import subprocess
import sys
import time
from typing import Any, ClassVar

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict

from albot1.contract import MapData, MapperOutput
from albot1.data.model import Frame, Scan, Sequence
from albot1.errors import ConfigError
from albot1.methods import registry as methods
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.registry import MethodRegistry, MethodSpec, parse_overrides, resolve_config
from albot1.runs.errors import RunError, UnknownMethodError
from albot1.runs.execute import run_method

ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 9)


def _sequence(n: int = 6) -> Sequence:
    frames = [
        Frame(
            i,
            Scan(np.full(9, 2.0), ANGLES, float(i), 30.0),
            np.array([0.5 * i, 0.0, 0.0]),
            np.array([0.5 * i, 0.0, 0.0]),
        )
        for i in range(n)
    ]
    return Sequence.from_frames("toy", frames)


class FakeConfig(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    mode: str = "ok"
    gain: float = 1.0


class FakeMapper:
    """Misbehaves on request, to exercise the runner's checks."""

    name: ClassVar[str] = "fake"
    config_model: ClassVar[type[BaseModel]] = FakeConfig
    presets: ClassVar[dict[str, dict[str, Any]]] = {"default": {}, "double": {"gain": 2.0}}

    def __init__(self, config: FakeConfig, *, seed: int = 0) -> None:
        self.config = config
        self.n = 0
        self.warmed = False

    def warm_up(self, announce: Any = None) -> None:
        """In mode ``warm``: a start-up that must happen before the first scan and stay out of its time."""
        if self.config.mode == "warm":
            time.sleep(0.2)
            self.warmed = True
            if announce is not None:
                announce("fake: warmed up")

    def process(self, frame: Frame) -> None:
        if self.config.mode == "warm" and not self.warmed:
            raise RuntimeError("process before warm_up")
        if self.config.mode == "raise" and frame.index == 3:
            raise ZeroDivisionError("boom")
        if self.config.mode == "child" and frame.index == 0:  # an external program's CPU time (as MRPT's)
            burn = "import time\nt = time.process_time()\nwhile time.process_time() - t < 0.3: pass"
            subprocess.run([sys.executable, "-c", burn], check=True)
        self.n += 1

    def finish(self) -> MapperOutput:
        n = self.n - 1 if self.config.mode == "short" else self.n
        poses = np.zeros((n, 3)) * self.config.gain
        if self.config.mode == "nan":
            poses[2, 0] = np.nan
        counters = {"views": self.n} if self.config.mode == "nocount" else {"views": self.n, "updates": 1}
        return MapperOutput(poses=poses, map=MapData(points=np.zeros((1, 2))), counters=counters)


FAKE = "fake"


@pytest.fixture
def fake_method() -> MethodRegistry:
    """The process's registry plus the fake method (a new registry: the process's stays as it was)."""
    return methods.method_registry().with_methods(MethodSpec(FAKE, f"{__name__}:FakeMapper"))


def test_config_precedence(fake_method: MethodRegistry, monkeypatch: pytest.MonkeyPatch) -> None:
    assert resolve_config(FAKE, registry=fake_method).gain == 1.0
    assert resolve_config(FAKE, "double", registry=fake_method).gain == 2.0
    monkeypatch.setenv("ALBOT1_FAKE_GAIN", "3.5")
    assert resolve_config(FAKE, "double", registry=fake_method).gain == 3.5
    assert resolve_config(FAKE, "double", {"gain": "4"}, registry=fake_method).gain == 4.0


def test_config_errors_say_what_was_expected(fake_method: MethodRegistry) -> None:
    with pytest.raises(ConfigError, match="no preset 'nope'; expected one of: default, double"):
        resolve_config(FAKE, "nope", registry=fake_method)
    with pytest.raises(ConfigError, match="gain"):
        resolve_config(FAKE, overrides={"gain": "abc"}, registry=fake_method)
    with pytest.raises(ConfigError, match="unknown|extra|not permitted"):
        resolve_config(FAKE, overrides={"typo": 1}, registry=fake_method)
    with pytest.raises(ConfigError, match="FIELD=VALUE"):
        parse_overrides(["gain"])


def test_unknown_method() -> None:
    with pytest.raises(UnknownMethodError, match="expected one of"):
        methods.get_method("nope")


def test_missing_dependency_is_named() -> None:
    spec = MethodSpec("ghost", "x:Y", requires=("no_such_module_xyz",))
    assert not spec.available()
    with pytest.raises(UnknownMethodError, match="no_such_module_xyz"):
        spec.load_class()


def test_successful_run_records_everything(fake_method: MethodRegistry) -> None:
    result = run_method(FAKE, _sequence(), degradation="gauss:0.1:1", seed=4, registry=fake_method)
    assert result.poses.shape == (6, 3) and result.per_scan_ns.shape == (6,)
    assert result.reference is not None and result.reference.shape == (6, 3)
    assert result.config == {"mode": "ok", "gain": 1.0}
    assert result.versions["code"].startswith("0.1.0+")
    median = result.timing().per_scan_ms_median
    assert median is not None and median >= 0.0
    assert not np.allclose(result.odometry, _sequence().odometry)  # degraded before the method saw it
    cpu_s = result.timing().cpu_s
    assert cpu_s is not None and 0.0 <= cpu_s


def test_the_warm_up_runs_before_the_timed_loop_and_is_recorded_as_startup(fake_method: MethodRegistry) -> None:
    said: list[str] = []
    result = run_method(FAKE, _sequence(), overrides={"mode": "warm"}, announce=said.append, registry=fake_method)
    timing = result.timing()
    assert said == ["fake: warmed up"]
    assert timing.startup_s is not None and timing.startup_s >= 0.2  # it slept 0.2 s
    assert timing.total_s == float(result.per_scan_ns.sum()) / 1e9 + timing.finish_s  # start-up is not scan time
    assert timing.wall_s >= timing.startup_s
    assert run_method(FAKE, _sequence(), registry=fake_method).timing().startup_s is not None


def test_the_cpu_time_counts_the_external_program_the_method_waited_for(fake_method: MethodRegistry) -> None:
    cpu_s = run_method(FAKE, _sequence(), overrides={"mode": "child"}, registry=fake_method).timing().cpu_s
    assert cpu_s is not None and cpu_s >= 0.3  # the child burnt 0.3 s of CPU; this process waited, idle


@pytest.mark.parametrize(
    ("mode", "error", "match"),
    [
        ("raise", BaselineError, r"fake on toy failed at scan 3: ZeroDivisionError: boom"),
        ("short", BaselineError, r"expected 6 poses"),
        ("nan", BaselineError, r"non-finite poses, first at scan 2"),
        ("nocount", RunError, r"counters lack the required key 'updates'"),
    ],
)
def test_contract_violations(fake_method: MethodRegistry, mode: str, error: type[Exception], match: str) -> None:
    with pytest.raises(error, match=match):
        run_method(FAKE, _sequence(), overrides={"mode": mode}, registry=fake_method)
