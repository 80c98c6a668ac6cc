"""After ``warm_up`` nothing compiles inside a timed scan: in a fresh process, whole runs add no kernel signature.

Numba compiles a kernel for each new set of argument types. ``warm_up``
calls every kernel once with the types the mappers use, so a run that then
meets a type the samples lack (a new signature) would compile mid-scan:
this test names the kernel and the signature. A fresh interpreter, because
other tests of this session may have compiled signatures already.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

_CODE = """
import json
from albot1.data.synthetic.worlds import load_world
from albot1.methods.registry import get_method, resolve_config
from albot1.methods.albot1.warm_up import kernel_names

def signatures(mapper):
    sets = (*mapper.inner.kernels, mapper._k) if hasattr(mapper, "inner") else mapper.kernels
    return {name: [str(s) for s in getattr(k, name).signatures] for k in sets for name in kernel_names(k)}

runs = [("albot1-places", "default", "synthetic-office-loop"), ("albot1", "plus", "synthetic-office-startstop"),
        ("albot1", "default", "synthetic-office-startstop")]
warmed = None
added = {}
for method, preset, world in runs:
    mapper = get_method(method).load_class()(resolve_config(method, preset, None))
    mapper.warm_up()
    before = signatures(mapper)
    warmed = warmed or before
    for frame in load_world(world):
        mapper.process(frame)
    mapper.finish()
    for name, sigs in signatures(mapper).items():
        new = sorted(set(sigs) - set(before[name]))
        if new:
            added[f"{method}:{preset} on {world}: {name}"] = new
print(json.dumps({"warmed": warmed, "added": added}))
"""


@pytest.mark.slow
def test_whole_runs_after_the_warm_up_compile_nothing_new() -> None:
    out = subprocess.run(
        [sys.executable, "-c", _CODE], env=dict(os.environ), capture_output=True, text=True, timeout=900
    )
    assert out.returncode == 0, out.stderr
    found = json.loads(out.stdout)
    assert found["added"] == {}
    assert all(len(sigs) >= 1 for sigs in found["warmed"].values()), found["warmed"]  # every kernel warmed
