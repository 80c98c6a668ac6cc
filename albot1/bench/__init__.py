"""The benchmark grid: suites (TOML) -> cells -> results store, run on a local or Dask executor.

Layering: ``suite`` parses and validates a suite file; ``plan`` expands it
into ``grid`` cells against what is installed and downloaded; ``store``
owns the results folder; ``runner`` skips complete cells and fans the rest
out over an ``executors`` executor; each cell is a ``job`` that runs it in
a fresh child process under a time and memory limit (``limits``, forked
from the ``preload``-ed forkserver), whose entry point is ``cell_main``
and whose work is ``cells``; ``progress`` is the terminal view the CLI
attaches.
"""
