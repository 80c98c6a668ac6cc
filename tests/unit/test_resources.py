"""The project's TOML folders: found in the checkout, in the wheel's bundle, or under ALBOT1_CONFIG_DIR."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from albot1 import resources, versions
from albot1.errors import ConfigError
from albot1.resources import FOLDERS, find_resource, list_resources, resource_dirs, shipped_dir

CHECKOUT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def _no_user_folder(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(resources.CONFIG_DIR_ENV, raising=False)


def test_a_checkout_uses_its_own_top_level_folders() -> None:
    for folder in FOLDERS:
        assert shipped_dir(folder) == CHECKOUT / folder
        assert resource_dirs(folder) == [CHECKOUT / folder]
    assert find_resource("baselines", "kiss-icp.toml") == CHECKOUT / "baselines" / "kiss-icp.toml"
    assert [p.name for p in list_resources("benchmarks")] == sorted(p.name for p in CHECKOUT.glob("benchmarks/*.toml"))


def test_missing_file_and_unknown_folder_are_config_errors() -> None:
    with pytest.raises(ConfigError, match=r"no baselines/nope.toml in .*baselines"):
        find_resource("baselines", "nope.toml")
    with pytest.raises(ConfigError, match="unknown resource folder 'presets'; expected one of: datasets, baselines"):
        list_resources("presets")  # type: ignore[arg-type]


def test_user_folder_adds_and_replaces_files(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "benchmarks").mkdir()
    (tmp_path / "benchmarks" / "quick.toml").write_text("# mine\n")
    (tmp_path / "benchmarks" / "lab.toml").write_text("# mine too\n")
    monkeypatch.setenv(resources.CONFIG_DIR_ENV, str(tmp_path))
    found = {p.name: p for p in list_resources("benchmarks")}
    assert found["quick.toml"] == tmp_path / "benchmarks" / "quick.toml"
    assert found["lab.toml"] == tmp_path / "benchmarks" / "lab.toml"
    assert found["default.toml"] == CHECKOUT / "benchmarks" / "default.toml"
    assert find_resource("benchmarks", "quick.toml") == tmp_path / "benchmarks" / "quick.toml"
    assert resource_dirs("datasets") == [CHECKOUT / "datasets"]  # no datasets/ in the user's folder


def test_a_user_file_replacing_the_projects_is_said_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    (tmp_path / "baselines").mkdir()
    (tmp_path / "baselines" / "kiss-icp.toml").write_text("# mine\n")
    (tmp_path / "baselines" / "mine.toml").write_text("# a file of my own: adds, replaces nothing\n")
    monkeypatch.setenv(resources.CONFIG_DIR_ENV, str(tmp_path))
    monkeypatch.setattr(resources, "_said", set(), raising=False)
    with caplog.at_level("WARNING", logger="albot1.resources"):
        for _ in range(2):
            find_resource("baselines", "kiss-icp.toml")
            list_resources("baselines")
            find_resource("baselines", "mine.toml")
    assert [r.getMessage() for r in caplog.records] == [
        f"{tmp_path / 'baselines' / 'kiss-icp.toml'} replaces the project's {CHECKOUT / 'baselines' / 'kiss-icp.toml'} "
        "(ALBOT1_CONFIG_DIR)"
    ]


def test_the_checkout_named_as_the_user_folder_replaces_nothing(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    monkeypatch.setenv(resources.CONFIG_DIR_ENV, str(CHECKOUT))
    with caplog.at_level("WARNING", logger="albot1.resources"):
        assert find_resource("baselines", "kiss-icp.toml") == CHECKOUT / "baselines" / "kiss-icp.toml"
        list_resources("datasets")
    assert caplog.records == []


def test_user_folder_that_is_not_a_folder_is_one_clear_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(resources.CONFIG_DIR_ENV, str(tmp_path / "missing"))
    with pytest.raises(ConfigError, match=r"ALBOT1_CONFIG_DIR=.*missing: not a folder"):
        list_resources("datasets")


def test_installed_package_uses_the_bundle(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    package = tmp_path / "site-packages" / "albot1"
    (package / "_bundled" / "datasets").mkdir(parents=True)
    (package / "_bundled" / "datasets" / "intel.toml").write_text("")
    (tmp_path / "site-packages" / "datasets").mkdir()  # another distribution's package named "datasets"
    monkeypatch.setattr(resources, "_PACKAGE_DIR", package)
    assert shipped_dir("datasets") == package / "_bundled" / "datasets"
    assert [p.name for p in list_resources("datasets")] == ["intel.toml"]
    with pytest.raises(ConfigError, match="neither .*baselines \\(a checkout\\) nor .*_bundled/baselines"):
        shipped_dir("baselines")


@pytest.mark.slow
@pytest.mark.compile
def test_the_build_step_bundles_every_toml_file(tmp_path: Path) -> None:
    """setup.py's build_py copies the top-level folders into the package tree of the build, and the kernels.

    The kernels (the numba kernels compiled for the wheel,
    ``albot1/methods/albot1/kernel_bundle.py``): a bundle this process would
    read (same code version, numba, Python and CPU target) with an index for
    every kernel a warm-up calls, Albot1's and gtsam-graph's
    (``albot1/methods/kernel_sources.py``).
    """
    from albot1.methods import kernel_sources
    from albot1.methods.albot1 import kernel_bundle

    build = tmp_path / "build"
    subprocess.run(
        [sys.executable, "setup.py", "-q", "build_py", "--build-lib", str(build)],
        cwd=CHECKOUT,
        check=True,
        capture_output=True,
    )
    for folder in FOLDERS:
        bundled = sorted(p.name for p in (build / "albot1" / "_bundled" / folder).iterdir())
        assert bundled == sorted(p.name for p in (CHECKOUT / folder).glob("*.toml")), folder
        for name in bundled:
            assert (build / "albot1" / "_bundled" / folder / name).read_bytes() == (
                CHECKOUT / folder / name
            ).read_bytes()
    assert not (CHECKOUT / "albot1" / "_bundled").exists()  # never into the source tree
    kernels = build / "albot1" / "_bundled" / "kernels"
    manifest = kernel_bundle.read_manifest(kernels)
    assert manifest is not None, (kernels / kernel_bundle.MANIFEST).read_text() if kernels.is_dir() else "no bundle"
    indexes = {Path(name).name for name in manifest["files"] if name.endswith(".nbi")}
    calls = kernel_sources.calls()
    assert {name for name, _, _ in calls} >= {"gtsam_graph.build_grid", "gtsam_graph.terms", "update_surfaces"}
    for name, kernel, _ in calls:
        folder = kernel_bundle.bundle_folder(kernel)
        assert f"{folder}/{kernel._cache._impl.filename_base}.nbi" in manifest["files"], name
    assert len(indexes) == len({kernel for _, kernel, _ in calls})  # nothing else


def test_the_code_version_ignores_the_bundle(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A wheel and its checkout name the same code: the bundled copies are not part of the digest."""
    package = tmp_path / "albot1"
    (package / "methods").mkdir(parents=True)
    (package / "methods" / "m.py").write_text("X = 1\n")
    (package / "methods" / "presets.toml").write_text("[presets.default]\n")
    monkeypatch.setattr(versions, "_PACKAGE_DIR", package)
    checkout = versions.code_version.__wrapped__()
    (package / resources.BUNDLE_DIR_NAME / "baselines").mkdir(parents=True)
    (package / resources.BUNDLE_DIR_NAME / "baselines" / "kiss-icp.toml").write_text("[presets.default]\n")
    assert versions.code_version.__wrapped__() == checkout
    (package / "methods" / "presets.toml").write_text("[presets.default]\nx = 1\n")
    assert versions.code_version.__wrapped__() != checkout  # package data does count


def _build_step(monkeypatch: pytest.MonkeyPatch) -> dict[str, object]:
    """setup.py's functions, without running its ``setup()`` (which would parse this process's argv)."""
    import runpy

    import setuptools

    monkeypatch.setattr(setuptools, "setup", lambda **_: None)
    return runpy.run_path(str(CHECKOUT / "setup.py"))


def _fake_kernel_sources(build_lib: Path, body: str) -> None:
    """A build tree whose ``albot1.methods.kernel_sources`` is ``body``: the build step's child imports it first."""
    methods = build_lib / "albot1" / "methods"
    methods.mkdir(parents=True)
    (build_lib / "albot1" / "__init__.py").write_text("")
    (methods / "__init__.py").write_text("")
    (methods / "kernel_sources.py").write_text(body)


def test_the_build_step_fails_when_a_kernel_does_not_bundle(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A kernel that does not compile fails the wheel's build with its reason, and leaves no partial bundle.

    A wheel silently without its kernels would cost every install a compile
    (setup.py, ``bundle_kernels``); only a missing runtime dependency (exit
    3) builds a wheel without them, with a notice.
    """
    step = _build_step(monkeypatch)
    bundle_kernels = step["bundle_kernels"]
    assert callable(bundle_kernels)
    monkeypatch.delenv("ALBOT1_BUILD_KERNELS", raising=False)
    build_lib = tmp_path / "build"
    _fake_kernel_sources(
        build_lib,
        "from pathlib import Path\n"
        "def build(dest: Path) -> int:\n"
        "    (dest / 'part').mkdir(parents=True)\n"
        "    (dest / 'part' / 'x.nbi').write_text('')\n"
        "    raise ValueError('kernel update_surfaces: its sample call raised')\n",
    )
    with pytest.raises(RuntimeError) as failed:
        bundle_kernels(build_lib)
    assert str(failed.value) == (
        "albot1-bench build: compiling the kernel bundle failed: "
        "ValueError: kernel update_surfaces: its sample call raised"
    )
    assert not (build_lib / "albot1" / "_bundled" / "kernels").exists()  # no partial bundle in the wheel

    missing = tmp_path / "missing"
    _fake_kernel_sources(missing, "import albot1_no_such_dependency\n")
    bundle_kernels(missing)  # a wheel without kernels, said once
    assert capsys.readouterr().err == (
        "albot1-bench build: the wheel carries no compiled kernels (a runtime dependency is missing from the build "
        "environment: No module named 'albot1_no_such_dependency')\n"
    )
    assert not (missing / "albot1" / "_bundled" / "kernels").exists()

    monkeypatch.setenv("ALBOT1_BUILD_KERNELS", "0")  # asked for a wheel without kernels: the step is not run
    bundle_kernels(build_lib)
    assert capsys.readouterr().err == ""
