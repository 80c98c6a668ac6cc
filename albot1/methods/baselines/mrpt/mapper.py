"""MRPT's ``icp-slam`` and ``rbpf-slam`` applications behind the mapper protocol.

The applications are batch programs: they read a whole rawlog and write
their results to a folder. The mapper therefore only *keeps* each frame in
:meth:`process` (the per-scan time the runner measures is that bookkeeping)
and does the work in :meth:`finish`: write the rawlog, render the INI file
from its template, run the application as a subprocess with a wall-clock
and a resident-memory limit, and read its output back. Where the time goes
is recorded in the counters: ``rawlog_write_s``, ``mrpt_wall_s`` (the
subprocess, start to exit), ``mrpt_cpu_s``, ``mrpt_total_s`` (MRPT's own
timing of its mapping loop) and ``mrpt_peak_rss_mb``; the runner's
``finish_s`` holds all of it.

Each run gets a fresh temporary folder (the applications delete everything
in their output folder first), removed afterwards. The INI file and MRPT's
own outputs (its per-step timing log, its path, the grid image) are kept as
the run folder's ``mrpt-*`` files (``MapperOutput.files``); MRPT's version
and timing statistics go into ``extras.mrpt``. MRPT's version is also the
run's ``versions.mrpt`` (``MapperOutput.versions``), part of its key: the
planner reads it once per plan from the application's banner
(:meth:`_MrptMapper.program_versions`), so a store made with another MRPT is
run again, not reused.

Success is checked, never assumed from the exit status: one pose per scan,
finite, and a path whose length is within ``[min_path_ratio,
max_path_ratio]`` of the odometry's. A failure is a :class:`BaselineError`
with the reason (timeout, memory limit, MRPT's exception message, a short or
frozen path).

Stamps: a scan whose stamp icp-slam cannot use (not finite, tick 0, not
strictly after the stamp written for the previous scan: several corrected logs
have one stamp for every scan) is written 1 us after that stamp instead
(``albot1.data.loaders.rawlog.stamps``); how many, and the first, are
``extras.mrpt.rawlog_replaced_stamps`` and
``rawlog_first_replaced_stamp``.

Frames: the runner gives the laser's trajectory (the mounting offset applied
once for every method, :func:`albot1.data.transforms.sensor_frame`), so the
rawlog's sensor pose is the origin. rbpf-slam's poses are relative to the
first scan (its filter starts at the origin); icp-slam's are re-expressed
relative to its first pose, with its map, so both start at the origin like
the other baselines.
"""

from __future__ import annotations

import functools
import math
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel

from albot1.config.presets import TomlPresets
from albot1.contract import MapData, MapperOutput
from albot1.data.errors import DataError
from albot1.data.loaders.rawlog.serialize import GaussianMotionModel
from albot1.data.loaders.rawlog.writer import RawlogLayout, write_frames
from albot1.data.model import Frame
from albot1.errors import InstallError
from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.mrpt import outputs
from albot1.methods.baselines.mrpt.config import WALL_BACKSTOP_FACTOR, MrptIcpConfig, MrptRbpfConfig, MrptRunConfig
from albot1.methods.baselines.mrpt.process import ProcessOutcome, run_limited
from albot1.methods.baselines.mrpt.templates import render

#: The Debian package that provides the applications (``make mrpt`` installs it).
APT_PACKAGE = "mrpt-apps"
#: The odometry must move at least this far before the path-length check applies (m).
MIN_CHECKED_PATH_M = 1.0

RAWLOG_NAME = "input.rawlog"
#: The INI file the application ran with, kept in the run folder (with MRPT's own output files, ``mrpt-*``).
CONFIG_FILE = "mrpt-config.ini"
INI_NAME = "config.ini"
OUTPUT_DIR = "out"


def find_app(app: str) -> str | None:
    """Absolute path of an MRPT application on ``PATH`` (None when absent)."""
    return shutil.which(app)


def _stats_ms(values: FloatArray) -> dict[str, float | int] | None:
    if not len(values):
        return None
    return {
        "median_ms": float(np.median(values)),
        "mean_ms": float(np.mean(values)),
        "p95_ms": float(np.percentile(values, 95)),
        "max_ms": float(np.max(values)),
        "sum_s": float(np.sum(values) / 1000.0),
        "n": int(len(values)),
    }


def _keep(out_dir: Path, names: dict[str, str]) -> dict[str, Any]:
    """MRPT's own output files for the run folder: run-folder name -> the file's bytes."""
    return {name: (out_dir / source).read_bytes() for name, source in names.items()}


def _mrpt_version(stdout_text: str) -> str | None:
    """MRPT's version from the banner an application prints first (``MRPT C++ Library: MRPT 2.5.8 - ...``)."""
    for line in stdout_text.splitlines()[:20]:
        marker = "MRPT C++ Library: MRPT "
        if marker in line:
            return line.split(marker, 1)[1].split()[0]
    return None


#: The name of MRPT's version in a run's ``versions`` (``result.json``) and key.
VERSION_NAME = "mrpt"
#: How long the applications may take to print their banner and their usage when asked for their version (s).
BANNER_TIMEOUT_S = 30.0


def installed_version(app: str) -> str | None:
    """MRPT's version as ``app`` reports it when started now (None: not on PATH, or no banner).

    Why started: the version a run records is the banner of the library the application loads, and only the
    application knows which that is (a build in ``/usr/local`` before the Debian package on ``PATH``). Asked with
    no arguments, it prints its banner and its usage and exits (about 0.6 s), so the answer is kept for as long
    as the executable is the same file (:func:`_banner_version`): once per plan, not once per cell.
    """
    executable = find_app(app)
    if executable is None:
        return None
    try:
        stat = os.stat(executable)
    except OSError:
        return None
    return _banner_version(executable, stat.st_ino, stat.st_size, stat.st_mtime_ns)


@functools.lru_cache(maxsize=8)
def _banner_version(executable: str, inode: int, size: int, mtime_ns: int) -> str | None:
    """The banner's version of ``executable`` (inode, size and time name the file: a reinstall reads it again)."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    try:
        done = subprocess.run(
            [executable],
            capture_output=True,
            text=True,
            errors="replace",
            timeout=BANNER_TIMEOUT_S,
            env=env,
            stdin=subprocess.DEVNULL,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return _mrpt_version(done.stdout)


#: A program that never ran: the loader's status (a library missing), "not executable" (MRPT's own failures: 255).
LOADER_EXIT_STATUSES = frozenset({126, 127})


def _broken_install(message: str, cause: BaseException | None = None) -> BaselineError:
    """The method's error for a program this machine cannot run, caused by an ``InstallError``: a bench cell
    records it as an ``executor`` failure, which ``allow_failure`` (for MRPT's own failures) does not allow."""
    install = InstallError(message)
    install.__cause__ = cause
    error = BaselineError(message)
    error.__cause__ = install
    return error


class _MrptMapper:
    """Shared bookkeeping of the two applications (see the module doc)."""

    name: ClassVar[str]
    app: ClassVar[str]
    layout: ClassVar[RawlogLayout]
    config_model: ClassVar[type[BaseModel]]
    presets = TomlPresets()

    def __init__(self, config: MrptRunConfig, *, seed: int = 0) -> None:
        self.config = config
        self.seed = seed
        self._frames: list[Frame] = []

    @classmethod
    def program_versions(cls) -> dict[str, str | None]:
        """MRPT's version before a run (``Mapper.program_versions``): the planner keys the run's cells with it."""
        return {VERSION_NAME: installed_version(cls.app)}

    # -- per scan --------------------------------------------------------------------------------------------

    def process(self, frame: Frame) -> None:
        """Keep the frame; the application runs on all of them in :meth:`finish`."""
        odometry = np.asarray(frame.odometry, dtype=float)
        if odometry.shape != (3,) or not np.isfinite(odometry).all():
            raise BaselineError(
                f"{self.name}: scan {frame.index}: odometry {odometry.tolist()} is not a finite (x, y, theta); "
                f"expected finite odometry at every scan"
            )
        self._frames.append(frame)

    # -- end of run ------------------------------------------------------------------------------------------

    def _motion_model(self) -> GaussianMotionModel | None:
        return None

    def _run_values(self) -> dict[str, Any]:
        return {}

    def finish(self) -> MapperOutput:
        """Write the rawlog and INI, run the application, read and check its output (module doc)."""
        scans = len(self._frames)
        if scans == 0:
            raise BaselineError(f"{self.name}: no scans were given; {self.app} needs at least one")
        executable = find_app(self.app)
        if executable is None:
            raise _broken_install(
                f"{self.name}: MRPT's {self.app} is not on PATH; install the Debian package {APT_PACKAGE} (`make mrpt`)"
            )
        odometry = np.asarray([f.odometry for f in self._frames], dtype=float)
        with tempfile.TemporaryDirectory(prefix=f"albot1-{self.name}-") as tmp:
            work = Path(tmp)
            start = time.perf_counter()
            try:
                with (work / RAWLOG_NAME).open("wb") as out:
                    rawlog = write_frames(
                        self._frames,
                        out,
                        layout=self.layout,
                        # The runner gives the laser's trajectory (albot1.data.transforms.sensor_frame): the
                        # scans are centred on it, so the rawlog's sensor pose is the origin.
                        sensor_offset=(0.0, 0.0, 0.0),
                        motion_model=self._motion_model(),
                        # icp-slam ignores the odometry of a scan not stamped strictly after the previous one
                        # (albot1.data.loaders.rawlog.stamps); rbpf-slam reads no stamps. Usable stamps are kept.
                        fill_stamps=True,
                    )
            except DataError as exc:
                raise BaselineError(f"{self.name}: cannot write the rawlog: {exc}") from None
            rawlog_s = time.perf_counter() - start
            ini = render(self.app, self.config, rawlog_file=RAWLOG_NAME, output_dir=OUTPUT_DIR, **self._run_values())
            (work / INI_NAME).write_text(ini, encoding="ascii")
            env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
            # One thread: MRPT's OpenMP loops draw from one global random generator, so more
            # threads would make a seeded run irreproducible; the cost is measured single-threaded.
            env["OMP_NUM_THREADS"] = "1"
            try:
                outcome = run_limited(
                    [executable, INI_NAME, RAWLOG_NAME],
                    cwd=work,
                    timeout_s=self.config.wall_limit_s,  # the backstop for a hang; the limit is cpu_limit_s
                    cpu_limit_s=self.config.cpu_limit_s,
                    memory_limit_mb=self.config.memory_limit_mb,
                    stdout_path=work / "stdout.txt",
                    stderr_path=work / "stderr.txt",
                    env=env,
                )
            except OSError as exc:  # gone since found, not executable, not a program (a full disk: the store's)
                if exc.filename != executable:
                    raise
                raise _broken_install(f"{self.name}: {self.app} cannot be started: {exc}", exc)  # noqa: B904
            stdout_text = (work / "stdout.txt").read_text(encoding="utf-8", errors="replace")
            stderr_text = (work / "stderr.txt").read_text(encoding="utf-8", errors="replace")
            out_dir = work / OUTPUT_DIR
            self._check_outcome(outcome, out_dir, stdout_text, stderr_text, scans)
            poses, points, counters, extras, files = self._read(out_dir, odometry)

        self._check_path(poses, odometry)
        version = _mrpt_version(stdout_text)
        mrpt_block = {
            "app": self.app,
            "executable": executable,
            "version": version,
            "rawlog_layout": self.layout,
            "rawlog_bytes": rawlog.bytes_written,
            "rawlog_invalid_beams": rawlog.invalid_beams,
            # Scans whose own stamp MRPT could not use (albot1.data.loaders.rawlog.stamps), and the first one.
            "rawlog_replaced_stamps": rawlog.replaced_stamps,
            "rawlog_first_replaced_stamp": rawlog.first_replaced_stamp,
            "seed": self.seed,
            "threads": 1,
            # The limits it ran under: cpu_limit_s is in the config; the wall backstop is derived from it.
            "wall_backstop_s": self.config.wall_limit_s,
            **extras,
        }
        files = {CONFIG_FILE: ini, **files}
        mrpt_block["files"] = sorted(files)
        all_counters: dict[str, int | float] = {
            "views": scans,
            **counters,
            "map_points": int(len(points)),
            "rawlog_write_s": rawlog_s,
            "mrpt_wall_s": outcome.wall_s,
            "mrpt_cpu_s": outcome.user_s + outcome.system_s,
        }
        if outcome.peak_rss_mb is not None:  # unknown only for a program gone before its first reading
            all_counters["mrpt_peak_rss_mb"] = outcome.peak_rss_mb
        total = outputs.total_time_s(stdout_text)
        if total is not None:
            all_counters["mrpt_total_s"] = total
        return MapperOutput(
            poses=poses,
            map=MapData(points=points),
            counters=all_counters,
            extras={"mrpt": mrpt_block},
            files=files,
            versions={VERSION_NAME: version},  # what ran, from this run's banner; the key was planned with the same
        )

    def _check_outcome(
        self, outcome: ProcessOutcome, out_dir: Path, stdout_text: str, stderr_text: str, scans: int
    ) -> None:
        """A BaselineError saying why the application did not finish (limits, crash, exit status)."""
        progress = self._progress(out_dir, scans)
        if outcome.stopped == "cpu":
            raise BaselineError(
                f"{self.name}: {self.app} stopped by its CPU limit (cpu_limit_s = {self.config.cpu_limit_s:g}) after "
                f"{outcome.cpu_s:.1f} CPU-s, {outcome.wall_s:.1f} s wall, {progress}"
            )
        if outcome.stopped == "timeout":
            raise BaselineError(
                f"{self.name}: {self.app} stopped by its wall-clock backstop ({WALL_BACKSTOP_FACTOR:g} x cpu_limit_s "
                f"= {self.config.wall_limit_s:g} s) after {outcome.wall_s:.1f} s wall, {outcome.cpu_s:.1f} CPU-s "
                f"(hung?), {progress}"
            )
        if outcome.stopped == "memory":
            raise BaselineError(
                f"{self.name}: {self.app} stopped by its memory limit (memory_limit_mb = "
                f"{self.config.memory_limit_mb:g}; resident {outcome.peak_rss_mb or 0:.0f} MB) after "
                f"{outcome.wall_s:.1f} s, {progress}"
            )
        if outcome.returncode != 0:
            if outcome.returncode is not None and outcome.returncode < 0:
                how = f"was killed by signal {-outcome.returncode}"
            else:
                how = f"exited with status {outcome.returncode}"
            reason = outputs.last_error_line(stderr_text + "\n" + stdout_text)
            if outcome.returncode in LOADER_EXIT_STATUSES:
                raise _broken_install(f"{self.name}: {self.app} {how}: it could not start (broken install?): {reason}")
            raise BaselineError(f"{self.name}: {self.app} {how}, {progress}: {reason}")

    def _progress(self, out_dir: Path, scans: int) -> str:
        """How far the application got, from its step log (written as it goes, possibly buffered)."""
        path = out_dir / "log_estimated_path.txt"
        try:
            with path.open("rb") as handle:
                lines = sum(1 for line in handle if line.strip() and not line.startswith(b"%"))
        except OSError:
            return f"before logging any of {scans} scans"
        done = lines // 2 if self.layout == "observations" else lines
        return f"about {done} of {scans} scans logged"

    def _check_path(self, poses: FloatArray, odometry: FloatArray) -> None:
        """The path must be finite and neither frozen nor wildly longer than the odometry's."""
        if poses.shape != odometry.shape:
            raise BaselineError(f"{self.name}: {len(poses)} poses for {len(odometry)} scans; expected one per scan")
        bad = np.flatnonzero(~np.isfinite(poses).all(axis=1))
        if len(bad):
            raise BaselineError(f"{self.name}: {len(bad)} non-finite poses from {self.app}, first at scan {bad[0]}")
        self._check_steps(poses, odometry)
        odometry_m = se2.path_length(odometry)
        if odometry_m < MIN_CHECKED_PATH_M:
            return
        estimate_m = se2.path_length(poses)
        ratio = estimate_m / odometry_m
        if ratio < self.config.min_path_ratio:
            raise BaselineError(
                f"{self.name}: the estimated path is {estimate_m:.2f} m long for {odometry_m:.2f} m of odometry "
                f"(ratio {ratio:.3f} < min_path_ratio {self.config.min_path_ratio:g}): {self.app} did not track "
                f"the robot"
            )
        if ratio > self.config.max_path_ratio:
            raise BaselineError(
                f"{self.name}: the estimated path is {estimate_m:.2f} m long for {odometry_m:.2f} m of odometry "
                f"(ratio {ratio:.3f} > max_path_ratio {self.config.max_path_ratio:g}): {self.app} diverged"
            )

    def _check_steps(self, poses: FloatArray, odometry: FloatArray) -> None:
        """No scan may jump away from the odometry's prediction by more than the configured bounds."""
        if len(poses) < 2:
            return
        predicted = se2.compose(poses[:-1], se2.between(odometry[:-1], odometry[1:]))
        correction = se2.between(predicted, poses[1:])
        shift = np.hypot(correction[:, 0], correction[:, 1])
        turn = np.degrees(np.abs(correction[:, 2]))
        bad = np.flatnonzero((shift > self.config.max_step_correction_m) | (turn > self.config.max_step_correction_deg))
        if len(bad):
            k = int(bad[0])
            raise BaselineError(
                f"{self.name}: {self.app} diverged at scan {k + 1}: the estimate jumped {shift[k]:.2f} m and "
                f"{turn[k]:.1f} deg away from the odometry's prediction in one scan (limits max_step_correction_m = "
                f"{self.config.max_step_correction_m:g}, max_step_correction_deg = "
                f"{self.config.max_step_correction_deg:g}; {len(bad)} such scan(s))"
            )

    def _read(
        self, out_dir: Path, odometry: FloatArray
    ) -> tuple[FloatArray, FloatArray, dict[str, int | float], dict[str, Any], dict[str, Any]]:
        raise NotImplementedError


class MrptIcpMapper(_MrptMapper):
    """MRPT ``icp-slam``: each scan matched by ICP against a growing point map (no loop closing)."""

    name: ClassVar[str] = "mrpt-icp"
    app: ClassVar[str] = "icp-slam"
    layout: ClassVar[RawlogLayout] = "observations"
    config_model: ClassVar[type[BaseModel]] = MrptIcpConfig

    def __init__(self, config: MrptIcpConfig, *, seed: int = 0) -> None:
        # icp-slam draws no random numbers; ``seed`` is accepted for the protocol.
        super().__init__(config, seed=seed)

    def _read(
        self, out_dir: Path, odometry: FloatArray
    ) -> tuple[FloatArray, FloatArray, dict[str, int | float], dict[str, Any], dict[str, Any]]:
        scans = len(odometry)
        raw = outputs.icp_poses(out_dir, scans)
        origin_inverse = se2.inverse(raw[0])
        poses = se2.compose(origin_inverse, raw)
        points = se2.transform_points(origin_inverse, outputs.icp_point_map(out_dir))
        times, map_sizes = outputs.icp_steps(out_dir, 2 * scans)
        counters: dict[str, int | float] = {"updates": int(map_sizes[-1]) if len(map_sizes) else 0}
        extras = {"step_times": _stats_ms(times), "scan_step_times": _stats_ms(times[1::2])}
        files = _keep(
            out_dir, {"mrpt-log_times.txt": "log_times.txt", "mrpt-estimated_path.txt": "log_estimated_path.txt"}
        )
        return poses, points, counters, extras, files


class MrptRbpfMapper(_MrptMapper):
    """MRPT ``rbpf-slam``: a Rao-Blackwellized particle filter of occupancy-grid maps (GMapping family)."""

    name: ClassVar[str] = "mrpt-rbpf"
    app: ClassVar[str] = "rbpf-slam"
    layout: ClassVar[RawlogLayout] = "actions"
    config_model: ClassVar[type[BaseModel]] = MrptRbpfConfig

    def __init__(self, config: MrptRbpfConfig, *, seed: int = 0) -> None:
        if seed < 0:
            raise BaselineError(f"{self.name}: seed {seed}; expected >= 0 (a negative RANDOM_SEED means 'random')")
        super().__init__(config, seed=seed)
        self.rbpf: MrptRbpfConfig = config

    def _run_values(self) -> dict[str, Any]:
        return {"seed": self.seed}

    def _motion_model(self) -> GaussianMotionModel:
        c = self.rbpf
        return GaussianMotionModel(
            a1=c.motion_a1,
            a2=c.motion_a2,
            a3=c.motion_a3,
            a4=c.motion_a4,
            min_std_xy=c.motion_min_std_xy_m,
            min_std_phi=math.radians(c.motion_min_std_theta_deg),
        )

    def _read(
        self, out_dir: Path, odometry: FloatArray
    ) -> tuple[FloatArray, FloatArray, dict[str, int | float], dict[str, Any], dict[str, Any]]:
        scans = len(odometry)
        steps = outputs.rbpf_steps(out_dir, scans)
        updates = int(np.count_nonzero(steps.updated))
        best = outputs.rbpf_best_path(out_dir, updates)
        # Between updates MRPT predicts with the odometry increments the rawlog carried: the frames' odometry.
        poses = outputs.poses_between_updates(best, steps.updated, odometry)
        mean = outputs.rbpf_mean_poses(out_dir, scans)
        grid = outputs.grid_map(out_dir, self.rbpf.grid_resolution_m)
        points = grid.occupied_points(self.rbpf.map_occupied_probability)
        ess = outputs.read_rows(out_dir / "log_ParticlesStats.txt", 3, "particle statistics")
        gap = np.linalg.norm(poses[:, :2] - mean[:, :2], axis=1)
        counters: dict[str, int | float] = {"updates": updates, "particles": self.rbpf.particles}
        extras = {
            "step_times": _stats_ms(steps.time_ms),
            "update_step_times": _stats_ms(steps.time_ms[steps.updated]),
            "grid": grid.summary(),
            "ess_min": float(ess[:, 2].min()) if len(ess) else None,
            "ess_mean": float(ess[:, 2].mean()) if len(ess) else None,
            # How far the reported path (the most likely particle's, smoothed by later updates) lies from
            # the online particle mean MRPT logged at each scan.
            "best_vs_mean_m": {"median": float(np.median(gap)), "max": float(np.max(gap))},
        }
        files = _keep(
            out_dir,
            {
                "mrpt-log_times.txt": "log_times.txt",
                "mrpt-most_likely_path.txt": "most_likely_path.txt",
                "mrpt-grid.png": outputs.GRID_IMAGE,
                "mrpt-grid-limits.txt": outputs.GRID_LIMITS,
            },
        )
        return poses, points, counters, extras, files
