"""Resident memory of a process tree, killing it, and watching it under limits (real child processes)."""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Callable

import psutil

from albot1.processes import MIB, TreeUsage, kill_tree, supervise

#: A child that starts a grandchild, then holds ~64 MiB of touched memory until killed.
PARENT = """
import subprocess, sys, time
child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
print(child.pid, flush=True)
block = bytearray(64 * 2**20)
for i in range(0, len(block), 4096):
    block[i] = 1
print("ready", flush=True)
time.sleep(600)
"""


def _start() -> tuple[subprocess.Popen[str], int]:
    proc = subprocess.Popen([sys.executable, "-c", PARENT], stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    grandchild = int(proc.stdout.readline())
    assert proc.stdout.readline().strip() == "ready"
    return proc, grandchild


def test_tree_memory_counts_the_process_and_its_children_and_kill_tree_stops_both() -> None:
    proc, grandchild = _start()
    try:
        root = psutil.Process(proc.pid)
        memory = TreeUsage(root, refresh_s=0.0)
        total = memory.sample()
        own = root.memory_info().rss
        assert total > own >= 64 * MIB  # the grandchild's resident set is added to the child's
        assert memory.peak_bytes == total
        kill_tree(root)
        assert proc.wait(timeout=10) == -9
        deadline = time.monotonic() + 10
        while psutil.pid_exists(grandchild) and psutil.Process(grandchild).status() != psutil.STATUS_ZOMBIE:
            assert time.monotonic() < deadline, "the grandchild outlived kill_tree"
            time.sleep(0.05)
        assert memory.sample() == 0  # gone: nothing to count
    finally:
        proc.kill()
        proc.wait()
        assert proc.stdout is not None
        proc.stdout.close()  # left open, the collector frees it with a ResourceWarning during another test


def test_kill_tree_of_a_process_that_is_gone_does_nothing() -> None:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    process = psutil.Process(proc.pid)
    proc.wait()
    kill_tree(process)  # the pid may even be reused by now: psutil refuses to signal a stranger


#: Touches ``{mb}`` MiB, then waits to be killed.
HOLD = """
import time
block = bytearray({mb} * 2**20)
for i in range(0, len(block), 4096):
    block[i] = 1
time.sleep(600)
"""


def _ended(proc: subprocess.Popen[bytes]) -> Callable[[float], bool]:
    """``supervise``'s wait: a poll after each pause is precise enough for these tests."""

    def ended(timeout: float) -> bool:
        time.sleep(timeout)
        return proc.poll() is not None

    return ended


def test_supervise_stops_a_tree_over_its_memory_limit_with_the_callers_stop() -> None:
    proc = subprocess.Popen([sys.executable, "-c", HOLD.format(mb=160)])
    stops: list[int] = []

    def stop() -> None:
        stops.append(proc.pid)
        proc.kill()

    try:
        stopped, peak = supervise(
            psutil.Process(proc.pid), _ended(proc), time_s=60, memory_mb=100, poll_s=0.05, stop=stop
        )
        assert stopped == "memory" and stops == [proc.pid]
        assert 100 < peak < 400
        assert proc.wait(timeout=10) == -9
    finally:
        proc.kill()
        proc.wait()


def test_supervise_times_out_and_kills_the_tree_by_default() -> None:
    proc = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    try:
        start = time.monotonic()
        stopped, peak = supervise(psutil.Process(proc.pid), _ended(proc), time_s=0.3, memory_mb=1024, poll_s=0.05)
        assert stopped == "timeout" and 0.3 <= time.monotonic() - start < 5
        assert peak > 1
        assert proc.wait(timeout=10) == -9  # kill_tree
    finally:
        proc.kill()
        proc.wait()


def test_supervise_of_a_process_that_could_not_be_watched_checks_only_the_clock() -> None:
    waits: list[float] = []

    def ended(timeout: float) -> bool:
        waits.append(timeout)
        time.sleep(timeout)
        return len(waits) == 3

    assert supervise(None, ended, time_s=60, memory_mb=0, poll_s=0.01) == (None, 0.0)
    assert waits == [0.01, 0.01, 0.01]
    assert supervise(None, lambda timeout: False, time_s=0.05, memory_mb=0, poll_s=0.01) == ("timeout", 0.0)


#: Starts a helper that burns CPU until killed, and sleeps itself.
BURNING_HELPER = """
import subprocess, sys, time
subprocess.Popen([sys.executable, "-c", "while True: pass"])
time.sleep(600)
"""


def test_supervise_stops_a_tree_over_its_cpu_limit_counting_the_helpers_cpu() -> None:
    """The limit is the tree's CPU seconds, so a sleeping parent whose helper burns CPU is stopped as "cpu"."""
    proc = subprocess.Popen([sys.executable, "-c", BURNING_HELPER])
    root = psutil.Process(proc.pid)
    try:
        start = time.monotonic()
        stopped, _ = supervise(root, _ended(proc), time_s=60, memory_mb=1024, poll_s=0.05, cpu_s=0.8)
        assert stopped == "cpu" and time.monotonic() - start < 30  # not the 60 s wall limit
        assert proc.wait(timeout=10) == -9  # kill_tree
    finally:
        proc.kill()
        proc.wait()


def test_tree_usage_cpu_seconds_counts_the_children_and_never_goes_back() -> None:
    proc = subprocess.Popen([sys.executable, "-c", BURNING_HELPER])
    try:
        usage = TreeUsage(psutil.Process(proc.pid), refresh_s=0.0)
        # Polled, not slept for a fixed time: on a loaded machine the helper gets a fraction of a core (0.18 CPU-s
        # in 0.8 s was seen), and this test is about what is counted, not how fast it grows.
        deadline = time.monotonic() + 30.0
        first = usage.cpu_seconds()
        while first <= 0.3 and time.monotonic() < deadline:
            time.sleep(0.05)
            first = usage.cpu_seconds()
        assert first > 0.3  # the sleeping parent alone has used a few hundredths of a second
        kill_tree(psutil.Process(proc.pid))
        proc.wait(timeout=10)
        assert usage.cpu_seconds() == usage.cpu_s >= first  # the killed tree's time is not taken back
    finally:
        proc.kill()
        proc.wait()


def test_supervise_without_a_cpu_limit_lets_a_busy_tree_run() -> None:
    """``cpu_s`` None (the bench's cells): only the wall clock and memory stop the tree."""
    proc = subprocess.Popen(
        [sys.executable, "-c", "import time\nt = time.monotonic()\nwhile time.monotonic() - t < 1: pass"]
    )
    try:
        stopped, _ = supervise(psutil.Process(proc.pid), _ended(proc), time_s=30, memory_mb=1024, poll_s=0.05)
        assert stopped is None and proc.wait(timeout=10) == 0
    finally:
        proc.kill()
        proc.wait()
