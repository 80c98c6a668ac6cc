"""Resident memory of a process tree and killing it (real child processes, a few MB each)."""

from __future__ import annotations

import subprocess
import sys
import time

import psutil

from albot1.processes import MIB, TreeMemory, kill_tree

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
        memory = TreeMemory(root, refresh_s=0.0)
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


def test_kill_tree_of_a_process_that_is_gone_does_nothing() -> None:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    process = psutil.Process(proc.pid)
    proc.wait()
    kill_tree(process)  # the pid may even be reused by now: psutil refuses to signal a stranger
