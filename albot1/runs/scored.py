"""What evaluation scores (:class:`Scored`): one trajectory per scan against its dataset's reference.

Both sources of ``albot1 evaluate`` produce one: a run folder
(:func:`scored_run`) and an external trajectory file
(:func:`albot1.runs.external.load_external`); :func:`albot1.runs.evaluate.score`
scores either the same way.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import NDArray

from albot1.records import Timing
from albot1.runs.errors import RunError

if TYPE_CHECKING:
    from albot1.contract import MapData
    from albot1.data.model import Relations
    from albot1.runs.folder import StoredRun


@dataclass(frozen=True)
class Scored:
    """What :func:`score` scores: poses per scan against the dataset's reference, plus what a run adds.

    ``timestamps``/``poses``/``reference`` are aligned row by row (one row
    per scan scored). ``relation_timestamps``/``relation_poses`` are the
    poses the relation metric looks relations up in (the same rows, for a
    run and for an external file alike: its poses matched to scans, at
    their scans' stamps). ``load_map``, ``counters`` and
    ``per_scan_ns``/``timing`` are None when the source has none, and
    ``absent`` says why for the metrics that need them.
    """

    header: dict[str, Any]
    dataset: str
    timestamps: NDArray[np.float64]
    poses: NDArray[np.float64]
    reference: NDArray[np.float64] | None
    relations: Relations | None
    relations_source: str
    relation_timestamps: NDArray[np.float64]
    relation_poses: NDArray[np.float64]
    load_map: Callable[[], MapData] | None = None
    counters: Mapping[str, int | float] | None = None
    per_scan_ns: NDArray[np.int64] | None = None
    timing: Timing | None = None
    #: a method's own output file of the run folder by name, parsed (None: no such file; the field is None
    #: for a source without a run folder)
    read_file: Callable[[str], object | None] | None = None
    absent: dict[str, str] = field(default_factory=dict)
    #: the ``ate`` alignment and the first N pairs it is estimated on (``albot1 evaluate --align``)
    alignment: Literal["none", "first", "rigid"] = "rigid"
    n_to_align: int | None = None
    extra: dict[str, Any] = field(default_factory=dict)


def scored_run(run: StoredRun) -> Scored:
    """A stored run as :class:`Scored` (its ``result.json`` gives the header, its folder the rest)."""
    info = run.info
    return Scored(
        header={
            "key": info.key,
            "method": info.method,
            "dataset": info.dataset,
            "preset": info.preset,
            "degradation": info.degradation,
            "seed": info.seed,
            "scans": int(len(run.poses)),
            "has_reference": run.reference is not None,
            "data_sha256": dict(info.dataset_info.data_sha256),
        },
        dataset=info.dataset,
        timestamps=run.timestamps,
        poses=run.poses,
        reference=run.reference,
        relations=run.relations,
        relations_source=str(run.path / "relations.txt"),
        relation_timestamps=run.timestamps,
        relation_poses=run.poses,
        load_map=run.load_map,
        counters=dict(info.counters),
        per_scan_ns=run.per_scan_ns,
        timing=info.timing,
        read_file=run_file_reader(run.path),
    )


def run_file_reader(run_dir: Path) -> Callable[[str], object | None]:
    """Reads a method's own JSON file of ``run_dir`` by name (once each); None when the run has no such file.

    Only plain names of the folder are read (a mapper's extra files, ``places.json``); an unreadable file is
    a RunError naming it.
    """

    @cache
    def read(name: str) -> object | None:
        if Path(name).name != name:
            raise RunError(f"{run_dir}: {name!r} is not a plain file name of the run folder")
        path = run_dir / name
        if not path.is_file():
            return None
        try:
            content: object = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise RunError(f"{path}: cannot read the method's file: {exc}") from None
        return content

    return read
