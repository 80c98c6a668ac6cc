"""The code version and library versions recorded with every result."""

from __future__ import annotations

import hashlib
import subprocess
from functools import lru_cache
from importlib import metadata
from pathlib import Path

from albot1 import __version__

_PACKAGE_DIR = Path(__file__).resolve().parent
#: ``albot1.resources.BUNDLE_DIR_NAME`` (same layer: the two modules may not import each other).
_BUNDLE_DIR_NAME = "_bundled"


@lru_cache(maxsize=1)
def code_version() -> str:
    """``<package version>+<digest of the package sources>``.

    A digest of the sources (rather than only a git hash) changes whenever the
    code that computes a result changes, committed or not, and works outside a
    git checkout (an installed wheel, a CI tarball). The copies of the project's
    TOML folders bundled into a wheel (``albot1/_bundled``, see
    :mod:`albot1.resources`) are left out, so a wheel and the checkout it was
    built from name the same code; the configs a run used are recorded with it.
    """
    digest = hashlib.sha256()
    for path in sorted(_PACKAGE_DIR.rglob("*")):
        relative = path.relative_to(_PACKAGE_DIR).parts
        if relative[0] == _BUNDLE_DIR_NAME or "__pycache__" in relative:
            continue
        if path.is_file() and path.suffix in {".py", ".toml", ".json", ".ini"}:
            digest.update(path.relative_to(_PACKAGE_DIR).as_posix().encode())
            digest.update(path.read_bytes())
    return f"{__version__}+{digest.hexdigest()[:12]}"


@lru_cache(maxsize=1)
def git_commit() -> str | None:
    """The checkout's commit (with ``-dirty`` when modified), or None outside git."""
    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=12"],
            cwd=_PACKAGE_DIR,
            capture_output=True,
            text=True,
            timeout=5,
            check=True,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None


def library_versions(
    names: tuple[str, ...] = ("numpy", "shapely", "scipy", "kiss-icp", "gtsam", "rosbags"),
) -> dict[str, str | None]:
    """Installed versions of the libraries a result may depend on (None if absent)."""
    found: dict[str, str | None] = {}
    for name in names:
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            found[name] = None
    return found
