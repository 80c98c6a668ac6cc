"""A child process under a wall-clock and a resident-memory limit."""

from __future__ import annotations

import sys
from pathlib import Path

from albot1.methods.baselines.mrpt.process import ProcessOutcome, run_limited


def _run(tmp_path: Path, code: str, timeout_s: float = 20.0, memory_limit_mb: float = 2000.0) -> ProcessOutcome:
    return run_limited(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        timeout_s=timeout_s,
        memory_limit_mb=memory_limit_mb,
        stdout_path=tmp_path / "out.txt",
        stderr_path=tmp_path / "err.txt",
    )


def test_exit_status_and_output_files(tmp_path: Path) -> None:
    outcome = _run(tmp_path, "import sys; print('hello'); sys.exit(3)")
    assert outcome.returncode == 3 and outcome.stopped is None
    assert (tmp_path / "out.txt").read_text() == "hello\n"
    assert outcome.peak_rss_mb > 1 and outcome.user_s >= 0 and outcome.wall_s > 0


def test_stdin_is_closed(tmp_path: Path) -> None:
    outcome = _run(tmp_path, "import sys; sys.exit(0 if sys.stdin.read() == '' else 1)")
    assert outcome.returncode == 0


def test_timeout_kills_the_whole_process_group(tmp_path: Path) -> None:
    child = "[sys.executable, '-c', 'import time; time.sleep(60)']"
    code = f"import subprocess, sys, time; subprocess.Popen({child}); time.sleep(60)"
    outcome = _run(tmp_path, code, timeout_s=0.5)
    assert outcome.stopped == "timeout" and outcome.returncode is None
    assert outcome.wall_s < 10


def test_resident_memory_limit(tmp_path: Path) -> None:
    code = "import time\nb = []\nwhile True:\n    b.append(bytearray(10 * 2**20)); time.sleep(0.005)"
    outcome = _run(tmp_path, code, memory_limit_mb=120.0)
    assert outcome.stopped == "memory" and outcome.returncode is None
    assert outcome.peak_rss_mb > 120.0
