"""The graph library behind ``places.graphml`` is imported by the warm-up, never by ``finish`` (issue 24).

``finish_s`` is timed inside a bench cell's wall: an import there is paid by
every cell. The check runs in a fresh interpreter, where nothing else has
imported networkx yet.
"""

from __future__ import annotations

import os
import subprocess
import sys

_RUN = """
import sys
import numpy as np
from albot1.data.model import Frame, Scan
from albot1.methods.albot1.places.config import Albot1PlacesConfig
from albot1.methods.albot1.places.mapper import Albot1PlacesMapper

mapper = Albot1PlacesMapper(Albot1PlacesConfig(accelerate=False), seed=0)
print("networkx" in sys.modules)
mapper.warm_up(None)
print("networkx" in sys.modules)
loaded = set(sys.modules)
angles = np.radians(np.arange(-90.0, 90.5, 1.0))
for i in range(3):
    scan = Scan(timestamp=float(i), angles=angles, ranges=np.full(angles.size, 3.0), max_range=30.0)
    mapper.process(Frame(index=i, scan=scan, odometry=np.array([0.1 * i, 0.0, 0.0]), reference=None))
out = mapper.finish()
assert "places.graphml" in out.files
print(sorted(name for name in set(sys.modules) - loaded if name.split(".")[0] == "networkx"))
"""


def _run(code: str) -> list[str]:
    command = [sys.executable, "-c", code]
    out = subprocess.run(command, env=dict(os.environ), capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return out.stdout.split("\n")


def test_the_warm_up_imports_networkx_and_finish_then_imports_none_of_it() -> None:
    """Importing the mapper does not import networkx (test collection, other methods); its warm-up does."""
    assert _run(_RUN)[:3] == ["False", "True", "[]"]
