"""The root of the project's exception tree.

Each area (data, mapping, baselines, metrics, bench) derives its own class
from :class:`Albot1Error`; the CLI turns any of them into one line on stderr
and a non-zero exit, while unknown exceptions keep their traceback.
"""

from __future__ import annotations


class Albot1Error(Exception):
    """Base class of every error this project raises on purpose."""


class ConfigError(Albot1Error):
    """A configuration value, preset or override is not what was expected."""


class InstallError(Albot1Error):
    """What this machine has installed cannot do what was asked: not the failure of a method or of its data.

    E.g. an external program on ``PATH`` that cannot start (a shared library it needs is gone: the loader's exit
    status 127), or a cell's process running other versions than its plan. Why a class of its own: the bench
    records a cell whose error has one of these in its chain as an ``executor`` failure, which no suite's
    ``allow_failure`` allows and the next run retries (:func:`albot1.bench.cell_main._report`), so a broken
    install fails ``albot1 bench`` instead of filling a page with the method's "failed" cells.
    """
