"""The kernels a wheel ships (``kernel_bundle``): loaded without a compile where numba accepts them, else left cold.

Every bundled kernel: Albot1's kernel sets and gtsam-graph's grid search
(``albot1.methods.kernel_sources``). The bundle is built here from this session's cache (``kernel_sources.build``,
a cache load when the kernels are warm), then handed to an empty cache: in a
fresh process every kernel must be seeded and loaded with no compile (numba's
own cache statistics), and each thing numba would reject (a damaged file,
another numba, another CPU target, an index numba already has, a folder that
cannot be written) must leave the kernel to an ordinary compile.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

# numba and the kernels are imported by the tests, not at collection (collection stays cheap)
if TYPE_CHECKING:
    from types import ModuleType

#: ``compiled.CPU_NAME_ENV``, numba's switch
CPU_NAME_ENV = "NUMBA_CPU_NAME"


def _bundle_module() -> ModuleType:
    from albot1.methods.albot1 import kernel_bundle

    return kernel_bundle


_SEED_AND_LOAD = """
import json, sys
from pathlib import Path
from albot1.methods import kernel_sources
from albot1.methods.albot1 import compiled as kernels, kernel_bundle
from albot1.methods.baselines.gtsam_graph import nearest

calls = kernel_sources.calls()
seeded = kernel_bundle.seed(calls, kernels.needs_compile, bundle=Path(sys.argv[1]))
for _, kernel, args in calls:
    kernel(*args)
nearest.warm_up(print)  # a run's own calls: nothing more to compile (nothing printed)
compiled = sorted({name for name, kernel, _ in calls if kernel.stats.cache_misses})
print(json.dumps({"seeded": sorted(seeded), "compiled": compiled}))
"""

#: gtsam-graph's warm-up alone, as its first run after a wheel install makes it (the bundle where the wheel's is)
_GTSAM_WARM_UP = """
import json, sys
from pathlib import Path
from albot1.methods.albot1 import kernel_bundle
from albot1.methods.baselines.gtsam_graph import nearest

kernel_bundle.BUNDLE_DIR = Path(sys.argv[1])
lines = []
nearest.warm_up(lines.append)
compiled = sorted(name for name, kernel, _ in nearest.sample_calls() if kernel.stats.cache_misses)
print(json.dumps({"announced": lines, "compiled": compiled}))
"""


@pytest.fixture(scope="module")
def bundle(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from albot1.methods import kernel_sources

    dest = tmp_path_factory.mktemp("bundle") / "kernels"
    assert kernel_sources.build(dest) > 0
    return dest


def _calls() -> list[tuple[str, Any, tuple[Any, ...]]]:
    from albot1.methods import kernel_sources

    return kernel_sources.calls()


def _fresh_process(bundle: Path, cache: Path, script: str = _SEED_AND_LOAD) -> dict[str, list[str]]:
    env = {**os.environ, "XDG_CACHE_HOME": str(cache)}
    env.pop(CPU_NAME_ENV, None)
    out = subprocess.run(
        [sys.executable, "-c", script, str(bundle)], env=env, capture_output=True, text=True, timeout=600
    )
    assert out.returncode == 0, out.stderr
    result: dict[str, list[str]] = json.loads(out.stdout)
    return result


class _Elsewhere:
    """A kernel whose numba cache folder is ``folder`` (a fresh one), everything else the kernel's own."""

    class _Cache:
        def __init__(self, cache: Any, folder: Path) -> None:
            self._real, self.cache_path = cache, str(folder)

        def __getattr__(self, name: str) -> Any:
            return getattr(self._real, name)

    def __init__(self, kernel: Any, folder: Path, fails: bool = False) -> None:
        self._kernel, self._cache, self._fails = kernel, _Elsewhere._Cache(kernel._cache, folder), fails

    def __getattr__(self, name: str) -> Any:
        return getattr(self._kernel, name)

    def __call__(self, *args: Any) -> Any:  # the real kernel, from this session's cache; or numba failing
        if self._fails:
            raise RuntimeError("numba could not rebuild the cached kernel")
        return self._kernel(*args)


def _elsewhere(folder: Path, failing: str = "") -> list[tuple[str, Any, tuple[Any, ...]]]:
    return [(name, _Elsewhere(kernel, folder / name, name == failing), args) for name, kernel, args in _calls()]


def _always_cold(kernel: object) -> bool:
    return True


@pytest.mark.slow
@pytest.mark.compile
def test_a_fresh_cache_loads_every_bundled_kernel_without_compiling(bundle: Path, tmp_path: Path) -> None:
    names = sorted({name for name, _, _ in _calls()})
    assert {"gtsam_graph.build_grid", "gtsam_graph.linearise_terms", "gtsam_graph.terms"} <= set(names)
    first = _fresh_process(bundle, tmp_path / "cache")
    assert first == {"seeded": names, "compiled": []}
    again = _fresh_process(bundle, tmp_path / "cache")  # numba's own files now: nothing seeded, nothing compiled
    assert again == {"seeded": [], "compiled": []}


@pytest.mark.slow
@pytest.mark.compile
def test_gtsam_graph_s_warm_up_loads_its_kernels_from_the_bundle(bundle: Path, tmp_path: Path) -> None:
    """Its first run after a wheel install: no compile, nothing announced; without a bundle it compiles, as before."""
    loaded = _fresh_process(bundle, tmp_path / "cache", _GTSAM_WARM_UP)
    assert loaded == {"announced": [], "compiled": []}
    compiled = _fresh_process(tmp_path / "no-bundle", tmp_path / "cache-2", _GTSAM_WARM_UP)
    assert compiled["compiled"] == ["gtsam_graph.build_grid", "gtsam_graph.linearise_terms", "gtsam_graph.terms"]
    assert compiled["announced"][0].startswith("gtsam-graph: compiling its grid search")


def test_every_kernel_of_the_bundle_is_seeded_where_nothing_is_cached(bundle: Path, tmp_path: Path) -> None:
    calls = _elsewhere(tmp_path)
    assert sorted(_bundle_module().seed(calls, _always_cold, bundle)) == sorted({name for name, _, _ in calls})
    for name, kernel, _ in calls:
        index = f"{kernel._cache._impl.filename_base}.nbi"
        assert (tmp_path / name / index).read_bytes() == next(bundle.rglob(index)).read_bytes()


@pytest.mark.parametrize(
    ("pattern", "damaged", "still_seeded"),
    [
        ("update_kernels.update_surfaces-*.nbc", "update_surfaces", {"build_view"}),
        # the same checks for gtsam-graph's kernels
        (
            "nearest.linearise_terms-*.nbc",
            "gtsam_graph.linearise_terms",
            {"gtsam_graph.build_grid", "gtsam_graph.terms", "build_view"},
        ),
    ],
)
def test_a_damaged_file_leaves_its_kernel_to_be_compiled(
    bundle: Path, tmp_path: Path, pattern: str, damaged: str, still_seeded: set[str]
) -> None:
    """A file that is not what the manifest says is not seeded; the other kernels are."""
    copy = tmp_path / "bundle"
    shutil.copytree(bundle, copy)
    data = sorted(copy.rglob(pattern))
    assert data
    data[0].write_bytes(data[0].read_bytes()[:-1])
    seeded = _bundle_module().seed(_elsewhere(tmp_path / "cache"), _always_cold, copy)
    assert damaged not in seeded
    assert still_seeded <= set(seeded)
    assert not (tmp_path / "cache" / damaged).exists()


@pytest.mark.parametrize(
    "key, value", [("numba", "0.1.0"), ("cpu_name", "skylake"), ("code_version", "0+other"), ("format", "0")]
)
def test_a_bundle_built_for_something_else_is_not_read(bundle: Path, tmp_path: Path, key: str, value: str) -> None:
    copy = tmp_path / "bundle"
    shutil.copytree(bundle, copy)
    manifest = json.loads((copy / _bundle_module().MANIFEST).read_text())
    (copy / _bundle_module().MANIFEST).write_text(json.dumps({**manifest, key: value}))
    assert _bundle_module().read_manifest(copy) is None
    assert _bundle_module().seed(_elsewhere(tmp_path / "cache"), _always_cold, copy) == []
    assert _bundle_module().seed(_calls(), _always_cold, tmp_path / "none") == []  # no bundle at all


def test_an_index_built_for_another_cpu_leaves_its_kernel_cold(bundle: Path, tmp_path: Path) -> None:
    """The manifest can say ``generic`` while an index holds another target's keys: the keys are checked too."""
    copy = tmp_path / "bundle"
    shutil.copytree(bundle, copy)
    index = next(copy.rglob("kernels.build_view-*.nbi"))
    numba_version, stamp, overloads = _bundle_module()._read_index(index)
    moved = {(k[0], (k[1][0], "skylake", k[1][2]), k[2]): v for k, v in overloads.items()}
    _write_index(index, numba_version, stamp, moved)
    manifest = json.loads((copy / _bundle_module().MANIFEST).read_text())
    manifest["files"][index.relative_to(copy).as_posix()] = _bundle_module().sha256(index)
    (copy / _bundle_module().MANIFEST).write_text(json.dumps(manifest))
    seeded = _bundle_module().seed(_elsewhere(tmp_path / "cache"), _always_cold, copy)
    assert "build_view" not in seeded and "recognise_landmarks" in seeded


def test_numba_s_own_index_is_never_replaced_and_an_unwritable_folder_is_skipped(bundle: Path, tmp_path: Path) -> None:
    calls = _elsewhere(tmp_path)
    own = tmp_path / "build_view" / f"{calls[0][1]._cache._impl.filename_base}.nbi"
    assert calls[0][0] == "build_view"
    own.parent.mkdir()
    own.write_bytes(b"numba's own")
    (tmp_path / "update_surfaces").write_text("a file where the folder would be")
    seeded = _bundle_module().seed(calls, _always_cold, bundle)
    assert "build_view" not in seeded and "update_surfaces" not in seeded and "landmark_rows" in seeded
    assert own.read_bytes() == b"numba's own"


def test_seeded_files_numba_cannot_load_are_taken_back(bundle: Path, tmp_path: Path) -> None:
    seeded = _bundle_module().seed(_elsewhere(tmp_path, failing="match_structure"), _always_cold, bundle)
    assert "match_structure" not in seeded and "same_any" in seeded
    assert list((tmp_path / "match_structure").iterdir()) == []  # compiled by the warm-up, as without a bundle


def test_the_build_refuses_a_missing_gtsam_graph_kernel(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Its kernels go through the build's one check: a kernel numba left no files for fails the build, named."""
    from albot1.methods import kernel_sources
    from albot1.methods.albot1 import kernel_bundle_build

    missing = _fake_kernel(tmp_path / "nowhere")
    missing.py_func = kernel_sources.nearest.build_grid.py_func
    others = [(lambda: None, lambda: [("gtsam_graph.build_grid", missing, ())])]
    monkeypatch.setattr(kernel_bundle_build, "albot1_kernel_sets", lambda: ())
    with pytest.raises(kernel_bundle_build.KernelBundleError, match=r"^kernel bundle: gtsam_graph.build_grid was"):
        kernel_bundle_build.build(tmp_path / "dest", others)
    assert not (tmp_path / "dest").exists()


def test_the_build_refuses_two_kernels_of_one_name(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from albot1.methods.albot1 import kernel_bundle_build

    others = [(lambda: None, lambda: [("k", _fake_kernel(tmp_path), ()), ("k", _fake_kernel(tmp_path), ())])]
    monkeypatch.setattr(kernel_bundle_build, "albot1_kernel_sets", lambda: ())
    with pytest.raises(kernel_bundle_build.KernelBundleError, match=r"^kernel bundle: two kernels are named k$"):
        kernel_bundle_build.build(tmp_path / "dest", others)


def test_the_gtsam_graph_kernels_are_bundled_without_gtsam(tmp_path: Path) -> None:
    """The build imports gtsam-graph's grid search, ICP loop and block sums, which need no GTSAM: a build works."""
    code = (
        "import sys\nsys.modules['gtsam'] = None\n"  # import gtsam now raises ImportError
        "from albot1.methods import kernel_sources\n"
        "print(sorted(name for name, _, _ in kernel_sources.calls() if name.startswith('gtsam_graph.')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True)
    expected = [
        "gtsam_graph.block_sums",
        "gtsam_graph.build_grid",
        "gtsam_graph.icp_run",
        "gtsam_graph.line_moments",
        "gtsam_graph.linearise_terms",
        "gtsam_graph.pose_sums",
        "gtsam_graph.rotate_runs",
        "gtsam_graph.terms",
    ]
    assert out.stdout.strip() == str(expected)


def test_a_kernel_already_cached_is_not_seeded(bundle: Path, tmp_path: Path) -> None:
    assert _bundle_module().seed(_elsewhere(tmp_path), lambda kernel: False, bundle) == []
    assert not any(tmp_path.iterdir())


def test_kernels_are_compiled_for_numba_s_generic_cpu_unless_the_user_says_otherwise() -> None:
    """``generic`` code loads on any machine of the architecture, which a shipped kernel needs."""
    code = "import albot1.methods.albot1.compiled\nfrom numba.core import config\nprint(config.CPU_NAME)\n"
    env = {k: v for k, v in os.environ.items() if k != CPU_NAME_ENV}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "generic"
    env[CPU_NAME_ENV] = "host"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "host"


def _write_index(index: Path, version: Any, stamp: Any, overloads: dict[Any, str]) -> None:
    import pickle

    from numba.core.serialize import dumps

    with index.open("wb") as f:
        pickle.dump(version, f, protocol=-1)
        f.write(dumps((stamp, overloads)))


def _fake_kernel(cache_path: Path) -> Any:
    from types import SimpleNamespace

    impl = SimpleNamespace(filename_base="stage.kernel-12.py311")
    return SimpleNamespace(_cache=SimpleNamespace(cache_path=str(cache_path), _impl=impl))


def test_the_build_refuses_a_kernel_compiled_without_the_cache() -> None:
    """Decorated without ``cache=True`` a kernel has numba's NullCache: one line, not a TypeError from ``Path``."""
    import numba

    from albot1.methods.albot1.kernel_bundle_build import KernelBundleError, _kernel_files

    uncached = numba.njit(lambda x: x + 1)
    with pytest.raises(KernelBundleError, match=r"^kernel bundle: plain is compiled without numba's cache"):
        _kernel_files("plain", uncached)


def test_the_build_refuses_a_kernel_whose_cache_files_are_missing(tmp_path: Path) -> None:
    """A wheel whose bundle silently lacked a kernel would compile it at the first run while claiming it ships it."""
    from albot1.methods.albot1.kernel_bundle_build import KernelBundleError, _kernel_files

    kernel = _fake_kernel(tmp_path)
    with pytest.raises(KernelBundleError, match=r"^kernel bundle: stage_kernel was compiled but numba wrote no index"):
        _kernel_files("stage_kernel", kernel)
    (tmp_path / "stage.kernel-12.py311.nbi").write_bytes(b"i")
    (tmp_path / "stage.kernel-120.py311.1.nbc").write_bytes(b"another kernel's")
    with pytest.raises(KernelBundleError, match=r"^kernel bundle: stage_kernel has an index but no data file"):
        _kernel_files("stage_kernel", kernel)
    (tmp_path / "stage.kernel-12.py311.2.nbc").write_bytes(b"d")
    (tmp_path / "stage.kernel-12.py311.1.nbc").write_bytes(b"d")
    assert [p.name for p in _kernel_files("stage_kernel", kernel)] == [
        "stage.kernel-12.py311.nbi",
        "stage.kernel-12.py311.1.nbc",
        "stage.kernel-12.py311.2.nbc",
    ]


def test_the_fingerprint_and_the_seed_hold_where_python_has_no_abiflags(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """``sys.abiflags`` is POSIX-only before Python 3.14: a cold warm-up on Windows must compile, not crash."""
    bundle_module = _bundle_module()
    monkeypatch.delattr(sys, "abiflags", raising=False)
    assert bundle_module.fingerprint()["python"].endswith(" ")
    (tmp_path / bundle_module.MANIFEST).write_text(json.dumps({"files": {}}))  # read, so compared with the fingerprint
    assert bundle_module.seed([], lambda kernel: True, bundle=tmp_path) == []
