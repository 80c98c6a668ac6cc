"""The MRPT wrapper around a stand-in application (fake_mrpt_app.py): outputs read back,
frames, counters, and every failure turned into a BaselineError with its reason."""

from __future__ import annotations

import math
import os
import stat
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

import fake_mrpt_app
import numpy as np
import pytest

from albot1.contract import MapperOutput
from albot1.data.model import Frame, Scan
from albot1.errors import ConfigError, InstallError
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.mrpt import MrptIcpMapper, MrptRbpfMapper
from albot1.methods.baselines.mrpt.config import MrptIcpConfig, MrptRbpfConfig
from albot1.methods.errors import UnknownMethodError
from albot1.methods.registry import method_registry, resolve_config

ANGLES = np.radians(np.linspace(-90.0, 90.0, 19))
SCANS = 6


def _frames(n: int = SCANS) -> list[Frame]:
    return [
        Frame(i, Scan(np.full(len(ANGLES), 2.0), ANGLES, 100.0 + i, 30.0), np.array([0.5 * i, 0.0, 0.0]))
        for i in range(n)
    ]


@pytest.fixture()
def fake_apps(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A PATH holding only fake icp-slam and rbpf-slam programs."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for app in ("icp-slam", "rbpf-slam"):
        script = bin_dir / app
        script.write_text(f'#!/bin/sh\nexec "{sys.executable}" "{fake_mrpt_app.__file__}" {app} "$@"\n')
        script.chmod(script.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setenv("PATH", str(bin_dir))
    monkeypatch.setenv("FAKE_MRPT_SCANS", str(SCANS))
    monkeypatch.delenv("FAKE_MRPT_MODE", raising=False)
    return bin_dir


def _icp(**overrides: Any) -> MrptIcpMapper:
    config = resolve_config("mrpt-icp", "default", overrides)
    assert isinstance(config, MrptIcpConfig)
    return MrptIcpMapper(config)


def _rbpf(seed: int = 0, **overrides: Any) -> MrptRbpfMapper:
    config = resolve_config("mrpt-rbpf", "default", {"grid_resolution_m": 0.5, **overrides})
    assert isinstance(config, MrptRbpfConfig)
    return MrptRbpfMapper(config, seed=seed)


def _run(mapper: MrptIcpMapper | MrptRbpfMapper, n: int = SCANS) -> MapperOutput:
    for frame in _frames(n):
        mapper.process(frame)
    return mapper.finish()


def test_icp_poses_start_at_the_origin_with_the_map_in_the_same_frame(fake_apps: Path) -> None:
    out = _run(_icp())
    np.testing.assert_allclose(out.poses[:, 0], 0.5 * np.arange(SCANS), atol=1e-5)
    np.testing.assert_allclose(out.poses[:, 1:], 0.0, atol=1e-5)
    assert out.map.points is not None
    np.testing.assert_allclose(out.map.points, [[0.0, -1.0], [1.0, 1.0]], atol=1e-5)
    c = out.counters
    assert (c["views"], c["updates"], c["map_points"]) == (SCANS, 3, 2)
    assert c["mrpt_total_s"] == 1.25 and c["mrpt_wall_s"] > 0
    assert "mrpt_peak_rss_mb" not in c or c["mrpt_peak_rss_mb"] > 0  # the fake app may exit before a reading
    mrpt = out.extras["mrpt"]
    assert mrpt["version"] == "2.5.8" and mrpt["rawlog_layout"] == "observations"
    assert mrpt["scan_step_times"]["median_ms"] == 1.5 and mrpt["step_times"]["n"] == 2 * SCANS
    ini = out.files["mrpt-config.ini"]
    assert "SHOW_PROGRESS_3D_REAL_TIME = 0" in ini and "thresholdDist = 0.3" in ini
    assert mrpt["files"] == ["mrpt-config.ini", "mrpt-estimated_path.txt", "mrpt-log_times.txt"]
    assert out.files["mrpt-log_times.txt"].startswith(b"0.500000 1\n")


def test_rbpf_poses_follow_the_best_particle_and_the_odometry_between_updates(fake_apps: Path) -> None:
    out = _run(_rbpf(seed=7))
    np.testing.assert_allclose(out.poses[:, 0], 0.5 * np.arange(SCANS), atol=1e-9)
    np.testing.assert_allclose(out.poses[:, 1], 0.01, atol=1e-9)
    assert out.map.points is not None
    np.testing.assert_allclose(np.sort(out.map.points, axis=0), [[-0.25, -0.75], [1.75, 0.75]], atol=1e-9)
    c = out.counters
    assert (c["updates"], c["particles"], c["map_points"]) == (3, 30, 2)
    mrpt = out.extras["mrpt"]
    ini = out.files["mrpt-config.ini"]
    assert "RANDOM_SEED = 7" in ini and "SHOW_PROGRESS_IN_WINDOW = 0" in ini
    assert "PF_algorithm = 2" in ini and mrpt["rawlog_layout"] == "actions"
    assert out.files["mrpt-grid.png"].startswith(b"\x89PNG")
    assert b"-1.0 2.0 -1.0 1.0" in out.files["mrpt-grid-limits.txt"]
    assert "mrpt-most_likely_path.txt" in mrpt["files"]
    assert mrpt["grid"]["resolution_m"] == 0.5 and mrpt["best_vs_mean_m"]["max"] == pytest.approx(0.01)
    assert mrpt["update_step_times"]["mean_ms"] == 10.0 and mrpt["ess_min"] == 0.5


@pytest.mark.parametrize(
    ("mode", "message"),
    [
        ("short", r"log_estimated_path.txt: 10 steps; expected 12"),
        ("frozen", r"estimated path is 0.00 m long for 2.50 m of odometry .*did not track"),
        ("jump", r"icp-slam diverged at scan 3: the estimate jumped 5\.00 m and 0\.0 deg .*max_step_correction_m = 3"),
        ("crash", r"icp-slam exited with status 255, .*: Message:  Assert condition failed: fake"),
        ("signal", r"icp-slam was killed by signal 11"),
    ],
)
def test_icp_failures_name_their_reason(
    fake_apps: Path, monkeypatch: pytest.MonkeyPatch, mode: str, message: str
) -> None:
    monkeypatch.setenv("FAKE_MRPT_MODE", mode)
    with pytest.raises(BaselineError, match=message):
        _run(_icp())


def _install_failure(error: BaseException) -> bool:
    """Whether an ``InstallError`` is in ``error``'s chain (how a bench cell tells the install's failure)."""
    current: BaseException | None = error
    while current is not None:
        if isinstance(current, InstallError):
            return True
        current = current.__cause__
    return False


def test_a_program_that_cannot_start_is_the_install_s_failure_not_mrpt_s(
    fake_apps: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    script = fake_apps / "icp-slam"
    script.write_text('#!/bin/sh\necho "icp-slam: loading shared libraries: libmrpt-slam.so" >&2\nexit 127\n')
    with pytest.raises(BaselineError, match=r"icp-slam exited with status 127: it could not start .*libmrpt") as caught:
        _run(_icp())
    assert _install_failure(caught.value)
    mapper = _icp()
    script.chmod(0o644)  # found by an earlier lookup, then not executable: Popen's PermissionError
    monkeypatch.setattr("albot1.methods.baselines.mrpt.mapper.find_app", lambda app: str(script))
    with pytest.raises(BaselineError, match=r"icp-slam cannot be started: .*Permission denied") as caught:
        _run(mapper)
    assert _install_failure(caught.value)
    monkeypatch.setenv("FAKE_MRPT_MODE", "crash")  # a program that runs and fails: MRPT's own failure
    script.chmod(0o755)
    script.write_text(f'#!/bin/sh\nexec "{sys.executable}" "{fake_mrpt_app.__file__}" icp-slam "$@"\n')
    with pytest.raises(BaselineError, match="exited with status 255") as caught:
        _run(_icp())
    assert not _install_failure(caught.value)


def test_rbpf_short_log_is_a_failure(fake_apps: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("FAKE_MRPT_MODE", "short")
    with pytest.raises(BaselineError, match=r"log_times.txt: 5 steps; expected 6 .*stopped early"):
        _run(_rbpf())


@pytest.mark.slow
def test_limits_stop_the_application_and_say_which(fake_apps: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("FAKE_MRPT_MODE", "burn")
    with pytest.raises(
        BaselineError,
        match=r"stopped by its CPU limit \(cpu_limit_s = 0\.5\) after (0\.[5-9]|1\.\d) CPU-s, \d+\.\d s wall",
    ):
        _run(_icp(cpu_limit_s=0.5))
    monkeypatch.setenv("FAKE_MRPT_MODE", "sleep")  # burns no CPU: only the wall-clock backstop (10 x) stops it
    with pytest.raises(
        BaselineError,
        match=r"stopped by its wall-clock backstop \(10 x cpu_limit_s = 3 s\) after 3\.\d s wall, 0\.\d CPU-s "
        r"\(hung\?\)",
    ):
        _run(_icp(cpu_limit_s=0.3))
    monkeypatch.setenv("FAKE_MRPT_MODE", "hog")
    with pytest.raises(BaselineError, match=r"stopped by its memory limit \(memory_limit_mb = 150;"):
        _run(_rbpf(memory_limit_mb=150))


def test_wrong_grid_resolution_is_caught(fake_apps: Path) -> None:
    with pytest.raises(BaselineError, match=r"0\.5 x 0\.5 m cells; expected 0\.05 m"):
        _run(_rbpf(grid_resolution_m=0.05))


def test_bad_input_and_seed_are_refused_before_running(fake_apps: Path) -> None:
    mapper = _icp()
    bad = Frame(2, _frames(1)[0].scan, np.array([0.0, math.inf, 0.0]))
    with pytest.raises(BaselineError, match="scan 2: odometry"):
        mapper.process(bad)
    with pytest.raises(BaselineError, match="no scans"):
        _icp().finish()
    with pytest.raises(BaselineError, match="seed -1"):
        _rbpf(seed=-1)


def test_missing_programs_make_the_methods_unavailable(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PATH", str(tmp_path))
    for name, program in (("mrpt-icp", "icp-slam"), ("mrpt-rbpf", "rbpf-slam")):
        spec = method_registry().get(name)
        assert not spec.available()
        assert spec.unavailable_reason() == f"needs the program(s) {program}, not found on PATH"
        assert "apt-get install mrpt-apps" in spec.install_command()
        with pytest.raises(UnknownMethodError, match=rf"'{name}' is unavailable: .*{program}.*apt-get install"):
            spec.load_class()
    # Built directly (not through the registry), it still says what is missing when it has to run.
    mapper = MrptIcpMapper(MrptIcpConfig.model_validate(MrptIcpMapper.presets["default"]))
    mapper.process(_frames(1)[0])
    with pytest.raises(BaselineError, match="icp-slam is not on PATH; install the Debian package mrpt-apps"):
        mapper.finish()


def test_runs_are_repeatable(fake_apps: Path) -> None:
    a, b = _run(_rbpf(seed=3)), _run(_rbpf(seed=3))
    np.testing.assert_array_equal(a.poses, b.poses)
    assert os.environ["FAKE_MRPT_SCANS"] == str(SCANS)


def test_a_run_reports_the_mrpt_version_the_planner_read_before_it(fake_apps: Path) -> None:
    """The planner keys an MRPT cell with the banner the application prints when started with no arguments
    (``program_versions``); the run reports its own run's banner (``MapperOutput.versions``, recorded in
    ``result.json`` and digested by the key its folder is stored under): one MRPT, one version, so the stored
    run is found again; another MRPT installed (another executable file) is read again, not taken from before."""
    assert MrptIcpMapper.program_versions() == MrptRbpfMapper.program_versions() == {"mrpt": "2.5.8"}
    assert _run(_icp()).versions == _run(_rbpf()).versions == {"mrpt": "2.5.8"}
    script = fake_apps / "icp-slam"
    script.write_text(script.read_text().replace("exec ", "export FAKE_MRPT_VERSION=2.6.0\nexec ", 1))
    assert MrptIcpMapper.program_versions() == _run(_icp()).versions == {"mrpt": "2.6.0"}


def test_unusable_scan_stamps_are_filled_and_counted(fake_apps: Path) -> None:
    usable = _run(_icp()).extras["mrpt"]
    assert (usable["rawlog_replaced_stamps"], usable["rawlog_first_replaced_stamp"]) == (0, None)
    for mapper in (_icp(), _rbpf()):
        for frame in _frames():
            mapper.process(Frame(frame.index, replace(frame.scan, timestamp=5.0), frame.odometry))
        mrpt = mapper.finish().extras["mrpt"]
        assert mrpt["rawlog_replaced_stamps"] == SCANS - 1
        assert mrpt["rawlog_first_replaced_stamp"] == "scan 1: timestamp 5.0 s is not after the previous scan's"


@pytest.mark.parametrize("method", ["mrpt-icp", "mrpt-rbpf"])
def test_the_old_wall_clock_field_is_refused_with_what_replaced_it(method: str) -> None:
    """``timeout_s`` (wall seconds) became ``cpu_limit_s`` (CPU seconds): taking the old value silently would
    change its meaning, so a suite or --set that still uses it fails with one line naming the new field."""
    with pytest.raises(ConfigError) as info:
        resolve_config(method, "default", {"timeout_s": 300})
    message = str(info.value)
    assert "\n" not in message and "timeout_s (wall-clock seconds) was replaced by cpu_limit_s (CPU seconds" in message
    assert resolve_config(method, "default", {"cpu_limit_s": 300}).model_dump()["cpu_limit_s"] == 300.0
