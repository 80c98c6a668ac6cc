"""A real ``dask.distributed`` cluster for the fault tests: a scheduler and worker processes on 127.0.0.1.

Started as ``dask scheduler`` / ``dask worker`` subprocesses (not a
``LocalCluster`` inside the test process) so that a test can SIGKILL one
worker, or the scheduler, exactly as a user's cluster would lose them.
Ports are ephemeral (port 0, read back from the scheduler file), so tests
may run in parallel (pytest-xdist). Workers run without a nanny (a killed
worker stays dead) and with one thread each, as the machine is shared.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

#: Where the fault mapper of the grid tests lives; the workers' cell processes import it from here
#: (its plugin entry point is on ``sys.path`` once conftest's ``fault_plugin`` has run).
TEST_DIR = Path(__file__).parent


def cluster_env(**dask_config: str) -> dict[str, str]:
    """The environment of the cluster's processes: this interpreter's path plus the test folder."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(TEST_DIR), *(p for p in sys.path if p)]))
    env.update({f"DASK_{name}": value for name, value in dask_config.items()})
    return env


class Cluster:
    """A scheduler and its workers as child processes of the test; :meth:`close` stops them all."""

    def __init__(self, folder: Path, env: dict[str, str]) -> None:
        self.folder = folder
        self.env = env
        self.scheduler_file = folder / "scheduler.json"
        self.scheduler: subprocess.Popen[bytes] | None = None
        self.workers: list[subprocess.Popen[bytes]] = []
        self.address = ""

    def start_scheduler(self, port: int = 0) -> str:
        """Start the scheduler on 127.0.0.1 (``port`` 0: an ephemeral one); returns its address."""
        self.scheduler_file.unlink(missing_ok=True)
        command = [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1"]
        command += ["--port", str(port), "--no-dashboard", "--scheduler-file", str(self.scheduler_file)]
        self.scheduler = self._start(command, "scheduler")
        deadline = time.monotonic() + 60
        while not self.scheduler_file.is_file() or not self.scheduler_file.read_text().strip():
            assert time.monotonic() < deadline and self.scheduler.poll() is None, "the scheduler did not start"
            time.sleep(0.1)
        self.address = str(json.loads(self.scheduler_file.read_text())["address"])
        assert self.address.startswith("tcp://127.0.0.1:"), self.address
        return self.address

    def start_worker(
        self, *, wrap: list[str] | None = None, env: dict[str, str] | None = None, death_timeout_s: int = 30
    ) -> subprocess.Popen[bytes]:
        """One single-threaded worker without a nanny; ``wrap`` prefixes the command (e.g. a mount namespace).

        ``death_timeout_s``: how long the worker tries to reach a scheduler it lost (or never reached) before it stops.
        """
        command = [sys.executable, "-m", "distributed.cli.dask_worker", self.address, "--nthreads", "1"]
        command += ["--no-nanny", "--host", "127.0.0.1", "--no-dashboard", "--death-timeout", str(death_timeout_s)]
        worker = self._start([*(wrap or []), *command], f"worker{len(self.workers)}", env)
        self.workers.append(worker)
        return worker

    def wait_for_workers(self, count: int) -> None:
        """Block until ``count`` workers are registered with the scheduler."""
        from distributed import Client

        with Client(self.address, timeout="30s") as client:
            client.wait_for_workers(count, timeout=120)

    def _start(self, command: list[str], name: str, env: dict[str, str] | None = None) -> subprocess.Popen[bytes]:
        with (self.folder / f"{name}.log").open("ab") as log:
            # cwd: `python -m` puts it first on sys.path, and the checkout's own albot1 must not win over PYTHONPATH.
            return subprocess.Popen(
                command, env=env or self.env, cwd=self.folder, stdin=subprocess.DEVNULL, stdout=log, stderr=log
            )

    def kill_scheduler(self) -> None:
        assert self.scheduler is not None
        self.scheduler.send_signal(signal.SIGKILL)
        self.scheduler.wait(timeout=30)

    def close(self) -> None:
        for process in [*self.workers, self.scheduler]:
            if process is not None and process.poll() is None:
                process.kill()
                process.wait(timeout=30)
