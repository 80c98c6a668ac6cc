"""Run an external program under a CPU-time limit, a wall-clock backstop and a resident-memory limit.

Why CPU time: a wall-clock limit held MRPT to the machine's load as much as
to its own cost (mit-csail: 61 s idle, 303 s of wall at load 10-16 on two
cores, stopped at about 1,762 of 1,988 scans), so which runs failed depended
on what else ran. ``cpu_limit_s`` holds the program's process tree to the
user plus system CPU seconds it has used (polled from ``/proc`` through
psutil, :meth:`albot1.processes.TreeUsage.cpu_seconds`); ``timeout_s``
stays a wall-clock limit, which a caller holding the program to its CPU time
sets generously, as the backstop for a hang that burns no CPU.

Why not ``subprocess.run(timeout=...)`` plus ``RLIMIT_AS``: an address-space
limit breaks programs that reserve large virtual ranges (OpenMP/TBB thread
pools, JIT runtimes) long before they use the memory, so the failure would
look like a crash rather than "memory limit exceeded". The child's tree is
watched as the bench watches its cells (:func:`albot1.processes.supervise`:
resident memory polled, the limit that stopped it named); here the whole
process group is killed, as the child runs in a session of its own. A
diverging particle filter grows steadily (hundreds of MB per second at
most), so a 0.1 s poll bounds the overshoot to a fraction of the limit.

The child is reaped with ``os.wait4`` so its CPU times (``ru_utime``,
``ru_stime``) are measured exactly, not mixed with other children of this
process. Its peak resident set is *not* ``ru_maxrss``: the kernel carries
the high-water mark of the image the child had before ``exec`` into it, and
that image is a fork of this Python process (``preexec_fn`` rules out
vfork), so ``/bin/sleep`` started from a 400 MB process reported 432 MB.
The peak is the program's own ``VmHWM`` (``/proc/PID/status``, monotonic,
read at every poll: only a rise in the last poll interval before it exits
can be missed) or the polled resident sum of its process tree, whichever is
larger. On Linux the child also asks the
kernel to kill it when this process dies (``PR_SET_PDEATHSIG``): a benchmark
cell killed by its own limit must not leave an unwatched MRPT run behind.
"""

from __future__ import annotations

import ctypes
import os
import resource
import signal
import subprocess
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import psutil

from albot1.processes import Stop, high_water_mb, supervise

#: How often the child's memory and the clock are checked (s).
POLL_S = 0.1


@dataclass(frozen=True)
class ProcessOutcome:
    """How a limited child process ended and what it cost."""

    returncode: int | None  # None when this module killed it (see ``stopped``)
    stopped: Stop | None  # "cpu": cpu_limit_s, "timeout": the wall clock (timeout_s), "memory"
    wall_s: float
    user_s: float
    system_s: float
    peak_rss_mb: float | None  # None: the program exited before its memory could be read once

    @property
    def cpu_s(self) -> float:
        """The program's CPU seconds (user + system, exact: ``wait4``), what ``cpu_limit_s`` holds it to."""
        return self.user_s + self.system_s


#: ``prctl`` option that sends a signal to this process when its parent dies (linux/prctl.h).
_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """In the child before exec: be killed with the parent (Linux; elsewhere a no-op)."""
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)


def _reap(pid: int) -> tuple[int, resource.struct_rusage] | None:
    """The exit status and resource usage of the child ``pid`` once it has exited (None while it runs)."""
    done, status, usage = os.wait4(pid, os.WNOHANG)
    return (status, usage) if done != 0 else None


def run_limited(
    argv: Sequence[str],
    *,
    cwd: Path,
    timeout_s: float,
    memory_limit_mb: float,
    stdout_path: Path,
    stderr_path: Path,
    env: Mapping[str, str] | None = None,
    cpu_limit_s: float | None = None,
) -> ProcessOutcome:
    """Run ``argv`` in ``cwd`` (stdin closed, output to files) until it exits or passes a limit.

    ``timeout_s``: wall-clock seconds; ``cpu_limit_s``: CPU seconds of the process tree (None: no CPU limit).
    """
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
    reaped: tuple[int, resource.struct_rusage] | None = None
    high_water = 0.0

    def ended(timeout: float) -> bool:
        """Reap the child if it has exited, else after ``timeout`` s (``wait4`` has no timeout of its own)."""
        nonlocal reaped, high_water
        high_water = max(high_water, high_water_mb(proc.pid) or 0.0)  # before the reap: /proc/PID goes with it
        reaped = _reap(proc.pid)
        if reaped is None:
            time.sleep(timeout)
            reaped = _reap(proc.pid)
        return reaped is not None

    def kill_group() -> None:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass

    # Not reaped before ``ended`` says so, so the pid is still this child's: psutil.Process cannot fail here.
    stopped, polled_peak_mb = supervise(
        psutil.Process(proc.pid),
        ended,
        time_s=timeout_s,
        memory_mb=memory_limit_mb,
        poll_s=POLL_S,
        stop=kill_group,
        cpu_s=cpu_limit_s,
    )
    if reaped is None:  # killed for a limit: reap it now
        _, status, usage = os.wait4(proc.pid, 0)
    else:
        status, usage = reaped
    wall_s = time.perf_counter() - start
    code = os.waitstatus_to_exitcode(status)
    proc.returncode = code  # reaped here: keep Popen from waiting on a pid that is gone
    peak_mb = max(polled_peak_mb, high_water) or None  # not ru_maxrss: see the module docstring
    return ProcessOutcome(
        returncode=None if stopped is not None else code,
        stopped=stopped,
        wall_s=wall_s,
        user_s=usage.ru_utime,
        system_s=usage.ru_stime,
        peak_rss_mb=peak_mb,
    )
