"""Run an external program with a wall-clock limit and a resident-memory limit.

Why not ``subprocess.run(timeout=...)`` plus ``RLIMIT_AS``: an address-space
limit breaks programs that reserve large virtual ranges (OpenMP/TBB thread
pools, JIT runtimes) long before they use the memory, so the failure would
look like a crash rather than "memory limit exceeded". The parent here
polls the child's *resident* memory (psutil) and kills its whole process
group when either limit is passed, and says which limit stopped it. A
diverging particle filter grows steadily (hundreds of MB per second at
most), so a 0.1 s poll bounds the overshoot to a fraction of the limit.

The child is reaped with ``os.wait4`` so its own peak resident set and CPU
times (``ru_maxrss``, ``ru_utime``, ``ru_stime``) are measured exactly, not
mixed with other children of this process. On Linux the child also asks the
kernel to kill it when this process dies (``PR_SET_PDEATHSIG``): a benchmark
cell killed by its own limit must not leave an unwatched MRPT run behind.
"""

from __future__ import annotations

import ctypes
import os
import signal
import subprocess
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import psutil

StopReason = Literal["timeout", "memory"]

#: How often the child's memory and the clock are checked (s).
POLL_S = 0.1


@dataclass(frozen=True)
class ProcessOutcome:
    """How a limited child process ended and what it cost."""

    returncode: int | None  # None when this module killed it (see ``stopped``)
    stopped: StopReason | None
    wall_s: float
    user_s: float
    system_s: float
    peak_rss_mb: float


#: ``prctl`` option that sends a signal to this process when its parent dies (linux/prctl.h).
_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """In the child before exec: be killed with the parent (Linux; elsewhere a no-op)."""
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)


def _tree_rss(process: psutil.Process) -> int:
    """Resident bytes of a process and its descendants (0 when it is gone)."""
    total = 0
    try:
        total += process.memory_info().rss
        for child in process.children(recursive=True):
            try:
                total += child.memory_info().rss
            except psutil.Error:
                continue
    except psutil.Error:
        return 0
    return total


def run_limited(
    argv: Sequence[str],
    *,
    cwd: Path,
    timeout_s: float,
    memory_limit_mb: float,
    stdout_path: Path,
    stderr_path: Path,
    env: Mapping[str, str] | None = None,
) -> ProcessOutcome:
    """Run ``argv`` in ``cwd`` (stdin closed, output to files) until it exits or passes a limit."""
    limit_bytes = memory_limit_mb * 1024.0 * 1024.0
    with stdout_path.open("wb") as out, stderr_path.open("wb") as err:
        start = time.perf_counter()
        proc = subprocess.Popen(
            list(argv),
            cwd=cwd,
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=err,
            env=dict(env) if env is not None else None,
            start_new_session=True,  # its own process group: a kill reaches every helper it started
            preexec_fn=_die_with_parent,
        )
    watched = psutil.Process(proc.pid)
    stopped: StopReason | None = None
    polled_peak = 0
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid != 0:
            break
        rss = _tree_rss(watched)
        polled_peak = max(polled_peak, rss)
        if stopped is None:
            if rss > limit_bytes:
                stopped = "memory"
            elif time.perf_counter() - start > timeout_s:
                stopped = "timeout"
            if stopped is not None:
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        time.sleep(POLL_S)
    wall_s = time.perf_counter() - start
    code = os.waitstatus_to_exitcode(status)
    proc.returncode = code  # reaped here: keep Popen from waiting on a pid that is gone
    peak = max(polled_peak, usage.ru_maxrss * 1024)  # ru_maxrss is KiB on Linux
    return ProcessOutcome(
        returncode=None if stopped is not None else code,
        stopped=stopped,
        wall_s=wall_s,
        user_s=usage.ru_utime,
        system_s=usage.ru_stime,
        peak_rss_mb=peak / (1024.0 * 1024.0),
    )
