"""Errors of the benchmark runner (suites, results store, executors)."""

from __future__ import annotations

from albot1.errors import Albot1Error


class BenchError(Albot1Error):
    """A suite, a results folder or an executor is not what the runner expected."""


class SuiteError(BenchError):
    """A suite file does not parse or names something that does not exist (message names file and key)."""
