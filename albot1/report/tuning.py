"""Held-in marks: was a number measured on a dataset its method's values were tuned on?

A method's preset file records, in a ``[tuned_on]`` table, the datasets its
values were chosen on by looking at their scores
(:func:`albot1.config.presets.tuned_on`). A number measured on one of them
says how well the method fits data it was fitted to, not how it generalises,
so every page that shows per-dataset numbers marks it with :data:`MARK` and
prints :data:`LEGEND`. The dataset of a cell is its catalog name: loader
options and a slice (``seattle-corrected?odometry=laser-pose[::3]``) do not
make another dataset, and a tuned-on list names the datasets as the catalog
does (``intel`` and ``intel-corrected`` are two entries there, and a list
names each one it used).

The lists are read from the preset files when the report is built (they
describe the values, which every run's ``result.json`` holds): a method or
class that cannot be loaded, or a preset file without the table, gives
``None`` ("not recorded"), which the pages say rather than leaving a number
unmarked silently.
"""

from __future__ import annotations

import re
from functools import cache

from albot1.bench.grid import Cell
from albot1.config.presets import tuned_on
from albot1.errors import Albot1Error
from albot1.methods.registry import load_mapper_class, method_registry

#: The mark beside a number measured on a dataset its method was tuned on.
MARK = "†"
LEGEND = (
    f"{MARK} measured on a dataset this method's values were chosen on (held-in: the `[tuned_on]` table of its "
    'preset file, docs/benchmarking.md "Held-in and held-out"); such a number shows fit, not generalisation.'
)

_SLICE = re.compile(r"\[[^\[\]]*\]$")


def dataset_name(reference: str) -> str:
    """The catalog name of a dataset reference: without its slice and loader options."""
    return _SLICE.sub("", reference).partition("?")[0]


@cache
def tuned_datasets(method: str, preset: str, target: str | None = None) -> tuple[str, ...] | None:
    """The datasets ``method``'s ``preset`` was tuned on; None when unknown (not recorded, class not loadable)."""
    registry = method_registry()
    where = target or (registry.get(method).target if method in registry else None)
    if where is None:
        return None
    try:
        cls = load_mapper_class(where)
    except (Albot1Error, ImportError):
        return None
    return tuned_on(cls, preset)


def held_in(cell: Cell) -> bool | None:
    """Whether ``cell``'s dataset is one its method was tuned on (None: the method records no tuning)."""
    names = tuned_datasets(cell.method, cell.preset)
    if names is None:
        return None
    return dataset_name(cell.dataset) in names


def marked(text: str, tuned: bool | None) -> str:
    """``text`` with :data:`MARK` when ``tuned`` is True."""
    return f"{text} {MARK}" if tuned else text
