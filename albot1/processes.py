"""Resident memory and CPU time of a process tree, and stopping one: what a memory and a CPU limit need.

Why resident memory and not an address-space limit (``RLIMIT_AS``): the
compiled libraries the methods use reserve large virtual ranges long before
they use the memory (numba's LLVM, OpenMP/TBB thread pools, gtsam), so an
address-space cap makes them fail to load (``libllvmlite.so`` not found,
``failed to map segment``) and the failure reads as an import error instead
of "memory limit exceeded". A supervisor instead polls the resident set of
the process and of every process it started (psutil) and kills them when
the sum passes the limit; the overshoot is bounded by what the tree
allocates between two polls.

The bench's cell processes (``albot1.bench.limits``) and the external
programs of wrapped baselines (``albot1.methods.baselines.mrpt.process``)
are both watched by :func:`supervise`; they differ only in how they wait for
their child and how they stop it.

Why a CPU limit beside the wall clock: a wall-clock limit measures the
machine's load as much as the program. A single-threaded program that needs
61 s idle took 303 s of wall on a machine at load 10-16 (two cores), so
which runs passed a wall limit depended on what else ran. The CPU time the
tree has used (polled, :meth:`TreeUsage.cpu_seconds`) is the program's own
cost; the wall clock is then kept only as a backstop for a program that
hangs without burning CPU.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Literal

import psutil

MIB = 1024.0 * 1024.0

#: The limit that made :func:`supervise` stop a process tree: ``timeout`` the wall clock, ``cpu`` the
#: tree's CPU time, ``memory`` its resident memory.
Stop = Literal["timeout", "memory", "cpu"]


class TreeUsage:
    """Samples the resident memory (bytes) and the CPU time (s) of ``process`` and its descendants.

    Listing the descendants walks every process of the machine (~10 ms with a
    hundred processes), so the list is refreshed every ``refresh_s`` seconds
    while the resident sizes of the known members (microseconds each) are read
    at every sample. A helper process started between two refreshes is counted
    from the next refresh on.
    """

    def __init__(self, process: psutil.Process, *, refresh_s: float = 1.0) -> None:
        self._root = process
        self._refresh_s = refresh_s
        self._members: list[psutil.Process] = [process]
        self._listed_at = -float("inf")
        self.peak_bytes = 0
        self.cpu_s = 0.0

    def _refresh(self) -> None:
        now = time.monotonic()
        if now - self._listed_at < self._refresh_s:
            return
        self._listed_at = now
        try:
            self._members = [self._root, *self._root.children(recursive=True)]
        except psutil.Error:  # the root is gone: nothing to count
            self._members = []

    def sample(self) -> int:
        """Resident bytes of the tree now (0 once it is gone); ``peak_bytes`` keeps the largest sample."""
        self._refresh()
        total = 0
        for member in self._members:
            try:
                total += member.memory_info().rss
            except psutil.Error:  # exited since the last listing
                continue
        self.peak_bytes = max(self.peak_bytes, total)
        return total

    def cpu_seconds(self) -> float:
        """User and system CPU seconds the tree has used so far (``cpu_s`` keeps the largest reading).

        Each member counts its own time and that of its children it has
        reaped (``children_user``, ``children_system``): a helper that ended
        and was waited for by a member stays counted through that member. A
        member that exits between two listings drops out of the sum until its
        parent reaps it, so the reading is kept monotonic: CPU time spent is
        never taken back.
        """
        self._refresh()
        total = 0.0
        for member in self._members:
            try:
                times = member.cpu_times()
            except psutil.Error:  # exited since the last listing
                continue
            total += times.user + times.system + times.children_user + times.children_system
        self.cpu_s = max(self.cpu_s, total)
        return self.cpu_s


def high_water_mb(pid: int | str = "self") -> float | None:
    """The resident high-water mark (MiB) of the program now running as ``pid`` (``VmHWM``); None where unknown.

    Why not ``ru_maxrss``: the kernel carries the high-water mark of a process's image before ``exec`` into the
    program it becomes, and that image is a fork of its parent, so a program started by a 400 MB process
    reports at least 400 MB (``/bin/sleep`` 432 MB; ``python -m albot1.bench.cell_main`` under a Dask worker, or
    ``albot1 run`` started by a large test process, the parent's peak as its own). ``VmHWM`` belongs to the
    program's own address space. None off Linux (no ``/proc``) or once the process is gone.
    """
    try:
        with open(f"/proc/{pid}/status", "rb") as status:
            for line in status:
                if line.startswith(b"VmHWM:"):
                    return int(line.split()[1]) * 1024 / MIB  # kB
    except (OSError, ValueError, IndexError):
        pass
    return None


def kill_tree(process: psutil.Process) -> None:
    """SIGKILL ``process``'s descendants, then ``process`` itself (its parent reaps it); gone ones are skipped.

    The descendants go first so that none is left running as an orphan of a
    dead parent (an external program started by a method, say). ``process``
    is a ``psutil.Process``, not a pid: psutil refuses to signal a pid that a
    new process has taken since, so a late kill never hits a stranger.
    """
    try:
        members = [*process.children(recursive=True), process]
    except psutil.Error:
        members = [process]
    for member in members:
        try:
            member.kill()
        except psutil.Error:
            continue


def supervise(
    process: psutil.Process | None,
    ended: Callable[[float], bool],
    *,
    time_s: float,
    memory_mb: float,
    poll_s: float,
    stop: Callable[[], None] | None = None,
    cpu_s: float | None = None,
) -> tuple[Stop | None, float]:
    """Wait for ``process`` to end, stopping its tree when it passes ``time_s`` seconds or ``memory_mb`` resident.

    ``time_s`` is wall-clock time; ``cpu_s`` (None: none) the user plus
    system CPU time of the whole tree (polled, so it may be passed by up to
    ``poll_s`` per busy core). A caller holding a program to its CPU time
    passes a generous ``time_s`` as the backstop for a hang that burns none.

    ``ended(timeout)`` waits up to ``timeout`` s (at most ``poll_s``) and says
    whether the process has exited; the caller owns waiting because only it
    knows how to reap its child (``Popen.wait``, ``os.wait4`` for the child's
    own resource usage, a multiprocessing ``join``). Between two waits the
    tree's resident memory (and, with ``cpu_s``, its CPU time) is sampled (:class:`TreeUsage`). ``stop`` kills
    the tree when a limit is passed (default :func:`kill_tree`; a child in a
    session of its own may rather be stopped by its process group). With
    ``process`` None (it exited before it could be watched) only the clock is
    checked and nothing is killed. Returns the limit that stopped it (None:
    it ended by itself) and the peak resident memory seen, MiB.
    """
    deadline = time.monotonic() + time_s
    limit = memory_mb * MIB
    usage = TreeUsage(process) if process is not None else None
    stopped: Stop | None = None
    while True:
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            stopped = "timeout"
        elif ended(min(poll_s, remaining)):
            break
        elif usage is not None and usage.sample() > limit:
            stopped = "memory"
        elif usage is not None and cpu_s is not None and usage.cpu_seconds() > cpu_s:
            stopped = "cpu"
        if stopped is not None:
            if process is not None and stop is not None:
                stop()
            elif process is not None:
                kill_tree(process)
            break
    peak = usage.peak_bytes / MIB if usage is not None else 0.0
    return stopped, peak
