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
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
FOLDERS = ("datasets", "baselines", "benchmarks")  # albot1.resources.FOLDERS
BUNDLE = Path("albot1") / "_bundled"  # albot1.resources.BUNDLE_DIR_NAME
BUILD_FILE = "build.json"  # albot1.versions.BUILD_FILE
COMMIT_ENV = "ALBOT1_BUILD_COMMIT"


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

    def get_outputs(self, include_bytecode: bool = True) -> list[str]:
        outputs = list(super().get_outputs(include_bytecode))
        if not getattr(self, "editable_mode", False):
            outputs += [
                str(Path(self.build_lib) / BUNDLE / folder / file.name)
                for folder in FOLDERS
                for file in sorted((ROOT / folder).glob("*.toml"))
            ]
            outputs.append(str(Path(self.build_lib) / BUNDLE / BUILD_FILE))
        return outputs


setup(cmdclass={"build_py": BuildPyWithProjectFiles})
