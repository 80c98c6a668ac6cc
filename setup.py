"""Build step: copy the project's TOML folders into the wheel as package data.

``datasets/``, ``baselines/`` and ``benchmarks/`` at the top of the repository
are the one source of truth for dataset manifests, baseline configs and
benchmark suites. A wheel must carry them (an installed package has no
checkout beside it), so ``build_py`` copies their ``*.toml`` files into
``albot1/_bundled/<folder>/`` of the build tree, never into the source tree.
Editable installs skip the copy: they read the checkout's folders directly
(``albot1/resources.py`` explains the search order). Everything else about
the package is declared in ``pyproject.toml``.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
FOLDERS = ("datasets", "baselines", "benchmarks")  # albot1.resources.FOLDERS
BUNDLE = Path("albot1") / "_bundled"  # albot1.resources.BUNDLE_DIR_NAME


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

    def get_outputs(self, include_bytecode: bool = True) -> list[str]:
        outputs = list(super().get_outputs(include_bytecode))
        if not getattr(self, "editable_mode", False):
            outputs += [
                str(Path(self.build_lib) / BUNDLE / folder / file.name)
                for folder in FOLDERS
                for file in sorted((ROOT / folder).glob("*.toml"))
            ]
        return outputs


setup(cmdclass={"build_py": BuildPyWithProjectFiles})
