"""`make bench`'s schedule (``.ci/bench``): each report beside the next grid, the page once its stores are final.

The script runs a fake ``albot1`` (a shell script in a temporary ``BIN``) that appends ``<command> start`` and
``<command> end`` to an event file, prints one line, and exits with the status the test gives it. A fake grid can
be told to wait for an event before it ends: the thesis grid waits for the default report to start, so with the
old schedule (every report after the last grid) it would give up and write ``gave up``, and the order assertions
would fail. No wall-clock assertion: the waits only bound a broken schedule.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import psutil
import pytest

SCRIPT = Path(__file__).resolve().parents[3] / ".ci" / "bench"

FAKE = r"""#!/usr/bin/env bash
# fake albot1: "<words> start", wait for $FAKE_WAIT_<n> when this command is "bench <suite>", "<words> end"
words="$*"
echo "$words start" >> "$EVENTS"
echo "$1 $(nice)" >> "$NICENESS"
name=$(printf '%s' "$1 $2" | tr -c 'A-Za-z0-9\n' '_')
wait_for="FAKE_WAIT_$name"
if [ -n "${!wait_for:-}" ]; then
  IFS='|' read -r -a wanted <<< "${!wait_for}"
  for want in "${wanted[@]}"; do
    for _ in $(seq 400); do grep -qxF "$want" "$EVENTS" && break; sleep 0.05; done
    grep -qxF "$want" "$EVENTS" || echo "gave up waiting for $want" >> "$EVENTS"
  done
fi
if [ "$1" = bench ]; then mkdir -p "results/$2" && touch "results/$2/grid.json"; fi
child_of="FAKE_CHILD_$name"
if [ -n "${!child_of:-}" ]; then  # a worker process, as a report's drawing pool: its pid into the file named
  sleep 300 &
  echo "$!" > "${!child_of}"
  echo "$words child" >> "$EVENTS"
  while :; do sleep 0.05; done
fi
echo "output of $words"
echo "$words end" >> "$EVENTS"
status_of="FAKE_STATUS_$name"
exit "${!status_of:-0}"
"""

PAGE = "results-page results/default --thesis results/thesis --out docs/results.md --readme README.md"


def schedule_env(tmp_path: Path, env: dict[str, str] | None = None) -> dict[str, str]:
    """The fake albot1 in ``tmp_path/bin``, the event file ``tmp_path/events`` and the environment naming them."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(parents=True)
    fake = bin_dir / "albot1"
    fake.write_text(FAKE)
    fake.chmod(0o755)
    events = tmp_path / "events"
    events.touch()
    (tmp_path / "clone").mkdir(exist_ok=True)
    return {
        "PATH": os.environ["PATH"],
        "BIN": str(bin_dir),
        "JOBS": "2",
        "EVENTS": str(events),
        "NICENESS": str(tmp_path / "niceness"),
        **(env or {}),
    }


def run_schedule(
    tmp_path: Path, suites: list[str], env: dict[str, str] | None = None
) -> tuple[int, list[str], list[str]]:
    """Run ``.ci/bench SUITES`` with the fake albot1; (exit status, events in order, output lines)."""
    full_env = schedule_env(tmp_path, env)
    done = subprocess.run(
        [str(SCRIPT), *suites],
        cwd=tmp_path / "clone",
        env=full_env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    return done.returncode, (tmp_path / "events").read_text().splitlines(), done.stdout.splitlines()


def test_each_report_starts_when_its_grid_ends_and_runs_beside_the_next_grid(tmp_path: Path) -> None:
    status, events, output = run_schedule(
        tmp_path,
        ["default", "thesis", "generalisation"],
        {
            "FAKE_WAIT_bench_thesis": "report results/default -j 2 start",
            "FAKE_WAIT_bench_generalisation": f"report results/thesis -j 2 start|{PAGE} start",
        },
    )
    assert status == 0
    assert not [event for event in events if event.startswith("gave up")]
    at = {event: index for index, event in enumerate(events)}
    # the grids one after the other, in the list's order
    assert [event for event in events if event.startswith("bench ")] == [
        f"bench {suite} -j 2 {edge}" for suite in ("default", "thesis", "generalisation") for edge in ("start", "end")
    ]
    # each report after its own grid, before the next grid has ended
    assert at["bench default -j 2 end"] < at["report results/default -j 2 start"] < at["bench thesis -j 2 end"]
    assert at["bench thesis -j 2 end"] < at["report results/thesis -j 2 start"] < at["bench generalisation -j 2 end"]
    assert at["bench generalisation -j 2 end"] < at["report results/generalisation -j 2 start"]
    # the page once the default and thesis stores are final, beside the generalisation grid
    assert at["bench thesis -j 2 end"] < at[f"{PAGE} start"] < at["bench generalisation -j 2 end"]
    assert len(events) == 2 * 7
    # the grids' output as they run; the reports' and the page's held, then shown in the list's order, page last
    held = [line for line in output if not line.startswith("output of bench ")]
    assert held == [
        "output of report results/default -j 2",
        "output of report results/thesis -j 2",
        "output of report results/generalisation -j 2",
        f"output of {PAGE}",
    ]


@pytest.mark.parametrize(
    ("statuses", "expected"),
    [
        ({}, 0),
        ({"FAKE_STATUS_bench_default": "3"}, 3),  # a failing grid: every report is still built
        ({"FAKE_STATUS_bench_default": "3", "FAKE_STATUS_bench_thesis": "4"}, 4),  # the last grid's
        ({"FAKE_STATUS_bench_thesis": "4", "FAKE_STATUS_report_results_default": "5"}, 5),  # reports after grids
        ({"FAKE_STATUS_report_results_default": "5", "FAKE_STATUS_report_results_thesis": "6"}, 6),
        ({"FAKE_STATUS_report_results_thesis": "6", "FAKE_STATUS_results_page_results_default": "7"}, 7),
        ({"FAKE_STATUS_results_page_results_default": "7", "FAKE_STATUS_bench_default": "3"}, 7),
    ],
)
def test_the_exit_status_is_the_last_failure_of_the_grids_then_the_reports_then_the_page(
    tmp_path: Path, statuses: dict[str, str], expected: int
) -> None:
    status, events, _ = run_schedule(tmp_path, ["default", "thesis"], statuses)
    assert status == expected
    assert sorted(event for event in events if event.endswith(" end")) == sorted(
        [
            "bench default -j 2 end",
            "bench thesis -j 2 end",
            "report results/default -j 2 end",
            "report results/thesis -j 2 end",
            f"{PAGE} end",
        ]
    )


def test_the_page_follows_a_lone_default_grid_and_needs_a_default_store(tmp_path: Path) -> None:
    _, events, _ = run_schedule(tmp_path / "a", ["default"])
    assert events[:2] == ["bench default -j 2 start", "bench default -j 2 end"]
    edges = ("start", "end")
    assert sorted(events[2:]) == sorted(
        [f"report results/default -j 2 {e}" for e in edges] + [f"{PAGE} {e}" for e in edges]
    )
    _, events, output = run_schedule(tmp_path / "b", ["generalisation"])  # no results/default: no page
    assert events == [
        "bench generalisation -j 2 start",
        "bench generalisation -j 2 end",
        "report results/generalisation -j 2 start",
        "report results/generalisation -j 2 end",
    ]
    assert output == ["output of bench generalisation -j 2", "output of report results/generalisation -j 2"]


@pytest.mark.parametrize(("setting", "added"), [(None, 10), ("10", 10), ("3", 3), ("0", 0)])
def test_the_reports_and_the_page_run_at_the_report_niceness(tmp_path: Path, setting: str | None, added: int) -> None:
    """Beside a grid a report takes the cores its cells leave idle (REPORT_NICE, default 10; 0: the grids' priority)."""
    status, _, _ = run_schedule(tmp_path, ["default", "thesis"], {} if setting is None else {"REPORT_NICE": setting})
    assert status == 0
    seen = sorted((line.split()[0], int(line.split()[1])) for line in (tmp_path / "niceness").read_text().splitlines())
    grid = os.nice(0)  # the grids run at the niceness of make (here: of the test)
    report = min(grid + added, 19)
    assert seen == [("bench", grid), ("bench", grid), ("report", report), ("report", report), ("results-page", report)]


@pytest.mark.parametrize("setting", ["high", "-5", "1.5", "20", "25"])
def test_a_report_niceness_that_is_not_a_number_is_refused_before_any_grid(tmp_path: Path, setting: str) -> None:
    status, events, _ = run_schedule(tmp_path, ["default"], {"REPORT_NICE": setting})
    assert status == 2
    assert events == []


def test_a_report_waits_while_a_later_grid_of_the_list_writes_a_store_it_reads(tmp_path: Path) -> None:
    """``thesis default``: the thesis report reads results/default, so it starts after the default grid, not before.

    A suite named twice: its report starts after its last grid. (The report must never read a store a grid is
    still writing; the fake grids mark their store written when they end.)
    """
    _, events, output = run_schedule(tmp_path / "a", ["thesis", "default"])
    at = {event: index for index, event in enumerate(events)}
    assert at["bench default -j 2 end"] < at["report results/thesis -j 2 start"]
    assert at["bench default -j 2 end"] < at["report results/default -j 2 start"]
    assert at["bench default -j 2 end"] < at[f"{PAGE} start"]
    assert [line for line in output if not line.startswith("output of bench ")] == [
        "output of report results/thesis -j 2",
        "output of report results/default -j 2",
        f"output of {PAGE}",
    ]
    _, events, _ = run_schedule(tmp_path / "b", ["default", "generalisation", "default"])
    at = {event: index for index, event in enumerate(events)}
    assert events.count("report results/default -j 2 start") == 2  # once per place in the list, after the last grid
    assert min(i for i, e in enumerate(events) if e == "report results/default -j 2 start") > max(
        i for i, e in enumerate(events) if e == "bench default -j 2 end"
    )
    assert at["bench generalisation -j 2 end"] < at["report results/generalisation -j 2 start"]


def test_no_suite_builds_the_page_alone_from_the_stores_there_are(tmp_path: Path) -> None:
    store = tmp_path / "clone" / "results" / "default"
    store.mkdir(parents=True)
    (store / "grid.json").touch()
    status, events, output = run_schedule(tmp_path, [])
    assert status == 0
    assert events == [f"{PAGE} start", f"{PAGE} end"]
    assert output == [f"output of {PAGE}"]


def test_a_term_stops_each_running_report_with_the_processes_it_started(tmp_path: Path) -> None:
    """TERM while the default report draws beside the thesis grid: the report's worker goes with it, exit 143.

    A report draws in a pool of worker processes; killing the report's pid alone left them waiting for work
    forever. The fake report starts a ``sleep`` as its worker and never ends by itself.
    """
    child = tmp_path / "child.pid"
    env = schedule_env(
        tmp_path,
        {
            "FAKE_CHILD_report_results_default": str(child),
            "FAKE_WAIT_bench_thesis": "report results/default -j 2 child",
        },
    )
    script = subprocess.Popen(
        [str(SCRIPT), "default", "thesis"],
        cwd=tmp_path / "clone",
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        for _ in range(600):
            if "report results/default -j 2 child" in (tmp_path / "events").read_text().splitlines():
                break
            time.sleep(0.05)
        worker = int(child.read_text())
        script.send_signal(signal.SIGTERM)
        assert script.wait(timeout=60) == 143
        for _ in range(200):  # the group's kill is sent before the script exits; the worker is reaped by init
            if not _alive(worker):
                break
            time.sleep(0.05)
        assert not _alive(worker)
    finally:
        script.kill()
        if child.exists() and _alive(int(child.read_text())):
            os.kill(int(child.read_text()), signal.SIGKILL)


def _alive(pid: int) -> bool:
    """Whether ``pid`` is a live process (a zombie counts as gone), as the project's other process tests ask psutil."""
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False
