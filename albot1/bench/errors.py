"""Errors of the benchmark runner (suites, results store, executors)."""

from __future__ import annotations

from albot1.errors import Albot1Error, InstallError


class BenchError(Albot1Error):
    """A suite, a results folder or an executor is not what the runner expected."""


class SuiteError(BenchError):
    """A suite file does not parse or names something that does not exist (message names file and key)."""


class PlanMismatchError(BenchError, InstallError):
    """A cell's process is not what its plan was made with: other versions, config or key than planned.

    Not the method's failure: the install or the files changed under the grid (or a worker runs another
    install), so a cell process records it as an ``executor`` failure, which no ``allow_failure`` allows and
    the next run retries (:func:`albot1.bench.cell_main._report`), not as the method's own error.
    """
