"""`albot1 bench` and `albot1 report` from the command line: dry run, defaults, errors as one line."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import psutil
import pytest
from typer.testing import CliRunner

from albot1.cli.app import app, main
from conftest import PluginInstaller

# `albot1 bench` end to end (its grid in worker processes): the end-to-end lane (Makefile, `make test-end-to-end`)
pytestmark = pytest.mark.end_to_end

#: the console entry point in a fresh interpreter, as a user runs it
ALBOT1 = [sys.executable, "-c", "from albot1.cli.entry import main; main()"]


def test_dry_run_lists_the_planned_cells_without_running_them(tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["bench", "quick", "--dry-run", "--results", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert "suite quick:" in result.output and "synthetic-office-startstop" in result.output
    assert not any(tmp_path.iterdir())


def test_errors_are_one_line_on_stderr_with_exit_1(tmp_path: Path) -> None:
    for args, words in (
        (["report", str(tmp_path)], "no grid.json"),
        (["bench", "no-such-suite"], "no suite named 'no-such-suite'"),
        (["bench", "quick", "--executor", "ray"], "executor 'ray' not understood"),
    ):
        done = subprocess.run(
            [*ALBOT1, *args],
            capture_output=True,
            text=True,
            cwd=tmp_path,
            timeout=120,
        )
        assert done.returncode == 1, done.stderr
        assert done.stderr.startswith("albot1: error: ") and words in done.stderr
        assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1


@pytest.mark.usefixtures("fault_plugin")
def test_bench_exits_1_after_the_whole_grid_when_a_cell_failed(tmp_path: Path) -> None:
    suite = tmp_path / "onefails.toml"
    suite.write_text(
        '[[methods]]\nname = "odometry"\n\n'
        '[[methods]]\nname = "fault"\nset = { mode = "raise", at_scan = 3 }\n\n'
        '[[datasets]]\nname = "synthetic-office-startstop"\n'
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(__file__).parent), *sys.path]))
    done = subprocess.run(
        [*ALBOT1, "bench", str(suite), "-j", "1"] + ["--results", str(tmp_path / "results"), "--no-progress"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
        env=env,
    )
    assert done.returncode == 1, done.stderr
    assert "total" in done.stdout and "albot1 report" in done.stdout  # the summary was printed first
    assert done.stderr.strip().splitlines()[-1] == "1 of 2 cells failed (reasons above and in the report)"
    assert "Traceback" not in done.stderr
    assert (tmp_path / "results" / "onefails" / "grid.json").is_file()


@pytest.mark.usefixtures("fault_plugin")
def test_a_method_failure_the_suite_allows_is_reported_but_the_exit_is_clean(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    fault = ""  # the plugin method `fault` (fault_plugin fixture)
    suite = tmp_path / "allowed.toml"
    suite.write_text(
        '[[methods]]\nname = "odometry"\n\n'
        f'[[methods]]\nname = "fault"\n{fault}set = {{ mode = "raise", at_scan = 3 }}\nallow_failure = true\n\n'
        '[[datasets]]\nname = "synthetic-office-startstop"\n'
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(__file__).parent), *sys.path]))
    args = [*ALBOT1, "bench", str(suite), "-j", "1"]
    args += ["--results", str(tmp_path / "results"), "--no-progress"]
    done = subprocess.run(args, capture_output=True, text=True, cwd=tmp_path, timeout=300, env=env)
    assert done.returncode == 0, done.stderr
    assert "FAILED (allowed by the suite) fault on synthetic-office-startstop" in done.stderr
    assert "injected fault at scan 3" in done.stderr
    assert done.stderr.strip().splitlines()[-1] == (
        "1 of 2 cells failed (reasons above and in the report); 1 of them by methods the suite allows to fail "
        "(allow_failure)"
    )
    # Run again: the same cell would fail the same way, so its record is kept, said so, and not run again.
    failed = next((tmp_path / "results" / "allowed" / "runs").glob("*/FAILED.json"))
    stamp = failed.stat().st_mtime_ns
    again = subprocess.run(args, capture_output=True, text=True, cwd=tmp_path, timeout=300, env=env)
    assert again.returncode == 0, again.stderr
    assert "2 of 2 cells" not in again.stderr  # an allowed failure is not counted as complete
    assert "1 of 2 cells already complete (kept)" in again.stderr
    assert (
        "FAILED (allowed by the suite; kept from an earlier run of this cell, --retry-failed runs it again) "
        "fault on synthetic-office-startstop"
    ) in again.stderr
    assert "injected fault at scan 3" in again.stderr
    assert failed.stat().st_mtime_ns == stamp
    retried = subprocess.run(
        [*args, "--retry-failed"], capture_output=True, text=True, cwd=tmp_path, timeout=300, env=env
    )
    assert retried.returncode == 0, retried.stderr
    assert "FAILED (allowed by the suite) fault on" in retried.stderr and "kept from" not in retried.stderr
    assert failed.stat().st_mtime_ns != stamp
    # A bad config is not the method's failure: allow_failure does not cover it, the suite is refused before any
    # cell runs (one line naming the entry and the key). A refusal before planning: main() in this process
    # (_albot1_in_process says why), with the plugin installed here by fault_plugin.
    suite.write_text(suite.read_text().replace('mode = "raise"', 'mode = "nonsense"'))
    done = _albot1_in_process(tmp_path, monkeypatch, capsys, *args[3:])
    assert done.returncode == 1, done.stderr
    assert done.stderr.strip().splitlines() == [
        f"albot1: error: {suite}: invalid suite: methods.1 ('fault'): invalid config for method 'fault' (preset "
        "'default'): mode: Input should be 'ok', 'slow', 'raise', 'hang', 'memory', 'crash', 'exit', 'os-exit' or "
        "'interrupt', found nonsense "
        "(from set)"
    ]


def _albot1(tmp_path: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*ALBOT1, *args],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )


def _albot1_in_process(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *args: str
) -> subprocess.CompletedProcess[str]:
    """The console entry :func:`main` run in this process (in ``tmp_path``): its exit status and its output.

    For the refusals that happen before any cell starts, where what is checked is the message and the
    exit status of :func:`main`'s error handling, not the process around it (a fresh interpreter per case
    costs ~1.5 s of imports; ``test_errors_are_one_line_on_stderr_with_exit_1`` runs the real process).
    """
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", ["albot1", *args])
    capsys.readouterr()
    with pytest.raises(SystemExit) as exited:
        main()
    out, err = capsys.readouterr()
    code = exited.value.code
    return subprocess.CompletedProcess(["albot1", *args], code if isinstance(code, int) else 1, out, err)


def _one_line(done: subprocess.CompletedProcess[str]) -> str:
    assert done.returncode == 1, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("albot1: error: ") and "Traceback" not in done.stderr
    return lines[0]


def test_suites_that_name_nothing_or_escape_the_results_folder_are_one_line_errors(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    body = '[[methods]]\nname = "odometry"\n[[datasets]]\nname = "{}"\n'
    for name, text, words in (
        ("glob", body.format("synthetic-offce-*"), "dataset entry 0 ('synthetic-offce-*') matches no dataset"),
        (
            "typo",
            body.format("synthetic-offce-loop[:20]"),
            "dataset entry 'synthetic-offce-loop[:20]': 'synthetic-offce-loop' is neither a dataset name",
        ),
        ("escape", 'name = ".."\n' + body.format("synthetic-office-loop[:5]"), "suite name '..': expected a plain"),
        ("huge", "[limits]\ntime_s = 1e12\n" + body.format("synthetic-office-loop[:5]"), "limits.time_s"),
    ):
        suite = tmp_path / f"{name}.toml"
        suite.write_text(text)
        done = _albot1_in_process(
            tmp_path, monkeypatch, capsys, "bench", str(suite), "--results", "results", "--no-progress"
        )
        assert words in _one_line(done)
    assert not (tmp_path / "grid.json").exists() and not (tmp_path / "results").exists()


def test_results_that_cannot_be_a_folder_are_refused_before_planning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "results").write_text("a file")
    line = _one_line(
        _albot1_in_process(tmp_path, monkeypatch, capsys, "bench", "quick", "--results", "results", "--no-progress")
    )
    assert line == (
        "albot1: error: --results results: is a file, not a folder; expected a folder this user can write to "
        "(it is made when missing)"
    )
    line = _one_line(_albot1_in_process(tmp_path, monkeypatch, capsys, "report", "results"))
    assert line == (
        "albot1: error: results: is a file, not a results folder of `albot1 bench`; run `albot1 bench SUITE` first"
    )


def test_a_suite_with_no_cell_to_run_exits_1_and_its_report_says_so(tmp_path: Path) -> None:
    suite = tmp_path / "nodata.toml"
    suite.write_text('[[methods]]\nname = "odometry"\n[[datasets]]\nname = "aces"\n')
    done = subprocess.run(
        [*ALBOT1, "bench", str(suite)] + ["--results", "results", "--no-progress"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
        env={
            **os.environ,
            "ALBOT1_DATA_DIR": str(tmp_path / "no-data"),
            "ALBOT1_CACHE_DIR": str(tmp_path),
        },
    )
    assert done.returncode == 1, done.stderr
    assert "skipped dataset aces: not downloaded" in done.stderr
    assert done.stderr.strip().splitlines()[-1] == (
        "suite nodata: no cell to run (every dataset or method it selects was skipped)"
    )
    report = _albot1(tmp_path, "report", "results/nodata", "--out", "report", "--no-plots")
    assert report.returncode == 0, report.stderr
    text = (tmp_path / "report" / "README.md").read_text()
    assert "Cells: 0 planned" in text and "`aces`: not downloaded" in text


#: A grid of one Albot1 cell: its forkserver compiles Albot1's kernels before it forks it (cold: tens of seconds).
ONE_ALBOT1_CELL = (
    "[limits]\ntime_s = 300\nmemory_mb = 3072\n\n[grid]\ndegradations = []\nseeds = [0]\n\n"
    '[[methods]]\nname = "albot1"\n\n[[datasets]]\nname = "synthetic-office-startstop[:5]"\n'
)


def _compile_helpers(runner: psutil.Process) -> tuple[psutil.Process | None, list[psutil.Process]]:
    """The runner's forkserver and the compile helpers it has forked (none yet: an empty list).

    A helper is a fork of the server (its command line); the server's other children (``git``) are not.
    """
    for child in runner.children():
        try:
            command = child.cmdline()
            if "forkserver" in " ".join(command):
                return child, [c for c in child.children() if c.cmdline() == command]
        except psutil.Error:
            continue
    return None, []


@pytest.mark.slow
def test_ctrl_c_during_the_forkservers_cold_warm_up_prints_only_the_interrupted_line(tmp_path: Path) -> None:
    """Ctrl-C reaches the whole process group: the forkserver and its compile helpers end without a traceback."""
    suite = tmp_path / "one.toml"
    suite.write_text(ONE_ALBOT1_CELL)
    cache = tmp_path / "cache"  # numba's cache lives under the user cache folder (methods/albot1/compiled.py): cold
    cache.mkdir()
    env = dict(os.environ, XDG_CACHE_HOME=str(cache), ALBOT1_COMPILE_PROCESSES="2")
    env.pop("NUMBA_DISABLE_JIT", None)
    runner = subprocess.Popen(
        [*ALBOT1, "bench", str(suite), "-j", "1"] + ["--results", str(tmp_path / "results"), "--no-progress"],
        env=env,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # a process group of its own, as a terminal's foreground job
    )
    try:
        server, helpers = None, []
        deadline = time.monotonic() + 120
        while not helpers and runner.poll() is None and time.monotonic() < deadline:
            server, helpers = _compile_helpers(psutil.Process(runner.pid))
            time.sleep(0.05)
        assert server is not None and helpers, "the forkserver started no compile helper (was numba's cache warm?)"
        os.killpg(runner.pid, signal.SIGINT)  # what Ctrl-C does
        _, stderr = runner.communicate(timeout=120)
    finally:
        if runner.poll() is None:
            os.killpg(runner.pid, signal.SIGKILL)
            runner.wait()
    assert runner.returncode == 130, stderr
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr
    assert stderr.splitlines() == [
        "albot1: interrupted; completed cells are kept, run the same command again to resume"
    ], stderr
    _, alive = psutil.wait_procs([server, *helpers], timeout=30)
    assert alive == [], f"the forkserver or its compile helpers went on after Ctrl-C: {alive}"


#: Starts the cell forkserver as the runner does, says so, and waits; its stderr is the server's.
_STARTS_THE_FORKSERVER = """
import sys
from albot1.bench.limits import start_forkserver
start_forkserver(["odometry"])
print("started", flush=True)
sys.stdin.read()
"""


def _catches_sigint(process: psutil.Process) -> bool:
    """Whether Python has installed its SIGINT handler in ``process`` (``SigCgt``): its start is under way."""
    status = Path(f"/proc/{process.pid}/status").read_text()
    caught = next(line for line in status.splitlines() if line.startswith("SigCgt:"))
    return bool(int(caught.split()[1], 16) & (1 << (signal.SIGINT - 1)))


def _alive(process: psutil.Process) -> bool:
    """Still running: neither gone nor a zombie (the driver, its parent, reaps it only when it exits)."""
    try:
        return process.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads the server's signal mask from /proc")
def test_ctrl_c_while_the_forkserver_starts_ends_it_without_a_traceback() -> None:
    """Before its preload's first line the server raised KeyboardInterrupt from Python's start or its imports.

    Ctrl-C reaches the server with the runner's process group; so does the SIGINT the runner hands on after a
    SIGTERM. The test signals the server once Python's handler is in place (its imports under way).
    """
    driver = subprocess.Popen(
        [sys.executable, "-c", _STARTS_THE_FORKSERVER],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert driver.stdout is not None and driver.stdout.readline() == "started\n", driver.communicate()
        (server,) = [c for c in psutil.Process(driver.pid).children() if "forkserver" in " ".join(c.cmdline())]
        deadline = time.monotonic() + 60
        while not _catches_sigint(server) and time.monotonic() < deadline:
            time.sleep(0.001)
        server.send_signal(signal.SIGINT)
        while _alive(server) and time.monotonic() < deadline + 60:
            time.sleep(0.01)
        assert not _alive(server), "the forkserver went on after Ctrl-C"
        _, stderr = driver.communicate("", timeout=60)
    finally:
        if driver.poll() is None:
            driver.kill()
            driver.wait()
    assert stderr == "", stderr


def test_what_a_plugin_module_prints_on_import_stays_out_of_the_bench_tables(
    install_method_plugin: PluginInstaller, tmp_path: Path
) -> None:
    """The runner's planner and the cell forkserver's preload both import the plugin; neither may print on stdout."""
    site = install_method_plugin({"banner": "banner_plugin_module:Mapper"})
    (site / "banner_plugin_module.py").write_text(
        "print('banner plugin 1.0 loaded')\nfrom albot1.methods.baselines.odometry import OdometryMapper as Mapper\n"
    )
    suite = tmp_path / "banner.toml"
    suite.write_text('[[methods]]\nname = "banner"\n\n[[datasets]]\nname = "synthetic-office-startstop[:3]"\n')
    args = [*ALBOT1, "bench", str(suite), "-j", "1"]
    args += ["--results", str(tmp_path / "results"), "--no-progress"]
    done = subprocess.run(args, capture_output=True, text=True, cwd=tmp_path, timeout=300, env=dict(os.environ))
    assert done.returncode == 0, done.stderr
    assert "banner plugin" not in done.stdout and done.stdout.startswith("method ")
    assert done.stderr.count("banner plugin 1.0 loaded\n") == 2  # the planner's import and the preload's


#: A grid of one cell whose method hangs at its second scan (the test plugin ``fault``).
HANGING_SUITE = (
    "[grid]\ndegradations = []\nseeds = [0]\n\n"
    '[[methods]]\nname = "fault"\nset = { mode = "hang", at_scan = 2 }\n\n'
    '[[datasets]]\nname = "synthetic-office-startstop[:5]"\n'
)


def _start_hanging_grid(tmp_path: Path, *options: str) -> subprocess.Popen[str]:
    """``albot1 bench`` of :data:`HANGING_SUITE` in a process group of its own (a terminal's foreground job)."""
    suite = tmp_path / "hangs.toml"
    suite.write_text(HANGING_SUITE)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(__file__).parent), *sys.path]))
    return subprocess.Popen(
        [*ALBOT1, "bench", str(suite), "-j", "1", *options, "--results", str(tmp_path / "results"), "--no-progress"],
        env=env,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def _hanging_cell_started(runner: subprocess.Popen[str], tmp_path: Path) -> list[psutil.Process]:
    """Wait until the grid's cell hangs in its method; the runner's descendants then."""
    deadline = time.monotonic() + 120
    while not list((tmp_path / "results").glob("hangs/runs/*/cell.log")) and time.monotonic() < deadline:
        assert runner.poll() is None, runner.communicate()
        time.sleep(0.1)
    time.sleep(2.0)  # the cell process has started and hangs in its method
    return psutil.Process(runner.pid).children(recursive=True)


def _stopped(runner: subprocess.Popen[str], stop: Callable[[], None]) -> str:
    """``stop()`` the runner, then its stderr once it has exited (SIGKILL to its group if it has not in 120 s)."""
    try:
        stop()
        _, stderr = runner.communicate(timeout=120)
    finally:
        if runner.poll() is None:
            os.killpg(runner.pid, signal.SIGKILL)
            runner.wait()
    return stderr


@pytest.mark.usefixtures("fault_plugin")
def test_ctrl_c_on_a_local_dask_cluster_prints_only_the_interrupted_line(tmp_path: Path) -> None:
    """The cluster's worker processes get the same Ctrl-C; they used to print two tracebacks each above the line.

    And distributed's warnings about the tasks cancelled as the cluster closed. The workers and their cells end.
    """
    runner = _start_hanging_grid(tmp_path, "--executor", "dask")
    descendants = _hanging_cell_started(runner, tmp_path)
    stderr = _stopped(runner, lambda: os.killpg(runner.pid, signal.SIGINT))  # what Ctrl-C does
    assert runner.returncode == 130, stderr
    assert stderr.splitlines() == [
        "albot1: interrupted; completed cells are kept, run the same command again to resume"
    ], stderr
    _, alive = psutil.wait_procs(descendants, timeout=30)
    assert alive == [], f"the Dask workers or their cells went on after Ctrl-C: {alive}"


@pytest.mark.usefixtures("fault_plugin")
@pytest.mark.parametrize("to_group", [False, True], ids=["runner-alone", "then-its-group"])
def test_sigterm_to_the_runner_alone_stops_the_grid_as_ctrl_c_does_and_says_so(tmp_path: Path, to_group: bool) -> None:
    """``kill PID`` / ``timeout`` / a batch scheduler: one line and exit 143, the cells stopped as by Ctrl-C.

    ``then-its-group``: GNU ``timeout`` (without ``--foreground``) signals the runner and then its whole process
    group, so the forkserver and the cell get SIGTERM themselves as well.

    SIGTERM reaches the runner only (not its process group, as Ctrl-C would): it used to die at once with exit
    143 and no word. As after Ctrl-C, the stopped cell has no result; whether its supervising thread recorded
    why it stopped before the runner exited is a race (no record, "interrupted", "executor" when the forkserver
    went first, or "crash" when the group's SIGTERM killed the cell): each is a cell the next run does again.
    """
    runner = _start_hanging_grid(tmp_path)
    descendants = _hanging_cell_started(runner, tmp_path)

    def sigterm() -> None:
        runner.send_signal(signal.SIGTERM)
        if to_group:
            os.killpg(runner.pid, signal.SIGTERM)

    stderr = _stopped(runner, sigterm)
    assert runner.returncode == 143, stderr
    assert stderr.splitlines() == [
        "albot1: terminated (SIGTERM); completed cells are kept, run the same command again to resume"
    ], stderr
    _, alive = psutil.wait_procs(descendants, timeout=30)
    assert alive == [], f"the forkserver or the cell went on after SIGTERM: {alive}"
    (run_dir,) = (tmp_path / "results").glob("hangs/runs/*")
    assert not (run_dir / "DONE").exists()
    if (run_dir / "FAILED.json").exists():  # only an "exception" record may be kept instead of run again
        assert json.loads((run_dir / "FAILED.json").read_text())["kind"] != "exception"
