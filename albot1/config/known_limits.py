"""Known limits: what a method's preset file says about a log it fails on or is not run on.

A failed cell on the standard page says *what* stopped the run (its error
line); a reader also needs to know whether that failure was looked into and
what the evidence says (e.g. that no configuration of MRPT's particle
filter tried reached published quality on every log, and why). That finding
belongs beside the values it concerns, so a preset file may hold a
``[known_limits.PRESET]`` table, ``DATASET = "one line: the finding and where
its evidence is"``. It is data, never config: it never enters a run's config
or key. A preset the table does not name has ``default``'s limits.

Parsing lives here; reading a method's file is
:func:`albot1.config.presets.load_known_limits` (one place that finds files).
"""

from __future__ import annotations

from typing import Any

from albot1.errors import ConfigError

#: The top-level table of a preset file that holds the known limits of each preset.
KNOWN_LIMITS = "known_limits"

#: preset name -> dataset name -> the finding (one line)
KnownLimitsTable = dict[str, dict[str, str]]

_EXPECTED = f'expected [{KNOWN_LIMITS}.PRESET] DATASET = "one line: the finding and where its evidence is"'


def parse_known_limits(data: dict[str, Any], source: str) -> KnownLimitsTable | None:
    """The ``[known_limits]`` table of a parsed preset file (None when the file has none), validated.

    Keys are preset names the file defines; each value maps dataset names to
    a non-empty, single-line text (a page prints it as one list item).
    """
    table = data.get(KNOWN_LIMITS)
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ConfigError(f"{source}: {KNOWN_LIMITS}: {_EXPECTED}, got {type(table).__name__}")
    declared = data.get("presets")
    presets: dict[str, Any] = declared if isinstance(declared, dict) else {}
    out: KnownLimitsTable = {}
    for preset, limits in table.items():
        if preset not in presets:
            raise ConfigError(f"{source}: [{KNOWN_LIMITS}] names preset {preset!r}, which the file does not define")
        if not isinstance(limits, dict):
            raise ConfigError(f"{source}: {KNOWN_LIMITS}.{preset}: {_EXPECTED}, got {limits!r}")
        for dataset, text in limits.items():
            if not isinstance(text, str) or not text.strip() or "\n" in text.strip():
                raise ConfigError(
                    f"{source}: {KNOWN_LIMITS}.{preset}.{dataset}: {_EXPECTED} (a non-empty single line), got {text!r}"
                )
        out[preset] = {dataset: " ".join(text.split()) for dataset, text in limits.items()}
    return out


def known_limit(table: KnownLimitsTable | None, preset: str, dataset: str) -> str | None:
    """The finding for ``dataset`` under ``preset`` (``default``'s when the preset names none), or None."""
    if table is None:
        return None
    own = table.get(preset)
    if own is not None and dataset in own:
        return own[dataset]
    return table.get("default", {}).get(dataset)
