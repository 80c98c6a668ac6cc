"""Files that live in the project checkout beside the package.

The dataset manifests (``datasets/*.toml``), the baseline configs
(``baselines/*.toml``) and the benchmark suites (``benchmarks/*.toml``) are
part of the project, not of the import package: they are meant to be read and
edited by users. They are found relative to the package's parent folder, or
under ``ALBOT1_PROJECT_DIR`` when the package is installed elsewhere.
"""

from __future__ import annotations

import os
from pathlib import Path

from albot1.errors import ConfigError

PROJECT_DIR_ENV = "ALBOT1_PROJECT_DIR"


def project_dir() -> Path:
    """The checkout holding ``datasets/``, ``baselines/`` and ``benchmarks/``."""
    env = os.environ.get(PROJECT_DIR_ENV)
    root = Path(env) if env else Path(__file__).resolve().parents[1]
    if not (root / "baselines").is_dir() or not (root / "datasets").is_dir():
        raise ConfigError(
            f"{root} does not hold the project's datasets/ and baselines/ folders; "
            f"set {PROJECT_DIR_ENV} to the albot1-bench checkout"
        )
    return root


def project_file(*parts: str) -> Path:
    """A file under the project folder; ConfigError naming it if it is missing."""
    path = project_dir().joinpath(*parts)
    if not path.exists():
        raise ConfigError(f"{path}: expected project file is missing")
    return path
