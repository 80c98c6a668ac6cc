"""Ctrl-C whose KeyboardInterrupt a finalizer dropped still ends `albot1 bench` as interrupted (exit 130, one line).

Seen once in the full suite under load: Ctrl-C during a cold compile killed the cell forkserver, the runner's
KeyboardInterrupt never surfaced, the cell was recorded as "executor error: EOFError" and the command exited 1.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from albot1.cli.app import main
from albot1.cli.interrupt import Interrupts, noting_interrupts, terminating_as_interrupt

INTERRUPTED = "albot1: interrupted; completed cells are kept, run the same command again to resume"


class _CtrlCInAFinalizer:
    """Gets Ctrl-C while it is being freed: Python raises the KeyboardInterrupt inside ``__del__``, which drops it."""

    def __del__(self) -> None:
        os.kill(os.getpid(), signal.SIGINT)
        sum(range(1000))  # bytecode after the signal: where the KeyboardInterrupt is raised, and dropped


def _run_suite_losing_ctrl_c(*args: Any, observer: Any, **kwargs: Any) -> tuple[None, None, None]:
    _CtrlCInAFinalizer()  # freed at once
    # The cell Ctrl-C killed ends: its forkserver died of the same Ctrl-C. That is the interrupt, not a failure.
    killed = SimpleNamespace(status="failed", allowed=False, kept=False, description="albot1 on w", reason="EOFError")
    observer.finished(killed)
    return None, None, None  # the grid "finished": the command must not go on to print a summary of it


def test_a_ctrl_c_dropped_by_a_finalizer_ends_bench_as_interrupted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import albot1.bench.runner

    monkeypatch.setattr(albot1.bench.runner, "run_suite", _run_suite_losing_ctrl_c)
    assert _bench(tmp_path, monkeypatch, capsys) == (130, "", [INTERRUPTED])
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # put back


def test_a_ctrl_c_dropped_by_a_finalizer_stops_the_grid_at_the_next_cell_not_at_its_end(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The runner never saw the lost KeyboardInterrupt: it went on starting cells (a whole grid, lines hidden)."""
    import albot1.bench.runner

    ended_after: list[int] = []

    def run_suite_going_on(*args: Any, observer: Any, **kwargs: Any) -> tuple[None, None, None]:
        _CtrlCInAFinalizer()
        for cell in range(3):  # the cells the runner goes on to run and see end
            observer.finished(SimpleNamespace(status="done", allowed=False, kept=False, description=f"c{cell}"))
            ended_after.append(cell)
        return None, None, None

    monkeypatch.setattr(albot1.bench.runner, "run_suite", run_suite_going_on)
    assert (*_bench(tmp_path, monkeypatch, capsys), ended_after) == (130, "", [INTERRUPTED], [])


def test_outside_the_command_ctrl_c_and_dropped_exceptions_behave_as_python_says(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with noting_interrupts() as ctrl_c, pytest.raises(KeyboardInterrupt):
        os.kill(os.getpid(), signal.SIGINT)
        sum(range(1000))
    assert ctrl_c.received
    with noting_interrupts() as nothing:
        pass
    assert not nothing.received
    hook = sys.unraisablehook
    with noting_interrupts():
        assert sys.unraisablehook is not hook
    assert sys.unraisablehook is hook and signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_inside_the_console_scripts_handlers_a_command_notes_ctrl_c_and_says_the_only_line() -> None:
    """``albot1 bench`` runs inside the console script's handlers (``albot1.cli.entry``), which it took for a host's.

    Its own record stayed empty and its "lost Ctrl-C" guard was off; the console script must not say a second line.
    """
    script = Interrupts()
    with noting_interrupts(script), terminating_as_interrupt(script):
        command = Interrupts()
        with noting_interrupts(command), terminating_as_interrupt(command), pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
            sum(range(1000))
        assert (command.received, script.received, script.told) == (True, True, False)
        assert command.line("kept") == "albot1: interrupted; kept" and command.status() == 130
        assert script.told  # the command said it: the console script says nothing more
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


def _bench(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> tuple[object, str, list[str]]:
    """``albot1 bench quick`` in ``tmp_path``: its exit code, stdout and stderr lines."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", ["albot1", "bench", "quick", "--results", "results", "--no-progress"])
    capsys.readouterr()
    with pytest.raises(SystemExit) as exited:
        main()
    out, err = capsys.readouterr()
    return exited.value.code, out, err.splitlines()


#: Run in a fresh interpreter: the handler signals every child of its process, and the test process's own children
#: (a bench forkserver of an earlier test) must not get it. argv[1] "ignored": the driver starts with SIGINT ignored,
#: as a script's ``cmd &`` starts a command, and so does its child.
_SIGTERM_DRIVER = """
import os, signal, subprocess, sys
from albot1.cli.interrupt import Interrupts, terminating_as_interrupt
if sys.argv[1] == "ignored":
    signal.signal(signal.SIGINT, signal.SIG_IGN)
child = "import signal, time; signal.signal(signal.SIGTERM, lambda *a: exit(15)); print(flush=True); time.sleep(60)"
kid = subprocess.Popen([sys.executable, "-c", child], stdout=subprocess.PIPE)
kid.stdout.readline()  # its handler is in place
noted = Interrupts()
try:
    with terminating_as_interrupt(noted):
        os.kill(os.getpid(), signal.SIGTERM)
        sum(range(1000))  # where the KeyboardInterrupt is raised
except KeyboardInterrupt:
    print("KeyboardInterrupt", noted.received, noted.terminated)
print(kid.wait(timeout=30))
os.kill(os.getpid(), signal.SIGTERM)  # the same stop's copy (GNU timeout's to the group): ignored
print("still here", flush=True)
if sys.argv[2] == "later":
    import time
    time.sleep(1.2)
    os.kill(os.getpid(), signal.SIGTERM)  # a later one ends the command at once, with its line
    time.sleep(5)
    print("not reached")
"""


@pytest.mark.parametrize(("sigint", "child_exit"), [("default", -signal.SIGINT), ("ignored", 15)])
def test_sigterm_hands_sigint_on_to_children_or_sigterm_where_sigint_is_ignored(sigint: str, child_exit: int) -> None:
    """A command started with SIGINT ignored (a script's ``cmd &``) has children that would wait through SIGINT."""
    done = subprocess.run(
        [sys.executable, "-c", _SIGTERM_DRIVER, sigint, "none"], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    # the child died of SIGINT (-2), or of SIGTERM (its handler's 15) where SIGINT was ignored
    assert done.stdout.splitlines() == ["KeyboardInterrupt True True", str(child_exit), "still here"], done.stderr


def test_a_second_sigterm_at_once_is_the_same_stop_and_a_later_one_ends_the_command_with_its_line() -> None:
    """GNU ``timeout`` signals the command, then its group: the copy used to end the runner with -15, no word."""
    done = subprocess.run(
        [sys.executable, "-c", _SIGTERM_DRIVER, "default", "later"], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 143, done.stderr
    assert done.stdout.splitlines() == ["KeyboardInterrupt True True", str(-signal.SIGINT), "still here"]
    # (above it, the child's own KeyboardInterrupt traceback: it is a plain Python child, not ours)
    assert done.stderr.splitlines()[-1] == "albot1: terminated (SIGTERM)" and done.stderr.count("albot1:") == 1
