"""Where a report goes when no folder is given (one place: the report command, its stamp check and the builder)."""

from __future__ import annotations

from pathlib import Path

REPORTS_ROOT = Path("reports")


def default_out(results_dir: Path) -> Path:
    """``results/<suite>`` -> ``reports/<suite>`` (relative to the working directory, as `make bench` runs)."""
    return REPORTS_ROOT / Path(results_dir).resolve().name
