"""The code version and library versions recorded with every result."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
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


#: Written by the build step (``setup.py``) into the wheel's bundle: the commit the wheel was built from.
BUILD_FILE = "build.json"
#: What a record says when the commit is not known (a wheel built outside a git checkout, a copied tree).
UNKNOWN_COMMIT = "commit unknown (not run from a git checkout, and no commit recorded when the wheel was built)"


@lru_cache(maxsize=1)
def git_commit() -> str | None:
    """The commit of the running code, or None when it cannot be known.

    From a checkout (the package's parent holds ``.git``): ``git describe``,
    with ``-dirty`` when modified. From an installed wheel: the commit the
    build step recorded in ``_bundled/build.json`` (it runs ``git describe``
    on the checkout it builds from, or takes ``ALBOT1_BUILD_COMMIT``). Git is
    not asked about a package that merely sits inside some repository (a
    virtualenv in a clone): that repository's commit is not the wheel's.
    """
    if (_PACKAGE_DIR.parent / ".git").exists():
        try:
            described = _git("describe", "--always", "--abbrev=12")
            changed = _git("status", "--porcelain", "--", *_CODE_PATHS)
        except (OSError, subprocess.SubprocessError):
            return None
        if not described:
            return None
        return f"{described}-dirty" if changed else described
    return _built_commit()


#: What "dirty" looks at, relative to the checkout: the package, its build files and the project's TOML folders
#: (``albot1.resources.FOLDERS``). Not the whole tree: ``make bench`` rewrites ``README.md`` and
#: ``docs/results.md`` from the results, and that must not relabel the code that computed them (a relabelled
#: plan makes every report rebuild once on the next, otherwise idle, ``make bench``).
_CODE_PATHS = (_PACKAGE_DIR.name, "pyproject.toml", "setup.py", "datasets", "baselines", "benchmarks")


def _git(*args: str) -> str:
    """``git ARGS`` in the checkout the package sits in: its stripped output (raises when git fails)."""
    out = subprocess.run(["git", *args], cwd=_PACKAGE_DIR.parent, capture_output=True, text=True, timeout=5, check=True)
    return out.stdout.strip()


def _built_commit() -> str | None:
    """The commit recorded in the wheel at build time, or None (no record, or not a record this build wrote)."""
    try:
        record = json.loads((_PACKAGE_DIR / _BUNDLE_DIR_NAME / BUILD_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    commit = record.get("commit") if isinstance(record, dict) else None
    return commit if isinstance(commit, str) and commit else None


def commit_label(commit: str | None) -> str:
    """``commit e309a8d0c1f2`` or :data:`UNKNOWN_COMMIT`: how a version line names the commit (never "None")."""
    return f"commit {commit}" if commit else UNKNOWN_COMMIT


#: What :func:`library_versions` records by default: the libraries a result is computed with. numba and llvmlite
#: compile Albot1's kernels (and gtsam-graph's grid search): another numba or LLVM may compile them into
#: different machine code (fused or reordered floating-point operations), so they name what ran as much as
#: numpy does.
RECORDED_LIBRARIES = ("numpy", "shapely", "scipy", "numba", "llvmlite", "kiss-icp", "gtsam", "rosbags")


def library_versions(names: tuple[str, ...] = RECORDED_LIBRARIES) -> dict[str, str | None]:
    """The version of each library as this process runs it (None if absent); a new dict each call.

    For a library this process has imported: the version read the first time it was seen imported (the
    installed distribution then is the one its module came from). So a long-lived process, such as the bench's
    forkserver and the cells it forks, goes on recording the library it runs even when another version is
    installed under it meanwhile. For a library not imported (the run did not use it): the installed version,
    read once; once the process imports it, it is read again, so a cell that imports a library its forkserver
    had not records what it imported.
    """
    return {name: _version(name) for name in names}


#: Distributions whose import name is not the distribution name with "-" as "_".
_IMPORT_NAMES = {"kiss-icp": "kiss_icp"}
#: Per process, what :func:`library_versions` read: of libraries imported when read, and of the others. Each
#: search of the installed metadata costs ~2 ms; the bench's forkserver reads them after its imports
#: (:mod:`albot1.bench.preload`) and the cells it forks inherit both.
_IMPORTED: dict[str, str | None] = {}
_NOT_IMPORTED: dict[str, str | None] = {}


def _version(name: str) -> str | None:
    """``name``'s version, as :func:`library_versions` says."""
    kept = _IMPORTED if _IMPORT_NAMES.get(name, name.replace("-", "_")) in sys.modules else _NOT_IMPORTED
    if name not in kept:
        try:
            kept[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            kept[name] = None
    return kept[name]
