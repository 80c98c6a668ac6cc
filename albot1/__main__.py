"""``python -m albot1``: the ``albot1`` command without its console script.

Where the package is importable but the script is not on PATH (a checkout used
through ``PYTHONPATH``, a virtual environment not activated), ``python -m albot1``
runs the same command line; without this module Python refused it ("albot1 is a
package and cannot be directly executed").
"""

from __future__ import annotations

from albot1.cli.entry import main

if __name__ == "__main__":
    main()
