"""How an ``albot1`` command ends when Ctrl-C or SIGTERM comes at a given moment after its start.

Each command is started in a process group of its own (a terminal's
foreground job) in a fresh temporary folder, signalled after each delay
(SIGINT to the group, as Ctrl-C; SIGTERM to the process alone, as ``kill
PID``), and its ending printed as ``DELAY:STATUS`` with ``T`` when stderr holds
a traceback, ``/NL`` when stderr is not exactly one line, ``(done)`` when it had
finished before the signal and ``@Ns`` when it took over 5 s to stop. What the
project wants: ``130`` (``143``) with one line, or ``0/0L`` when the work was
done. ``--tree`` runs another checkout (``PYTHONPATH``), e.g. a pristine copy of
main, so that old and new code meet the same machine::

    python benchmarks/stop_signals.py
    python benchmarks/stop_signals.py --tree /tmp/old --entry albot1.cli.app:main --commands bench
    python benchmarks/stop_signals.py --commands bench --delays 0.8,0.9,1.0,1.1,1.2 --signals TERM

Dataset folder: ``ALBOT1_DATA_DIR`` as set (the commands use synthetic worlds only).
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMMANDS = {
    "version": ["--version"],
    "methods": ["methods"],
    "run": ["run", "odometry", "synthetic-office-loop", "--out", "runs"],
    "bench": ["bench", "quick", "--results", "results", "-j", "2", "--no-progress"],
}
DELAYS = "0.05,0.1,0.2,0.4,0.7,1.0,1.5,2.0,2.5,3.0"


def ending(entry: str, args: list[str], signum: signal.Signals, delay: float, env: dict[str, str]) -> str:
    """One run: ``STATUS`` and its marks (module docstring)."""
    module, function = entry.split(":")
    folder = tempfile.mkdtemp(prefix="albot1-stop-")
    try:
        command = subprocess.Popen(
            [sys.executable, "-c", f"from {module} import {function}; {function}()", *args],
            env=env,
            cwd=folder,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        time.sleep(delay)
        sent = command.poll() is None
        started = time.monotonic()
        if sent and signum == signal.SIGINT:
            os.killpg(command.pid, signal.SIGINT)
        elif sent:
            command.send_signal(signum)
        try:
            _, stderr = command.communicate(timeout=120)
        except subprocess.TimeoutExpired:
            os.killpg(command.pid, signal.SIGKILL)
            _, stderr = command.communicate()
        took = time.monotonic() - started
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    lines = [line for line in stderr.splitlines() if line.strip()]
    mark = str(command.returncode)
    mark += "T" if "Traceback" in stderr or "KeyboardInterrupt" in stderr else ""
    mark += f"/{len(lines)}L" if len(lines) != 1 else ""
    mark += "" if sent else "(done)"
    return mark + (f"@{took:.0f}s" if took > 5 else "")


def main() -> None:
    """Every command, signal and delay asked for; one line per command and signal."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--entry", default="albot1.cli.entry:main", help="MODULE:FUNCTION the console script runs")
    parser.add_argument("--tree", type=Path, default=Path(__file__).resolve().parents[1], help="checkout to run")
    parser.add_argument("--commands", default=",".join(COMMANDS), help=f"of {', '.join(COMMANDS)}")
    parser.add_argument("--signals", default="INT,TERM", help="INT, TERM or both")
    parser.add_argument("--delays", default=DELAYS, help="seconds after the start, comma-separated")
    options = parser.parse_args()
    env = dict(os.environ, PYTHONPATH=str(options.tree.resolve()))
    delays = [float(delay) for delay in options.delays.split(",")]
    for name in options.commands.split(","):
        for signame in options.signals.split(","):
            signum = signal.Signals[f"SIG{signame}"]
            row = [f"{delay}:{ending(options.entry, COMMANDS[name], signum, delay, env)}" for delay in delays]
            print(f"{name:8s} SIG{signame:4s} {' '.join(row)}", flush=True)


if __name__ == "__main__":
    main()
