"""Importing the report's entry module loads neither pandas nor matplotlib.

Test modules import `albot1.report.index` at collection, and `make test` collects every test before
running one: a module-level `import pandas` there (or in a module it imports, such as the figure pool)
costs every test run the library's import (issue 24, "collection under 5 s"). The report imports them
where it draws or tabulates. This checks which modules a fresh interpreter has loaded, not a time.
"""

from __future__ import annotations

import json
import subprocess
import sys

#: Libraries the report needs only when it works, never at import.
DEFERRED = ("pandas", "matplotlib", "gtsam", "evo")


def test_importing_the_report_loads_no_table_or_plotting_library() -> None:
    code = (
        "import json, sys\n"
        "import albot1.report.index, albot1.report.figure_pool\n"
        f"print(json.dumps(sorted(m for m in {DEFERRED!r} if m in sys.modules)))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
    assert json.loads(out.stdout) == []
