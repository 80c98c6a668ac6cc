"""A run's ``peak_mb`` is its own process's peak, not the peak of the process that started it.

Linux carries ``ru_maxrss`` across ``exec``: a program started by a 400 MB process reports at least 400 MB. So a
bench cell run as ``python -m albot1.bench.cell_main`` (the launcher inside a Dask worker) or ``albot1 run``
started by a large process recorded its parent's memory as its method's peak.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from albot1.processes import high_water_mb
from albot1.runs.execute import peak_rss_mb

#: The parent's resident padding (MiB): far above what the child itself reaches (about 60 MiB with its imports).
PADDING_MB = 300
PARENT = f"""
import subprocess, sys
padding = bytearray({PADDING_MB} * 1024 * 1024)
padding[::4096] = b"\\1" * len(padding[::4096])  # resident, page by page
sys.exit(subprocess.run([sys.executable, "-c", sys.argv[1]]).returncode)
"""
CHILD = "from albot1.runs.execute import peak_rss_mb; print(peak_rss_mb())"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the inherited ru_maxrss is Linux's")
def test_a_run_started_by_a_large_process_does_not_report_that_process_s_peak() -> None:
    root = Path(__file__).resolve().parents[3]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")]))}
    out = subprocess.run(
        [sys.executable, "-c", PARENT, CHILD], env=env, capture_output=True, text=True, check=True, timeout=120
    )
    peak = float(out.stdout.strip())
    assert 0 < peak < PADDING_MB / 2, f"the child reported {peak:.0f} MiB: its parent's {PADDING_MB} MiB padding"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc is Linux's")
def test_the_peak_is_this_process_s_high_water_mark() -> None:
    own = high_water_mb()
    assert own is not None and abs(peak_rss_mb() - own) < 1.0
    assert high_water_mb(2**22 + 12345) is None  # no such process
