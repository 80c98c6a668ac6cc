"""Held-in marks: was a number measured on a dataset its method's values were tuned on?

A method's preset file records, in a ``[tuned_on]`` table, the datasets its
values were chosen on by looking at their scores
(:func:`albot1.config.presets.tuned_on`). A number measured on one of them
says how well the method fits data it was fitted to, not how it generalises,
so every page that shows per-dataset numbers marks it with :data:`MARK` and
prints :data:`LEGEND`. What a cell was measured on is its data, not its
spelling: loader options and a slice (``seattle-corrected?odometry=laser-pose[::3]``)
do not make another dataset, a manifest whose log has the sha256 of a tuned-on
dataset's log (a user's ``my-aces.toml``, a bag or log given by path whose
run read that file) is that dataset, and a corrected or thinned copy of a
drive (a manifest's ``recording``: ``aces-corrected`` is the ``aces`` drive)
is held-in wherever the drive is. Names alone let a tuned number go unmarked
on each of these (``my-aces``, ``aces-corrected`` for a method tuned on ``aces``).
A tuned-on list must name catalog datasets or synthetic worlds: a typo would
otherwise never mark anything, so it is a :class:`~albot1.errors.ConfigError`.

The lists are read from the preset files when the report is built (they
describe the values, which every run's ``result.json`` holds): a method or
class that cannot be loaded, or a preset file without the table, gives
``None`` ("not recorded"), which the pages say rather than leaving a number
unmarked silently.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from functools import cache

from albot1.bench.grid import Cell
from albot1.config.presets import preset_file, tuned_on
from albot1.config.suggest import unknown_name_message
from albot1.data import catalog
from albot1.data.synthetic.worlds import WORLDS
from albot1.errors import Albot1Error, ConfigError
from albot1.methods.registry import load_mapper_class, method_registry
from albot1.report.collect import CellRecord
from albot1.runs.folder import EXTERNAL_PRESET

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
    """The datasets ``method``'s ``preset`` was tuned on; None when unknown (not recorded, class not loadable).

    A name that is neither a catalog dataset nor a synthetic world is a ConfigError naming the preset file:
    it would match no cell, leaving every number of the dataset meant unmarked.
    """
    registry = method_registry()
    where = target or (registry.get(method).target if method in registry else None)
    if where is None:
        return None
    try:
        cls = load_mapper_class(where)
    except (Albot1Error, ImportError):
        return None
    names = tuned_on(cls, preset)
    known = {*catalog.names(), *WORLDS}
    for name in names or ():
        if name not in known:
            raise ConfigError(
                f"{preset_file(cls.name)}: [tuned_on] of preset {preset!r}: "
                + unknown_name_message("dataset", name, sorted(known), listing="albot1 datasets list")
            )
    return names


@cache
def _identities(name: str) -> frozenset[str]:
    """What a dataset name stands for: itself, its log's sha256 and its drive (``recording``), followed through."""
    if name not in catalog.names():
        return frozenset({name})
    manifest = catalog.get(name)
    own = {name, manifest.log.sha256}
    return frozenset(own | (_identities(manifest.recording) if manifest.recording else set()))


@cache
def _held_in_identities(names: tuple[str, ...]) -> frozenset[str]:
    """Every identity of the tuned-on datasets, and of each catalog dataset of the same log or drive."""
    tuned = frozenset().union(*(_identities(n) for n in names))
    same = [n for n in catalog.names() if _identities(n) & tuned]
    return tuned.union(*(_identities(n) for n in same))


def held_in(cell: Cell, data_sha256: Iterable[str] = ()) -> bool | None:
    """Whether ``cell``'s data is a dataset its method was tuned on (None: the method records no tuning).

    ``data_sha256``: the checksums of the files the cell's run read (``result.json``), which identify a log
    given by path or under another manifest's name. A cell that scores another system's trajectory file is
    None: that system's tuning is not known, whatever label the suite gives it.
    """
    if cell.trajectory is not None:
        return None
    return run_held_in(cell.method, cell.preset, cell.dataset, data_sha256)


def run_held_in(method: str, preset: str, dataset: str, data_sha256: Iterable[str] = ()) -> bool | None:
    """The one decision: is ``dataset`` (a reference, maybe sliced or with options) held-in for ``method:preset``?

    The run's own words (``result.json``, ``metrics.json`` ``run``) and a grid cell both come here, so a
    number reads held-in on a command's output exactly where it does on the pages. None: not recorded.
    """
    if preset == EXTERNAL_PRESET:
        return None
    names = tuned_datasets(method, preset)
    if names is None:
        return None
    tuned = _held_in_identities(names)
    return bool((_identities(dataset_name(dataset)) | set(data_sha256)) & tuned)


def held_in_line(method: str, preset: str, dataset: str, data_sha256: Iterable[str] = ()) -> str | None:
    """One line for a command's output when its numbers are held-in (:func:`run_held_in`), naming the preset file.

    None when they are not, or when the tuning is unknown (a plugin, an external trajectory: nothing is said,
    as "not tuned" would be a claim nobody recorded).
    """
    if not run_held_in(method, preset, dataset, data_sha256):
        return None
    owner = load_mapper_class(method_registry().get(method).target).name
    return (
        f"{MARK} held-in: {method}:{preset} was tuned on this data ({dataset_name(dataset)}; the [tuned_on] table "
        f"of {preset_file(owner)}): these numbers show fit, not generalisation"
    )


def held_in_share(count: int, total: int) -> str:
    """How many of ``total`` verdicts or numbers pooled in one cell are held-in: ``, 20 held-in †`` (or nothing).

    A count (of a thesis claim over datasets, say) pools held-in and held-out data, so the mark alone would
    not say how much of it shows fit; the thesis page and the results page word it the same way.
    """
    if not count:
        return ""
    return f", {'all' if count == total else count} held-in {MARK}"


def combined(values: Iterable[bool | None]) -> bool | None:
    """The mark of numbers pooled from several cells: True when one is held-in, None when one's tuning is unknown.

    Unknown is not "not tuned": a row or comparison pooling a plugin's cells with others must not read False.
    """
    seen = list(values)
    if any(v is True for v in seen):
        return True
    return None if any(v is None or v != v for v in seen) else False


def record_held_in(rec: CellRecord) -> bool | None:
    """:func:`held_in` of a stored cell, with the checksums of the files its run read when it has a result."""
    files = rec.result.dataset_info.data_sha256.values() if rec.result is not None else ()
    return held_in(rec.cell, files)


def csv_flag(held: bool | None) -> str:
    """A ``held_in`` cell of a CSV written by hand, as pandas writes ``cells.csv``'s: ``True``, ``False``, empty
    when the tuning is unknown (never ``False`` for it)."""
    return "" if held is None else str(held)


def marked(text: str, tuned: bool | None) -> str:
    """``text`` with :data:`MARK` when ``tuned`` is True."""
    return f"{text} {MARK}" if tuned else text
