"""Where cells run: a local pool or Dask distributed, both as a ``concurrent.futures.Executor``.

One code path: the runner only calls ``submit`` and ``concurrent.futures.as_completed``.

``local`` (default)
    a thread pool of ``jobs`` threads; each thread supervises one cell
    process at a time (:mod:`albot1.bench.limits`), so ``-j N`` means N cell
    processes at once. Threads, not a process pool, because the supervisor
    must survive its cell being killed (a crashed ``ProcessPoolExecutor``
    worker breaks the whole pool).
``dask``
    a ``distributed.LocalCluster`` of ``jobs`` single-threaded workers,
    through ``Client.get_executor()``. Its worker processes are made
    non-daemonic so they may fork cell processes themselves.
``dask://HOST:PORT`` (or ``tcp://``)
    an existing scheduler. Its workers must have albot1 installed and see
    the results folder (and the datasets) at the same paths as this machine.
"""

from __future__ import annotations

import concurrent.futures as cf
from collections.abc import Iterator
from contextlib import contextmanager

from albot1.bench.errors import BenchError

EXECUTORS_HELP = "local | dask | dask://HOST:PORT"


def parse_executor(spec: str) -> tuple[str, str | None]:
    """``local`` -> ("local", None); ``dask`` -> ("dask", None); ``dask://h:p`` -> ("dask", "tcp://h:p")."""
    text = spec.strip()
    if text in ("local", "dask"):
        return text, None
    for prefix in ("dask://", "tcp://"):
        if text.startswith(prefix) and len(text) > len(prefix):
            return "dask", "tcp://" + text[len(prefix) :]
    raise BenchError(f"executor {spec!r} not understood; expected {EXECUTORS_HELP}")


def check_jobs(jobs: int) -> int:
    """``jobs`` when it is a usable number of parallel cells (at least one), else a BenchError."""
    if jobs < 1:
        raise BenchError(f"-j {jobs}: expected at least one parallel job")
    return jobs


@contextmanager
def open_executor(spec: str, jobs: int, *, dask_processes: bool = True) -> Iterator[cf.Executor]:
    """The executor named by ``spec`` with ``jobs`` parallel cells; shut down on exit."""
    check_jobs(jobs)
    kind, address = parse_executor(spec)
    if kind == "local":
        with cf.ThreadPoolExecutor(max_workers=jobs, thread_name_prefix="cell") as pool:
            yield pool
        return
    import dask
    from distributed import Client, LocalCluster

    if address is not None:
        try:
            client = Client(address, timeout="10s")
        except OSError as exc:
            raise BenchError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
        try:
            yield client.get_executor(pure=False)
        finally:
            client.close()
        return
    with dask.config.set({"distributed.worker.daemon": False}):
        cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=dask_processes, dashboard_address=None)
    try:
        with Client(cluster) as client:
            yield client.get_executor(pure=False)
    finally:
        cluster.close()
