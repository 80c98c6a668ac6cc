"""Build step: copy the project's TOML folders into the wheel as package data.

``datasets/``, ``baselines/`` and ``benchmarks/`` at the top of the repository
are the one source of truth for dataset manifests, baseline configs and
benchmark suites. A wheel must carry them (an installed package has no
checkout beside it), so ``build_py`` copies their ``*.toml`` files into
``albot1/_bundled/<folder>/`` of the build tree, never into the source tree.
Editable installs skip the copy: they read the checkout's folders directly
(``albot1/resources.py`` explains the search order). Everything else about
the package is declared in ``pyproject.toml``. The same step records the
commit the wheel is built from in ``albot1/_bundled/build.json``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
FOLDERS = ("datasets", "baselines", "benchmarks")  # albot1.resources.FOLDERS
BUNDLE = Path("albot1") / "_bundled"  # albot1.resources.BUNDLE_DIR_NAME
BUILD_FILE = "build.json"  # albot1.versions.BUILD_FILE
COMMIT_ENV = "ALBOT1_BUILD_COMMIT"
KERNELS = BUNDLE / "kernels"  # albot1.methods.albot1.kernel_bundle.BUNDLE_DIR
KERNELS_ENV = "ALBOT1_BUILD_KERNELS"  # 0: build the wheel without its compiled kernels
#: the build step's child process: compile, bundle, say how many files (or fail with the reason as its last line)
#: (exit 3: a runtime dependency is missing from the build environment, e.g. --no-build-isolation without numba)
MISSING_DEPENDENCY = 3
BUILD_KERNELS = """
import sys
from pathlib import Path
try:
    from albot1.methods.kernel_sources import build
except ImportError as error:
    print(f"a runtime dependency is missing from the build environment: {error}", file=sys.stderr)
    sys.exit(3)
print(f"kernel bundle: {build(Path(sys.argv[1]))} numba cache files in {sys.argv[1]}")
"""


def bundle_kernels(build_lib: Path) -> None:
    """Compile the numba kernels into the wheel (``albot1.methods.kernel_sources``: Albot1's, gtsam-graph's), or not.

    Numba compiles them from the build tree's sources into an empty cache;
    its files go into ``albot1/_bundled/kernels/``, and the first run after
    a bare ``pip install`` loads them instead of compiling them, where numba
    accepts them (same numba, Python and architecture; otherwise it
    compiles, as without them). A build environment without the runtime
    dependencies builds a wheel without them, with a notice; any other
    failure (a kernel that does not compile, a sample call that raises, a
    kernel that left no cache files) fails the build with its reason: a
    wheel silently without its kernels would cost every install a compile.
    """
    if os.environ.get(KERNELS_ENV, "1").strip() == "0":
        return
    with tempfile.TemporaryDirectory(prefix="albot1-build-kernels-") as cache:
        # The build tree first; pip's isolated build environment is found through PYTHONPATH too.
        path = os.pathsep.join(p for p in (str(build_lib), os.environ.get("PYTHONPATH", "")) if p)
        # No NUMBA_* setting of the builder's reaches the compile: numba's cache key holds neither its
        # optimisation level nor bounds checking nor debug info, so such a setting would ship other code
        # to every install under the same key; the kernels are numba's defaults for its generic CPU.
        env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
        env.update(PYTHONPATH=path, XDG_CACHE_HOME=cache, PYTHONDONTWRITEBYTECODE="1")
        done = subprocess.run(
            [sys.executable, "-c", BUILD_KERNELS, str(build_lib / KERNELS)],
            cwd=cache,
            env=env,
            capture_output=True,
            text=True,
            check=False,
        )
    if done.returncode != 0:
        shutil.rmtree(build_lib / KERNELS, ignore_errors=True)
        why = (done.stderr.strip().splitlines() or ["no message"])[-1]
        if done.returncode != MISSING_DEPENDENCY:
            raise RuntimeError(f"albot1-bench build: compiling the kernel bundle failed: {why}")
        print(f"albot1-bench build: the wheel carries no compiled kernels ({why})", file=sys.stderr)


def build_commit() -> str | None:
    """``ALBOT1_BUILD_COMMIT`` if set (a build from a copy of the tree), else ``git describe`` of this checkout."""
    given = os.environ.get(COMMIT_ENV, "").strip()
    if given:
        return given
    if not (ROOT / ".git").exists():
        return None
    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=12"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None


class BuildPyWithProjectFiles(build_py):
    """``build_py`` that also bundles the top-level TOML folders into the package."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return
        target = Path(self.build_lib) / BUNDLE
        shutil.rmtree(target, ignore_errors=True)  # no stale files from an earlier build
        for folder in FOLDERS:
            files = sorted((ROOT / folder).glob("*.toml"))
            if not files:
                raise RuntimeError(f"{ROOT / folder}: no *.toml files to bundle; is the source tree complete?")
            (target / folder).mkdir(parents=True, exist_ok=True)
            for file in files:
                self.copy_file(str(file), str(target / folder / file.name))
        # The commit the wheel is built from (albot1.versions.git_commit reads it back): an installed
        # package has no git beside it. Unknown is recorded as null, never guessed.
        (target / BUILD_FILE).write_text(json.dumps({"commit": build_commit()}) + "\n", encoding="utf-8")
        bundle_kernels(Path(self.build_lib).resolve())

    def get_outputs(self, include_bytecode: bool = True) -> list[str]:
        outputs = list(super().get_outputs(include_bytecode))
        if not getattr(self, "editable_mode", False):
            outputs += [
                str(Path(self.build_lib) / BUNDLE / folder / file.name)
                for folder in FOLDERS
                for file in sorted((ROOT / folder).glob("*.toml"))
            ]
            outputs.append(str(Path(self.build_lib) / BUNDLE / BUILD_FILE))
            outputs += sorted(str(p) for p in (Path(self.build_lib) / KERNELS).rglob("*") if p.is_file())
        return outputs


setup(cmdclass={"build_py": BuildPyWithProjectFiles})
