"""Debian's ``chromium`` for the report's browser tests: where it is, and how it is started offline.

One place for the flags, so that every browser test runs the browser the
same way: headless, no sandbox (CI runs as root), no first-run or background
traffic, and every network request refused (``offline``), because a report
page must work from ``file://`` with nothing fetched.
"""

from __future__ import annotations

import shutil
from pathlib import Path

BROWSER_NAMES = ("chromium", "chromium-browser")

#: The reason a browser test is skipped when no browser is found.
NO_BROWSER = "no chromium on PATH (.ci/run installs Debian's chromium with apt)"


def browser() -> str | None:
    """The chromium executable on PATH, or None."""
    return next((found for name in BROWSER_NAMES if (found := shutil.which(name))), None)


def flags(profile: Path, *, offline: bool = True, window: str | None = "1280,1000") -> list[str]:
    """Command-line flags for a headless run with its own profile folder.

    ``offline``: every request goes to a closed proxy port and every host name
    fails to resolve, so a page that needs the network fails visibly.
    """
    found = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        f"--user-data-dir={profile}",
    ]
    if offline:
        found += ["--proxy-server=127.0.0.1:9", "--host-resolver-rules=MAP * ~NOTFOUND"]
    if window is not None:
        found.append(f"--window-size={window}")
    return found
