"""Cells started and ended at once in several runner threads keep their own exit status.

Python 3.11's ``Process.start()`` reads the status of every child that has
ended; without :class:`albot1.bench.limits.ForkserverChild`'s lock, a start
in one thread racing a status read in another left one of them with EOF,
and a cell that had completed was recorded as "exited with code 255"
(seen in CI, 1 in 21 cells of the disk-full test; 17 of 600 children in a
two-thread loop of 50-110 ms children).
"""

from __future__ import annotations

import threading
import time

import pytest

from albot1.bench.limits import ForkserverChild

#: Per thread; without the lock, 80 per thread lost 16 to 26 of the 160 statuses in three runs.
CHILDREN = 50


def start_and_reap(thread: int, codes: list[tuple[int, int, int | None]]) -> None:
    for n in range(CHILDREN):
        # time.sleep as the target: the forkserver child needs nothing but the standard library
        child = ForkserverChild(time.sleep, (0.02 + 0.01 * (n % 6),), name=f"sleep-{thread}-{n}")
        while not child.ended(0.05):
            pass
        codes.append((thread, n, child.exit_code()))


@pytest.mark.slow
def test_two_threads_starting_and_reaping_children_read_every_exit_code() -> None:
    codes: list[tuple[int, int, int | None]] = []
    threads = [threading.Thread(target=start_and_reap, args=(t, codes)) for t in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(codes) == 2 * CHILDREN
    assert [c for c in codes if c[2] != 0] == []


def test_a_killed_child_reports_its_signal() -> None:
    child = ForkserverChild(time.sleep, (30,), name="sleep-killed")
    assert not child.ended(0.0)
    child.kill()
    while not child.ended(0.05):
        pass
    assert child.exit_code() == -9
