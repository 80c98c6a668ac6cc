"""`make test-fast` runs "without the public logs" (``-m "not integration"``): the tests that read them are marked.

Before, ``tests/unit/data/test_open_ref.py::test_corrected_log_with_clean_odometry`` (a public log through the
``data_file`` fixture) and the generalisation suite's plan on the held-out logs were unmarked unit tests, so the
fast lane read public logs whenever ``ALBOT1_DATA_DIR`` was set.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ON_PUBLIC_LOGS = [
    "tests/unit/data/test_open_ref.py::test_corrected_log_with_clean_odometry",
    "tests/unit/bench/test_bench_generalisation_suite.py::test_the_plan_has_one_cell_per_method_dataset_perturbation_and_seed",
]


def _collected(*arguments: str) -> str:
    """The node ids ``pytest --collect-only -q ARGUMENTS`` lists, as its text."""
    return subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", *arguments],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout


@pytest.mark.slow
def test_the_fast_lane_s_selection_leaves_out_the_tests_on_public_logs() -> None:
    files = sorted({nodeid.split("::")[0] for nodeid in ON_PUBLIC_LOGS})
    collected = _collected(*files)
    fast = _collected("-m", "not slow and not integration", *files)
    for nodeid in ON_PUBLIC_LOGS:
        assert nodeid in collected, nodeid  # the test exists ...
        assert nodeid not in fast, nodeid  # ... and the fast lane does not run it
    assert "tests/unit/data/test_open_ref.py::test_unknown_name_points_to_the_listing" in fast  # the others stay
