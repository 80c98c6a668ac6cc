"""Ctrl-C or SIGTERM at any moment of an ``albot1`` command: one line, exit 130 or 143, never a traceback.

The console script used to import ``albot1.cli.app`` (Typer and every command module) before anything caught a
stop: a Ctrl-C then printed Python's KeyboardInterrupt traceback and a SIGTERM ended the process without a word;
once the command ran, Typer turned Ctrl-C into exit 130, silently. Each test runs the console script's own target
(``[project.scripts]`` in pyproject.toml) in a fresh interpreter, as a user's shell does.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import pytest

# Process tests beside the bench's Ctrl-C / SIGTERM ones: the end-to-end lane (Makefile, `make test-end-to-end`)
pytestmark = pytest.mark.end_to_end

ROOT = Path(__file__).resolve().parents[2]
#: ``albot1 = "MODULE:FUNCTION"``, the console script's target
TARGET = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]["albot1"]

#: The console script's target run as its script runs it, after a finder that announces on stdout the import of
#: ``argv[1]`` (a module the command imports) and, for ``argv[2] == "stall"``, waits there (until a signal): the
#: test signals the command at a known point of its start without a seam in the code under test.
_DRIVER = """
import sys, time
watched, stall = sys.argv.pop(1), sys.argv.pop(1) == "stall"
class Announce:
    def find_spec(self, name, path=None, target=None):
        if name == watched:
            sys.meta_path.remove(self)
            print("importing", name, flush=True)
            if stall:
                time.sleep(120)
        return None
sys.meta_path.insert(0, Announce())
from {module} import {function}
{function}()
""".format(module=TARGET.split(":")[0], function=TARGET.split(":")[1])

STOPS = {
    "ctrl-c": (lambda pid: os.killpg(pid, signal.SIGINT), 130, "albot1: interrupted"),  # the terminal's group
    "sigterm": (lambda pid: os.kill(pid, signal.SIGTERM), 143, "albot1: terminated (SIGTERM)"),  # `kill PID`
}


def _start(tmp_path: Path, watched: str, stall: bool, *args: str) -> subprocess.Popen[str]:
    """``albot1 ARGS`` in a process group of its own; returns once it announced the import of ``watched``."""
    command = subprocess.Popen(
        [sys.executable, "-c", _DRIVER, watched, "stall" if stall else "go", *args],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    assert command.stdout is not None
    line = command.stdout.readline()
    assert line == f"importing {watched}\n", (line, command.communicate(timeout=120))
    return command


def _ended(command: subprocess.Popen[str]) -> tuple[int, list[str]]:
    """Its exit status and stderr lines (SIGKILL to its group if it has not ended in 120 s)."""
    try:
        _, stderr = command.communicate(timeout=120)
    finally:
        if command.poll() is None:
            os.killpg(command.pid, signal.SIGKILL)
            command.wait()
    return command.returncode, stderr.splitlines()


@pytest.mark.parametrize("stop", sorted(STOPS))
@pytest.mark.parametrize(
    ("watched", "args"),
    [
        ("typer", ["methods"]),  # the console script imports the CLI
        ("numpy", ["run", "odometry", "synthetic-office-loop[:20]", "--out", "runs"]),  # the command imports its layers
    ],
    ids=["importing-the-cli", "importing-the-commands-layers"],
)
def test_a_stop_while_the_command_imports_is_one_line_and_the_signals_status(
    tmp_path: Path, stop: str, watched: str, args: list[str]
) -> None:
    signal_it, status, line = STOPS[stop]
    command = _start(tmp_path, watched, True, *args)
    signal_it(command.pid)
    assert _ended(command) == (status, [line])


@pytest.mark.parametrize("stop", sorted(STOPS))
def test_a_stop_at_any_moment_of_a_command_ends_it_cleanly(tmp_path: Path, stop: str) -> None:
    """Signalled at a few moments after the CLI's import began: whichever point it reached, no traceback.

    Under load the same delay lands earlier in the command: every outcome is accepted but a messy one (the
    command may also have finished first).
    """
    signal_it, status, line = STOPS[stop]
    for delay in (0.0, 0.05, 0.1, 0.2, 0.4, 0.8):
        out = tmp_path / f"after-{delay}"
        out.mkdir()
        command = _start(
            out, "albot1.cli.app", False, "run", "odometry", "synthetic-office-loop[:200]", "--out", "runs"
        )
        time.sleep(delay)
        if command.poll() is None:
            signal_it(command.pid)
        outcome = _ended(command)
        assert outcome in [(status, [line]), (0, [])], (delay, outcome)
