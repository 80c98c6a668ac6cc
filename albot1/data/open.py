"""One entry point from a user's dataset argument to a Sequence.

``ref`` may be an embedded synthetic world name, a registered dataset name
(resolved through the catalog and the dataset settings) or a path to a file
of any known format, optionally followed by loader options and a slice::

    intel-corrected?odometry=laser-pose      loader options (key=value&key=value)
    intel[:1000]   intel[:5000:5]   intel[::2]   the first STOP scans, every STEP-th

The whole string names what a run used, so a stored run reopens its data
exactly (``albot1 evaluate`` relies on this).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from albot1.data.errors import DatasetNotFoundError
from albot1.data.model import Sequence
from albot1.settings import Settings, get_settings


def open_sequence(
    ref: str | Path, *, settings: Settings | None = None, format_name: str | None = None, **options: Any
) -> Sequence:
    """Open ``ref`` (world name, dataset name or path) as a streamed Sequence."""
    from albot1.data import catalog
    from albot1.data.loaders.registry import load
    from albot1.data.synthetic import worlds

    text = str(ref)
    # "NAME[:STOP]" / "NAME[:STOP:STEP]" / "NAME[::STEP]": the first STOP scans, every STEP-th of them
    # (the benchmark suites name their slices of long logs this way, so a run's dataset reopens as run).
    sliced = re.fullmatch(r"(?P<ref>.+)\[:(?P<stop>\d*)(?::(?P<step>\d+))?\]", text)
    if sliced is not None and not Path(text).expanduser().exists():
        from albot1.data.transforms import head, stride

        sequence = open_sequence(sliced["ref"], settings=settings, format_name=format_name, **options)
        if sliced["stop"]:
            sequence = head(sequence, int(sliced["stop"]))
        if sliced["step"]:
            sequence = stride(sequence, int(sliced["step"]))
        return sequence
    name, has_query, query = text.partition("?")
    if has_query and not Path(text).expanduser().exists():
        return open_sequence(
            name, settings=settings, format_name=format_name, **{**parse_options(query, text), **options}
        )
    if text in worlds.WORLDS:
        if options:
            raise DatasetNotFoundError(f"synthetic world {text!r} takes no loader options, got {', '.join(options)}")
        return worlds.load_world(text)
    settings = settings or get_settings()
    if text in catalog.names():
        return catalog.open_dataset(text, settings, **options)
    path = Path(text).expanduser()
    if path.exists():
        return load(path, format_name, **options)
    raise DatasetNotFoundError(
        f"{text!r} is neither a dataset name nor an existing file; known datasets: "
        f"{', '.join(catalog.names() + sorted(worlds.WORLDS))} (see `albot1 datasets list`)"
    )


def parse_options(query: str, ref: str) -> dict[str, Any]:
    """``"a=1&b=x"`` -> ``{"a": 1, "b": "x"}`` (numbers become int/float)."""
    options: dict[str, Any] = {}
    for pair in filter(None, query.split("&")):
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise DatasetNotFoundError(f"{ref!r}: loader option {pair!r} is not of the form KEY=VALUE")
        for convert in (int, float):
            try:
                options[key] = convert(value)
                break
            except ValueError:
                continue
        else:
            options[key] = value
    return options
