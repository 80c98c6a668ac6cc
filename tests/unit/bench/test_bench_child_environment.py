"""A cell's child gets the ``ALBOT1_*`` environment read while no other cell's thread is changing it.

Each cell's thread sets ``ALBOT1_PRELOAD_METHODS`` and removes it again while it
makes sure the forkserver runs (``limits._preloading``, under ``_START_LOCK``);
a thread copying ``os.environ`` at that moment failed its cell with
``KeyError: 'ALBOT1_PRELOAD_METHODS'`` (seen once in ``.ci/wheel-check``'s
``bench quick``). The copy now waits for the lock.
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Any

from albot1.bench import limits
from albot1.bench.grid import Cell


def _cell() -> Cell:
    return Cell(
        suite="t",
        dataset="synthetic-office-loop",
        dataset_label="synthetic-office-loop",
        method="odometry",
        method_label="odometry",
        preset="default",
        degradation="none",
        seed=0,
        key="k",
        code_version="c",
        time_s=60,
        memory_mb=100,
    )


def test_the_child_s_environment_is_copied_only_between_two_preload_changes(tmp_path: Path) -> None:
    got: list[dict[str, Any]] = []
    reader = threading.Thread(target=lambda: got.append(limits.child_args(_cell(), tmp_path, tmp_path / "log")))
    with limits._START_LOCK, limits._preloading(["albot1"]):
        reader.start()
        reader.join(0.3)
        assert reader.is_alive()  # waits while the preload list is in the environment
    reader.join(10)
    assert len(got) == 1
    assert limits.METHODS_ENV not in got[0]["env"]
