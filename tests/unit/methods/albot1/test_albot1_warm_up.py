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
import signal
import subprocess
import sys
from pathlib import Path

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
warmed = {}
added = {}
for method, preset, world in runs:
    mapper = get_method(method).load_class()(resolve_config(method, preset, None))
    mapper.warm_up()
    before = signatures(mapper)
    for name, sigs in before.items():
        warmed[name] = sorted(set(warmed.get(name, [])) | set(sigs))
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
@pytest.mark.compile
def test_whole_runs_after_the_warm_up_compile_nothing_new() -> None:
    out = subprocess.run(
        [sys.executable, "-c", _CODE], env=dict(os.environ), capture_output=True, text=True, timeout=900
    )
    assert out.returncode == 0, out.stderr
    found = json.loads(out.stdout)
    assert found["added"] == {}
    # every kernel warmed by one run, but scan_points: only perceive calls it (plus's warm-up leaves out FUSED)
    assert {name for name, sigs in found["warmed"].items() if not sigs} <= {"scan_points"}, found["warmed"]


_SKIPPED = """
import json
from albot1.methods.registry import get_method, resolve_config
from albot1.methods.albot1.warm_up import kernel_names
found = {}
for preset in ("thesis", "plus"):
    mapper = get_method("albot1").load_class()(resolve_config("albot1", preset, None))
    mapper.warm_up()
    found[preset] = sorted(name for k in mapper.kernels for name in kernel_names(k) if getattr(k, name).signatures)
print(json.dumps(found))
"""


@pytest.mark.compile
def test_a_thesis_preset_s_warm_up_leaves_out_the_kernels_only_albot1_plus_calls() -> None:
    """The first run of a thesis preset does not pay for Albot1+'s pose kernels; ``plus`` warms them (in that order)."""
    out = subprocess.run(
        [sys.executable, "-c", _SKIPPED], env=dict(os.environ), capture_output=True, text=True, timeout=900
    )
    assert out.returncode == 0, out.stderr
    found = json.loads(out.stdout)
    assert found["thesis"] == [
        "build_view",
        "landmark_rows",
        "place_segments",
        "recognise_landmarks",
        "robust_starts",  # the thesis's localisation, compiled (Albot1+ starts from it)
        "update_surfaces",
    ]
    # plus calls perceive, which compiles scan_points into itself (a compile in this process gives scan_points a
    # signature too, a load from the cache does not): scan_points is not warmed on its own
    assert sorted(set(found["plus"]) - {"scan_points"}) == sorted(
        [
            *found["thesis"],
            "measurement_costs",
            "perceive",
            "refine_and_score",
            "refine_pose",
            "screen_directions",
        ]
    )


def _python(code: str, cache: str, **env: str) -> str:
    """Run ``code`` in a fresh interpreter whose user cache (numba's cache folder with it) is ``cache``."""
    out = subprocess.run(
        [sys.executable, "-c", code],
        env={**os.environ, "XDG_CACHE_HOME": cache, **env},
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


_LOAD = """
import json
from albot1.methods.albot1 import compiled
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.perception.kernels import PerceptionKernels
from albot1.methods.albot1.warm_up import sample_calls
sets = (PerceptionKernels(), MappingKernels())
cached = {name: compiled.is_cached(kernel) for name, kernel, _ in sample_calls(*sets)}
for name, kernel, args in sample_calls(*sets):
    if cached[name]:
        kernel(*args)
stats = {name: [sum(kernel.stats.cache_hits.values()), sum(kernel.stats.cache_misses.values())]
         for name, kernel, _ in sample_calls(*sets) if cached[name]}
print(json.dumps({"cached": cached, "stats": stats}))
"""


@pytest.mark.compile
def test_a_helper_s_kernels_are_loaded_from_numba_s_cache_by_the_next_process(tmp_path: Path) -> None:
    """The mechanism of a parallel warm-up: what a helper compiles for its claims, another process loads."""
    claims = tmp_path / "claims"
    claims.mkdir()
    (claims / "refine_pose").touch()  # claimed by another process: the helper leaves it
    code = (
        "from albot1.methods.albot1.warm_up import compile_claimed\n"
        f"compile_claimed({str(claims)!r}, ['albot1.methods.albot1.mapping.kernel_set:MappingKernels'], "
        "['refine_pose', 'scan_points'])\n"
    )
    _python(code, str(tmp_path))
    found = json.loads(_python(_LOAD, str(tmp_path)))
    assert {name for name, cached in found["cached"].items() if cached} == {"scan_points"}
    assert found["stats"] == {"scan_points": [1, 0]}  # its one warm-up signature loaded, not compiled
    assert sorted(p.name for p in claims.iterdir()) == ["refine_pose", "scan_points"]


@pytest.mark.slow
@pytest.mark.compile
def test_a_cold_warm_up_in_two_processes_fills_the_cache_with_every_kernel_of_its_preset(tmp_path: Path) -> None:
    """``ALBOT1_COMPILE_PROCESSES=2`` on an empty cache: each kernel cached once, the next process compiles nothing.

    The thesis preset's warm-up (its mapper's ``skip``): six kernels of both sets, among them the dearest
    (``update_surfaces``, which the helper claims first) and a kernel with its follower (``build_view``,
    ``landmark_rows``), so both processes get kernels to compile and the mechanism is that of every preset;
    what it leaves out must stay out of the cache. Albot1+'s six more kernels would double the compile (about
    8.6 of 17 CPU-s, ``warm_up.COMPILE_CPU_S``) and check nothing more about two processes: that every kernel
    is cached and loads without a compile is checked kernel by kernel by ``test_albot1_kernel_bundle.py`` (a
    fresh cache seeded with each kernel compiles none) and ``tests/unit/test_resources.py`` (the wheel's cold
    compile, in as many processes as CPUs, leaves an index for each kernel).
    """
    code = (
        "from albot1.methods.albot1.mapping.kernel_set import MappingKernels\n"
        "from albot1.methods.albot1.perception.kernels import PerceptionKernels\n"
        "from albot1.methods.albot1.warm_up import warm_up\n"
        "warm_up((PerceptionKernels(), MappingKernels()), print, skip=MappingKernels.not_called(''))\n"
    )
    from albot1.methods.albot1.mapping.kernel_set import MappingKernels

    left_out = set(MappingKernels.not_called(""))
    said = _python(code, str(tmp_path), ALBOT1_COMPILE_PROCESSES="2").splitlines()
    assert said[0].startswith("albot1: compiling the numba kernels once") and said[1].startswith("albot1: kernels")
    found = json.loads(_python(_LOAD, str(tmp_path)))
    assert {name for name, cached in found["cached"].items() if cached} == set(found["cached"]) - left_out
    assert sorted(found["stats"]) == [
        "build_view",
        "landmark_rows",
        "place_segments",
        "recognise_landmarks",
        "robust_starts",
        "update_surfaces",
    ]
    assert all(misses == 0 and hits >= 1 for hits, misses in found["stats"].values()), found["stats"]
    assert _python(code, str(tmp_path)) == ""  # a warm warm-up says nothing


def test_the_number_of_compile_processes_comes_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    from albot1.errors import ConfigError
    from albot1.methods.albot1 import compiled

    monkeypatch.setenv(compiled.PROCESSES_ENV, " 3 ")
    assert compiled.compile_processes() == 3
    for bad in ("0", "-1", "two", "1.5"):
        monkeypatch.setenv(compiled.PROCESSES_ENV, bad)
        with pytest.raises(ConfigError, match=f"ALBOT1_COMPILE_PROCESSES='{bad}': expected a whole number"):
            compiled.compile_processes()
    monkeypatch.delenv(compiled.PROCESSES_ENV)
    assert compiled.compile_processes() >= 1


@pytest.mark.parametrize("bad", ["1_0", "\u0663", "\uff12", "+2", "2e0"])
def test_a_process_count_must_be_ascii_digits(monkeypatch: pytest.MonkeyPatch, bad: str) -> None:
    """``int()`` read ``1_0`` as 10 and Arabic-Indic ``٣`` as 3: a count the user did not write, silently."""
    from albot1.errors import ConfigError
    from albot1.methods.albot1 import compiled

    monkeypatch.setenv(compiled.PROCESSES_ENV, bad)
    with pytest.raises(ConfigError) as caught:
        compiled.compile_processes()
    assert str(caught.value) == f"ALBOT1_COMPILE_PROCESSES={bad!r}: expected a whole number of processes (1 or more)"


def test_every_kernel_has_a_measured_compile_cost() -> None:
    """A cold warm-up claims kernels by measured compile CPU (``COMPILE_CPU_S``): a new kernel needs a measurement."""
    from albot1.methods.albot1.mapping.kernel_set import MappingKernels
    from albot1.methods.albot1.perception.kernels import PerceptionKernels
    from albot1.methods.albot1.places.kernels import PlacesKernels
    from albot1.methods.albot1.warm_up import COMPILE_CPU_S, compile_cost, kernel_names

    names = [name for k in (PerceptionKernels(), MappingKernels(), PlacesKernels()) for name in kernel_names(k)]
    assert sorted(names) == sorted(COMPILE_CPU_S)
    assert compile_cost("update_surfaces", len) == COMPILE_CPU_S["update_surfaces"]
    mapping = MappingKernels()
    assert compile_cost("not measured", mapping.refine_pose) > compile_cost("not measured", mapping.scan_points) > 0


def test_a_scan_s_arrays_reach_a_kernel_with_one_type_whatever_their_flags() -> None:
    """``readonly_float64``: writable, read-only, strided or float32 ranges all become one numba argument type."""
    import numba
    import numpy as np

    from albot1.methods.albot1.compiled import readonly_float64

    base = np.arange(10.0)
    frozen_base = base.copy()
    frozen_base.flags.writeable = False
    inputs = [base, frozen_base, np.arange(20.0)[::2], np.arange(10, dtype=np.float32), [0.0, 1.0]]
    outputs = [readonly_float64(a) for a in inputs]
    assert {str(numba.typeof(out)) for out in outputs} == {"readonly array(float64, 1d, C)"}
    for a, out in zip(inputs, outputs, strict=True):
        np.testing.assert_array_equal(out, np.asarray(a, dtype=np.float64))
    assert np.shares_memory(outputs[0], base) and base.flags.writeable  # a view: the caller's array is untouched


def test_a_process_that_claims_refine_pose_claims_measurement_costs_next(tmp_path: Path) -> None:
    """Kernels sharing dear callees go to one process: ``measurement_costs`` right after ``refine_pose``."""
    from albot1.methods.albot1 import warm_up

    order: list[str] = []
    names = ["update_surfaces", "refine_pose", "build_view", "measurement_costs"]
    calls = [(name, lambda name=name: order.append(name), ()) for name in names]
    (tmp_path / "update_surfaces").touch()  # another process has it
    warm_up._compile(tmp_path, calls, names)
    assert order == ["refine_pose", "measurement_costs", "build_view"]
    order.clear()
    fresh = tmp_path / "fresh"
    fresh.mkdir()
    warm_up._compile(fresh, calls, ["refine_pose"])
    assert order == ["refine_pose"]  # the follower only when it is among the names to compile


def _recorded_warms(monkeypatch: pytest.MonkeyPatch) -> list[tuple[list[str], list[str], object]]:
    """Replace the compiling part of ``warm_up`` by a record of (kernel set types, kernel names, announce) per call."""
    from albot1.methods.albot1 import warm_up

    warms: list[tuple[list[str], list[str], object]] = []

    def record(kernel_sets: tuple[object, ...], calls: list[tuple[str, object, object]], announce: object) -> None:
        warms.append(([type(k).__name__ for k in kernel_sets], [name for name, _, _ in calls], announce))

    monkeypatch.setattr(warm_up, "_warm", record)
    return warms


def test_warm_ups_inside_together_are_compiled_once_as_their_union(monkeypatch: pytest.MonkeyPatch) -> None:
    """The forkserver's case: every preset of both methods, one cold compile over every kernel each needs, once each."""
    from albot1.methods.albot1 import warm_up
    from albot1.methods.albot1.mapping.kernel_set import MappingKernels
    from albot1.methods.albot1.perception.kernels import PerceptionKernels
    from albot1.methods.albot1.places.kernels import PlacesKernels

    warms = _recorded_warms(monkeypatch)
    thesis_skip = MappingKernels.not_called("")
    with warm_up.together():
        warm_up.warm_up((PerceptionKernels(), MappingKernels()), skip=thesis_skip)
        with warm_up.together():  # nested: joins the outer block
            warm_up.warm_up((PerceptionKernels(), MappingKernels()), print)
        warm_up.warm_up((PerceptionKernels(), MappingKernels(), PlacesKernels()), skip=thesis_skip)
        assert warms == []  # noted, not compiled
    every = [name for k in (PerceptionKernels(), MappingKernels(), PlacesKernels()) for name in warm_up.kernel_names(k)]
    thesis_first = [
        name for name in every if name not in thesis_skip and name not in warm_up.kernel_names(PlacesKernels())
    ]
    assert warms == [
        (
            ["PerceptionKernels", "MappingKernels", "PlacesKernels"],
            [*thesis_first, *(name for name in every if name in thesis_skip), *warm_up.kernel_names(PlacesKernels())],
            print,
        )
    ]
    assert sorted(warms[0][1]) == sorted(every)
    warm_up.warm_up((PlacesKernels(),))  # after the block: compiled at once again
    assert warms[1] == (["PlacesKernels"], warm_up.kernel_names(PlacesKernels()), None)


def test_a_together_block_that_raises_compiles_nothing_and_ends(monkeypatch: pytest.MonkeyPatch) -> None:
    from albot1.methods.albot1 import warm_up
    from albot1.methods.albot1.places.kernels import PlacesKernels

    warms = _recorded_warms(monkeypatch)
    with pytest.raises(RuntimeError, match="boom"), warm_up.together():
        warm_up.warm_up((PlacesKernels(),))
        raise RuntimeError("boom")
    assert warms == []
    warm_up.warm_up((PlacesKernels(),))
    assert len(warms) == 1


def test_a_together_block_takes_only_its_own_thread_s_warm_ups(monkeypatch: pytest.MonkeyPatch) -> None:
    """A warm-up in another thread (a run's own) compiles at once, never left to a block it does not know of."""
    import threading

    from albot1.methods.albot1 import warm_up
    from albot1.methods.albot1.places.kernels import PlacesKernels

    warms = _recorded_warms(monkeypatch)
    with warm_up.together():
        other = threading.Thread(target=warm_up.warm_up, args=((PlacesKernels(),),))
        other.start()
        other.join()
        assert len(warms) == 1
        warm_up.warm_up((PlacesKernels(),))
        assert len(warms) == 1
    assert len(warms) == 2


_SET_UP = """
import json
from albot1.methods.albot1 import compiled, warm_up
before = sorted(str(p) for p in compiled.CACHE_DIR.rglob("*"))
warm_up._set_up_numba()
print(json.dumps({"cache": sorted(str(p) for p in compiled.CACHE_DIR.rglob("*")) == before}))
"""


def test_numba_s_set_up_before_the_fork_writes_nothing_to_the_kernel_cache(tmp_path: Path) -> None:
    """The throw-away function that pays numba's set-up is not a kernel: no cache entry, nothing to invalidate."""
    assert json.loads(_python(_SET_UP, str(tmp_path))) == {"cache": True}


_INTERRUPTED_HELPER = """
import os, signal, time
from albot1.methods.albot1 import warm_up
def compiling(*args):
    os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C in the middle of a compile
    time.sleep(30)
warm_up.compile_claimed = compiling
warm_up.helper_main("claims", [], [])
"""


def test_ctrl_c_ends_a_compile_helper_at_once_and_silently(tmp_path: Path) -> None:
    """Ctrl-C reaches the helpers too: a KeyboardInterrupt's traceback (multiprocessing prints it) must not appear."""
    done = subprocess.run(
        [sys.executable, "-c", _INTERRUPTED_HELPER], capture_output=True, text=True, timeout=120, cwd=tmp_path
    )
    assert (done.returncode, done.stdout, done.stderr) == (-signal.SIGINT, "", "")
