"""The project's editable TOML files, found the same way from a checkout and from a wheel.

Dataset manifests (``datasets/*.toml``), baseline configs (``baselines/*.toml``)
and benchmark suites (``benchmarks/*.toml``) are meant to be read, questioned
and edited by users, so their one source of truth is the top-level folders of
the repository, not the import package. They are found in this order:

1. ``ALBOT1_CONFIG_DIR`` (optional): a user's folder laid out the same way
   (``datasets/``, ``baselines/``, ``benchmarks/``). A file there adds to the
   project's files, or replaces the project's file of the same name, which is
   said once per process (a warning naming both files): a replaced preset
   changes what ``--preset default`` means.
2. The checkout around the package (an editable install or a source tree):
   ``<checkout>/datasets/`` etc., recognised by the ``pyproject.toml`` beside
   the package.
3. The copies bundled in the installed package (``albot1/_bundled/<folder>/``):
   the build step in ``setup.py`` copies the top-level folders into the wheel,
   so a wheel installed anywhere runs without a checkout. The copies are made
   at build time only and never committed.

An explicit path given by the user (``albot1 bench path/to/suite.toml``)
bypasses this search altogether.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import Literal

from albot1.errors import ConfigError

#: The project folders shipped as package data (and what they hold).
Folder = Literal["datasets", "baselines", "benchmarks"]
FOLDERS: tuple[Folder, ...] = ("datasets", "baselines", "benchmarks")

CONFIG_DIR_ENV = "ALBOT1_CONFIG_DIR"

log = logging.getLogger(__name__)
#: The user's files already said to replace the project's (in this process).
_said: set[Path] = set()

_PACKAGE_DIR = Path(__file__).resolve().parent
#: Where the build step puts the copies inside the package (``setup.py`` uses the same name).
BUNDLE_DIR_NAME = "_bundled"


def _check_folder(folder: str) -> None:
    if folder not in FOLDERS:
        raise ConfigError(f"unknown resource folder {folder!r}; expected one of: {', '.join(FOLDERS)}")


def user_config_dir() -> Path | None:
    """The folder named by ``ALBOT1_CONFIG_DIR``, or None; ConfigError if it is not a folder."""
    value = os.environ.get(CONFIG_DIR_ENV)
    if not value:
        return None
    path = Path(value).expanduser()
    if not path.is_dir():
        raise ConfigError(
            f"{CONFIG_DIR_ENV}={value}: not a folder; expected a folder holding datasets/, baselines/ or benchmarks/"
        )
    return path


def shipped_dir(folder: Folder) -> Path:
    """The project's own copy of ``folder``: the checkout's, else the one bundled in the package."""
    _check_folder(folder)
    checkout = _PACKAGE_DIR.parent
    if (checkout / "pyproject.toml").is_file() and (checkout / folder).is_dir():
        return checkout / folder
    bundled = _PACKAGE_DIR / BUNDLE_DIR_NAME / folder
    if bundled.is_dir():
        return bundled
    raise ConfigError(
        f"neither {checkout / folder} (a checkout) nor {bundled} (an installed wheel) exists; "
        "reinstall albot1-bench from a wheel or a checkout"
    )


def resource_dirs(folder: Folder) -> list[Path]:
    """Folders searched for ``folder``'s files, most preferred first (see the module docstring)."""
    _check_folder(folder)
    user = user_config_dir()
    found = [user / folder] if user is not None and (user / folder).is_dir() else []
    return [*found, shipped_dir(folder)]


def find_resource(folder: Folder, name: str) -> Path:
    """The file ``name`` (e.g. ``"kiss-icp.toml"``) of ``folder``; ConfigError listing the places searched."""
    dirs = resource_dirs(folder)
    for directory in dirs:
        candidate = directory / name
        if candidate.is_file():
            _say_replacing(candidate, folder)
            return candidate
    raise ConfigError(f"no {folder}/{name} in {' or '.join(str(d) for d in dirs)}")


def list_resources(folder: Folder, pattern: str = "*.toml") -> list[Path]:
    """The files of ``folder`` matching ``pattern``, one per file name, sorted by name.

    A user's file (``ALBOT1_CONFIG_DIR``) replaces the project's file of the same name.
    """
    chosen: dict[str, Path] = {}
    for directory in reversed(resource_dirs(folder)):
        for path in directory.glob(pattern):
            if path.is_file():
                chosen[path.name] = path
    for path in chosen.values():
        _say_replacing(path, folder)
    return [chosen[name] for name in sorted(chosen)]


def _say_replacing(found: Path, folder: Folder) -> None:
    """Warn, once per process, when ``found`` is a user's file replacing the project's file of the same name."""
    shipped = shipped_dir(folder) / found.name
    if found in _said or found.parent == shipped.parent or not shipped.is_file():
        return
    if found.resolve() == shipped.resolve():  # ALBOT1_CONFIG_DIR naming the checkout itself
        return
    _said.add(found)
    log.warning("%s replaces the project's %s (%s)", found, shipped, CONFIG_DIR_ENV)
