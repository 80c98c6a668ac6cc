"""The code version and library versions recorded with every result."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from collections.abc import Mapping
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
#: numpy does. networkx writes albot1-places' ``places.graphml``, a file of the run. Each is in every run's key
#: (:func:`key_versions` says why).
RECORDED_LIBRARIES = ("numpy", "shapely", "scipy", "numba", "llvmlite", "kiss-icp", "gtsam", "rosbags", "networkx")


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


#: What a run's versions block holds that its key leaves out: the commit is a label of the code, whose digest
#: (``code``) the key holds; a commit label differs between a checkout and the wheel built from it, and gains
#: ``-dirty`` with any edit of the build files, neither of which changes what a run computes.
UNKEYED_VERSIONS = frozenset({"git"})


def run_versions(programs: Mapping[str, str | None] | None = None, plugin: str | None = None) -> dict[str, str | None]:
    """The ``versions`` block of a run: code, commit, every :data:`RECORDED_LIBRARIES` version, programs, plugin.

    One block for what a run records (``result.json``) and what its key digests (:func:`key_versions`), built
    here for both: the planner builds it before a cell runs, the cell after, and a difference between the two
    is a result that would be stored under a key naming other versions. ``programs``: the versions of the
    programs outside Python the method runs (MRPT's applications: ``Mapper.program_versions`` before a run,
    ``MapperOutput.versions`` after it); ``plugin``: a plugin method's distribution and version.
    """
    problem = program_versions_problem(programs or {})
    if problem is not None:
        raise ValueError(problem)
    block: dict[str, str | None] = {"code": code_version(), "git": git_commit(), **library_versions()}
    block.update(programs or {})
    if plugin is not None:
        block["plugin"] = plugin
    return block


#: The names of a versions block that are not a program's (:func:`run_versions`).
_TAKEN = ("code", "git", "plugin", *RECORDED_LIBRARIES)


def program_versions_problem(programs: object) -> str | None:
    """Why ``programs`` (a method's program versions) cannot go into a versions block, or None when they can."""
    if not isinstance(programs, Mapping):
        return f"program versions {programs!r}; expected a dict of program name -> version"
    for name, version in programs.items():
        if not isinstance(name, str) or name in _TAKEN or not (version is None or isinstance(version, str)):
            return (
                f"program version {name!r}: {version!r}; expected a program's name (not one of {', '.join(_TAKEN)}) "
                "and its version as a string (None when unknown)"
            )
    return None


def key_versions(recorded: Mapping[str, str | None]) -> dict[str, str | None]:
    """The part of a run's versions block (:func:`run_versions`) its key digests: all but :data:`UNKEYED_VERSIONS`.

    Why every library, for every method: the libraries a run's files depend on are not those its method imports
    alone. Every run reads its data (shapely draws the synthetic worlds' scans, rosbags decodes bags), degrades
    its odometry (numpy's generator), and is evaluated into ``metrics.json`` (numpy, scipy, shapely); gtsam-graph
    computes with Albot1's numba kernels; a list kept per method would be wrong the day an import is added, and
    that error is a stale result reused without a word. The cost of the wider key is a re-run of every cell
    after an upgrade of any one of them, the same cost as any edit of this package's code (``code``), which the
    key already takes. Not recorded, so not keyed: the libraries that draw ``preview.png`` (matplotlib), a
    picture of the run no metric reads (the report's figures are keyed on them, ``albot1.report.figure_cache``).
    """
    return {name: recorded[name] for name in sorted(recorded) if name not in UNKEYED_VERSIONS}
