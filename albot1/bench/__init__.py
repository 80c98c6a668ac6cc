"""The benchmark grid: suites (TOML) -> cells -> results store, run on a local or Dask executor.

Layering: ``suite`` parses and validates; ``plan`` expands a suite into
cells against what is installed and downloaded; ``store`` owns the results
folder; ``limits`` runs one cell in a fresh child process under a time and
memory limit; ``cells`` is the code that runs inside that child;
``executors`` and ``runner`` fan cells out and collect outcomes; ``progress``
is the terminal view the CLI attaches.
"""
